#!/usr/bin/env bash
# The candela vs Mitsuba 3 benchmark in one command (see bench/README.md):
#
#   bash bench/mitsuba.sh                 # setup, build, references (cached), 3 alternated rounds
#   bash bench/mitsuba.sh --reps 5 --check
#   bash bench/mitsuba.sh --interior      # the diffuse interior instead (bench/mitsuba/interior.py)
#   bash bench/mitsuba.sh --interior --quick --candela PATH
#
# Arguments go to bench/compare.py, or with --interior to bench/mitsuba/interior.py (--help lists
# them). Results: a Markdown table on stdout, target/bench/mitsuba-results.json (Cornell) or
# target/bench/mitsuba-interior-results.json, progress on stderr.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

SCRIPT=bench/compare.py
if [ "${1:-}" = "--interior" ]; then
    SCRIPT=bench/mitsuba/interior.py
    shift
fi

# Mitsuba scenes: must match scenes/bench-cornell.ron and data/ (regenerate with gen_scene.py).
python3 bench/mitsuba/gen_scene.py --check

eval "$(bash bench/setup_mitsuba.sh)"
if [[ " $* " != *" --candela "* ]]; then
    echo "build: cargo build --release" >&2
    CARGO_PROFILE_RELEASE_LTO="${CARGO_PROFILE_RELEASE_LTO:-false}" \
    CARGO_PROFILE_RELEASE_CODEGEN_UNITS="${CARGO_PROFILE_RELEASE_CODEGEN_UNITS:-16}" \
        nice -n 19 cargo build --release --quiet
fi

exec nice -n 19 target/bench-venv/bin/python "$SCRIPT" "$@"
