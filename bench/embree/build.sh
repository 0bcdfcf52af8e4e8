#!/usr/bin/env bash
# Builds bench/embree/embree_trace.c into target/bench/embree_trace against Debian's Embree 3
# (libembree-dev, installed with apt-get if its header is missing).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="$root/target/bench"
mkdir -p "$out"
if [ ! -f /usr/include/embree3/rtcore.h ]; then
    echo "libembree-dev is not installed; installing it (Debian package, Embree 3)" >&2
    if [ "$(id -u)" = 0 ]; then sudo=""; else sudo="sudo"; fi
    $sudo apt-get install -y libembree-dev >/dev/null || {
        $sudo apt-get update >/dev/null && $sudo apt-get install -y libembree-dev >/dev/null
    }
fi
gcc -O3 -march=native -std=c11 -Wall -Wextra -o "$out/embree_trace" \
    "$root/bench/embree/embree_trace.c" -lembree3 -lpthread -lm
echo "$out/embree_trace"
