#!/usr/bin/env bash
# candela against Radiance (rtrace -I) on an office work-plane grid, in one command
# (see bench/README.md, "Against Radiance"):
#
#   bash bench/radiance.sh                  # N = 6 and 48, references (cached), 3 alternated rounds
#   bash bench/radiance.sh --quick          # smoke run, a minute or two
#   bash bench/radiance.sh --ns 6,48,500    # also 500 luminaires (Radiance's side takes hours)
#
# Arguments go to bench/radiance/run.py (--help lists them). Results: a Markdown table on stdout,
# target/bench/radiance/results.json, progress on stderr.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

# Radiance 6 from PyPI: pyradiance's wheel carries the binaries (bin/) and their library (lib/).
VENV=target/venv-radiance
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import pyradiance" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet "pyradiance==1.3.1"
fi
PKG="$("$VENV/bin/python" -c 'import os, pyradiance; print(os.path.dirname(pyradiance.__file__))')"
export PATH="$PKG/bin:$PATH"
export RAYPATH=".:$PKG/lib"
rtrace -version >&2

echo "build: cargo build --release" >&2
CARGO_PROFILE_RELEASE_LTO="${CARGO_PROFILE_RELEASE_LTO:-false}" \
CARGO_PROFILE_RELEASE_CODEGEN_UNITS="${CARGO_PROFILE_RELEASE_CODEGEN_UNITS:-16}" \
    cargo build --release --quiet

exec "$VENV/bin/python" bench/radiance/run.py "$@"
