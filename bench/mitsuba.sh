#!/usr/bin/env bash
# The candela vs Mitsuba 3 benchmark in one command (issue 7; see bench/README.md):
#
#   bash bench/mitsuba.sh                 # setup, build, references (cached), 3 alternated rounds
#   bash bench/mitsuba.sh --reps 5 --check
#
# Arguments go to bench/compare.py (--help lists them). Results: a Markdown table on stdout,
# target/bench/mitsuba-results.json, progress on stderr.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

# Mitsuba scene: must match scenes/bench-cornell.ron and data/ (regenerate with gen_scene.py).
python3 bench/mitsuba/gen_scene.py --check

eval "$(bash bench/setup_mitsuba.sh)"
echo "build: cargo build --release" >&2
cargo build --release --quiet

exec target/bench-venv/bin/python bench/compare.py "$@"
