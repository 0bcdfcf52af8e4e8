#!/usr/bin/env bash
# The one command that runs every test on a fresh machine:
#   bash scripts/test.sh
# It installs the Python reference (colour-science, pinned) into target/venv when missing, then
# runs the whole Rust test suite (optimised: [profile.test] opt-level = 3).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_python.sh
export CANDELA_PYTHON="${CANDELA_PYTHON:-$PWD/target/venv/bin/python}"
cargo test --all-targets "$@"
