#!/usr/bin/env bash
# candela against Radiance (rtrace -I) on an office work-plane grid, in one command
# (see bench/README.md, "Against Radiance"):
#
#   bash bench/radiance.sh                  # N = 6 and 48, references (cached), 3 alternated rounds
#   bash bench/radiance.sh --quick          # smoke run, a minute or two
#   bash bench/radiance.sh --ns 6,48,500    # also 500 luminaires (an open-plan floor; hours)
#   bash bench/radiance.sh --candela PATH   # another candela binary (no build)
#   bash bench/radiance.sh --images         # luminance and illuminance images: rpict against candela
#   bash bench/radiance.sh --images --quick
#
# Arguments go to bench/radiance/run.py, or with --images to bench/radiance/images.py (--help
# lists them). Results: a Markdown table on stdout, target/bench/radiance/results.json or
# images-results.json, progress on stderr.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

SCRIPT=bench/radiance/run.py
if [ "${1:-}" = "--images" ]; then
    SCRIPT=bench/radiance/images.py
    shift
fi

# Radiance 6 from PyPI: pyradiance's wheel carries the binaries (bin/) and their library (lib/).
VENV=target/venv-radiance
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import pyradiance" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet "pyradiance==1.3.1"
fi
# candela's EXR images, for images.py.
if ! "$VENV/bin/python" -c "import OpenEXR" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet "OpenEXR==3.5.3"
fi
PKG="$("$VENV/bin/python" -c 'import os, pyradiance; print(os.path.dirname(pyradiance.__file__))')"
export PATH="$PKG/bin:$PATH"
export RAYPATH=".:$PKG/lib"
rtrace -version >&2

if [[ " $* " != *" --candela "* ]]; then
    echo "build: cargo build --release" >&2
    CARGO_PROFILE_RELEASE_LTO="${CARGO_PROFILE_RELEASE_LTO:-false}" \
    CARGO_PROFILE_RELEASE_CODEGEN_UNITS="${CARGO_PROFILE_RELEASE_CODEGEN_UNITS:-16}" \
        nice -n 19 cargo build --release --quiet
fi

exec nice -n 19 "$VENV/bin/python" "$SCRIPT" "$@"
