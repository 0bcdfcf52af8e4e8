#!/usr/bin/env bash
# Create the Python virtual environment used to regenerate data/, to build and test the Python
# package (tests/python/), and to run the colour-science validation test
# (tests/colour_science.rs) and the Radiance sky and EPW comparisons (tests/daylight_peers.rs).
#
#   scripts/setup_python.sh            # creates <repo>/target/venv if missing, installs pins
#   PYTHON=python3.11 scripts/setup_python.sh
#
# The tests look for the interpreter in $CANDELA_PYTHON, else <repo>/target/venv/bin/python.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/target/venv"
PYTHON="${PYTHON:-python3}"

# Pinned versions: colour-science 0.4.7 and the only dependency it pulls in (numpy);
# pyradiance 1.3.1 (Radiance 6's binaries: gensky, gendaylit, rtrace) and ladybug-core
# 0.44.62 (EPW weather files) for the daylight tests; luxpy 1.12.5 (CIE S 026 alpha-opic
# quantities, CIE 191 mesopic photometry; tests/colour_health.rs and data/alpha-opic-*.csv),
# which imports scipy and matplotlib at start-up; OpenImageIO 3.2.2.0, through which
# colour-science reads spectral OpenEXR files (tests/health_render.rs). numpy stays below 2.4:
# luxpy 1.12.5 calls float() on 1-element arrays, which numpy 2.4 refuses. maturin 1.16.0 builds
# the Python package into this venv and pytest 9.2.0 runs its tests (tests/python/); selenium
# 4.51.0 drives Debian's chromium through chromium-driver in the HTML report's browser test
# (tests/browser/).
PINS=(
  "colour-science==0.4.7"
  "numpy==2.3.5"
  "luxpy==1.12.5"
  "scipy==1.17.1"
  "matplotlib==3.10.7"
  "pyradiance==1.3.1"
  "ladybug-core==0.44.62"
  "ladybug-geometry==1.35.6"
  "maturin==1.16.0"
  "pytest==9.2.0"
  "openimageio==3.2.2.0"
  "selenium==4.51.0"
)

if [ ! -x "$VENV/bin/python" ]; then
  echo "creating $VENV with $($PYTHON --version 2>&1)"
  mkdir -p "$ROOT/target"
  "$PYTHON" -m venv "$VENV"
fi

"$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${PINS[@]}"
"$VENV/bin/python" - <<'PY'
import warnings
warnings.filterwarnings("ignore")
import colour, numpy
assert colour.__version__ == "0.4.7", colour.__version__
import pyradiance, ladybug.epw
import luxpy
assert luxpy.__version__.lstrip("v") == "1.12.5", luxpy.__version__
print(f"ok: colour-science {colour.__version__}, luxpy {luxpy.__version__}, numpy {numpy.__version__}")
PY
