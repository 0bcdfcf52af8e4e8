#!/usr/bin/env bash
# Install what bench/compare.py needs, idempotently (a second run takes about a second):
#   * target/bench-venv: Python venv with Mitsuba 3 (pinned) and numpy, from PyPI;
#   * GNU time (/usr/bin/time, for the peak RSS of each render), from Debian if missing;
#   * a libLLVM recent enough for Dr.Jit's LLVM backend (llvm_ad_* variants), from Debian if
#     missing. Debian 12's default LLVM 14 (and 15) cannot compile Dr.Jit 1.5's kernels
#     ("LLVM ERROR: Cannot select: ... fminimum"), so we take the newest libLLVM >= 16 there is
#     and install libllvm19 if there is none.
# Prints `export DRJIT_LIBLLVM_PATH=...` as its last line for bench/mitsuba.sh to eval.
#
#   bench/setup_mitsuba.sh            PYTHON=python3.11 bench/setup_mitsuba.sh
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/target/bench-venv"
PYTHON="${PYTHON:-python3}"
PINS=("mitsuba==3.9.1" "drjit==1.5.0" "numpy==2.4.6")

log() { echo "setup: $*" >&2; }

apt_install() {
  # apt-get install, refreshing the package lists once if the package is unknown.
  if ! apt-get install -y "$@" >&2; then
    apt-get update >&2 && apt-get install -y "$@" >&2
  fi
}

# --- Python environment -------------------------------------------------------------------
if [ ! -x "$VENV/bin/python" ]; then
  log "creating $VENV with $($PYTHON --version 2>&1)"
  mkdir -p "$ROOT/target"
  "$PYTHON" -m venv "$VENV"
fi
if ! "$VENV/bin/python" - <<'PY' 2>/dev/null
import importlib.metadata as md
want = {"mitsuba": "3.9.1", "drjit": "1.5.0", "numpy": "2.4.6"}
assert all(md.version(k) == v for k, v in want.items())
PY
then
  log "installing ${PINS[*]} into $VENV"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "${PINS[@]}" >&2
fi

# --- GNU time -----------------------------------------------------------------------------
if [ ! -x /usr/bin/time ]; then
  log "installing GNU time"
  apt_install time
fi

# --- LLVM for Dr.Jit ----------------------------------------------------------------------
newest_llvm() {
  # Path of the newest libLLVM with major version >= 16, or nothing.
  local best="" best_v=0 f v
  for f in /usr/lib/*-linux-gnu/libLLVM*.so* /usr/lib/llvm-*/lib/libLLVM*.so*; do
    [ -e "$f" ] || continue
    v="$(basename "$f" | grep -oE '[0-9]+' | head -1 || true)"
    [ -n "$v" ] || continue
    if [ "$v" -ge 16 ] && [ "$v" -gt "$best_v" ]; then best="$f"; best_v="$v"; fi
  done
  echo "$best"
}
LLVM_LIB="${DRJIT_LIBLLVM_PATH:-$(newest_llvm)}"
if [ -z "$LLVM_LIB" ]; then
  log "no libLLVM >= 16 found: installing libllvm19 (fallback libllvm16)"
  apt_install libllvm19 || apt_install libllvm16
  LLVM_LIB="$(newest_llvm)"
fi
[ -n "$LLVM_LIB" ] || { log "no usable libLLVM"; exit 1; }

# --- smoke test: a 1-spp render with each variant (also warms the kernel cache) -------------
for variant in llvm_ad_spectral scalar_spectral; do
  if ! DRJIT_LIBLLVM_PATH="$LLVM_LIB" "$VENV/bin/python" "$ROOT/bench/mitsuba/render.py" \
      --variant "$variant" --spp 1 --out "$ROOT/target/bench-smoke.npy" >/dev/null 2>"$ROOT/target/bench-smoke.log"; then
    log "Mitsuba $variant does not run (with DRJIT_LIBLLVM_PATH=$LLVM_LIB); see target/bench-smoke.log"
    tail -5 "$ROOT/target/bench-smoke.log" >&2
    exit 1
  fi
done
rm -f "$ROOT/target/bench-smoke.npy" "$ROOT/target/bench-smoke.log"
log "ok: $("$VENV/bin/python" -c 'import mitsuba, drjit, numpy; print(f"mitsuba {mitsuba.__version__}, drjit {drjit.__version__}, numpy {numpy.__version__}")'), LLVM $LLVM_LIB"
echo "export DRJIT_LIBLLVM_PATH=$LLVM_LIB"
