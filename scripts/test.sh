#!/usr/bin/env bash
# The one command that runs every test on a fresh machine:
#   bash scripts/test.sh
# It installs the Python reference (colour-science, pinned) into target/venv when missing, runs
# the whole Rust test suite (optimised: [profile.test] opt-level = 3), then builds the Python
# package into target/venv and runs its tests (tests/python/), and the HTML report's end-to-end
# test in headless Chromium (tests/browser/).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_python.sh
# tests/slurm.rs starts a one-node Slurm cluster: as root, install its Debian packages.
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null && ! command -v slurmctld >/dev/null; then
    { apt-get update -qq &&
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge; } ||
        echo "test.sh: slurm-wlm and munge could not be installed; tests/slurm.rs will skip" >&2
fi
# tests/browser/ opens the HTML report in headless Chromium through chromedriver: as root,
# install Debian's packages when missing.
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null &&
    ! { command -v chromium >/dev/null && command -v chromedriver >/dev/null; }; then
    { apt-get update -qq &&
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium chromium-driver; } ||
        echo "test.sh: chromium and chromium-driver could not be installed; tests/browser will fail" >&2
fi
export CANDELA_PYTHON="${CANDELA_PYTHON:-$PWD/target/venv/bin/python}"
cargo test --all-targets "$@"
# The Python package, built with the dev profile (maturin's default; its dependencies are those
# cargo test compiled, with two more features of syn that pyo3's macros turn on, so the derive
# macros and the crates using them are compiled again; `--profile test` would build the unit-test
# harness, not a library), installed into the venv (numpy, its one requirement, is among the
# pins), then its tests (finding none, pytest exits 5: a failure).
VIRTUAL_ENV="$PWD/target/venv" target/venv/bin/maturin develop --quiet
target/venv/bin/python -m pytest -q -p no:cacheprovider -p no:warnings tests/python
# The HTML report in headless Chromium (selenium, pinned above), with the candela binary that
# `cargo test` built (target/debug/candela); screenshots and a PDF print go to target/browser/.
target/venv/bin/python -m pytest -q -p no:cacheprovider -p no:warnings tests/browser
