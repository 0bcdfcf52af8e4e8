#!/usr/bin/env bash
# candela's BVH traversal against Embree on the same mesh and rays (see README.md).
#
#   bash bench/embree/run.sh [extra `candela bench traversal` options, e.g. --reps 9]
#
# Environment: TRIANGLES (default 1000000), RESOLUTION (primary rays RES×RES, default 1024).
# Builds release candela and bench/embree/embree_trace.c, exports the mesh and rays to
# target/bench/rays.bin, then times both (alternating, medians) and prints Markdown tables.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
triangles="${TRIANGLES:-1000000}"
resolution="${RESOLUTION:-1024}"
target="${CARGO_TARGET_DIR:-$root/target}"
cargo build --release --quiet
candela="$target/release/candela"
embree_trace="$(bash bench/embree/build.sh)"
rays="$root/target/bench/rays.bin"
"$candela" bench traversal --triangles "$triangles" --resolution "$resolution" --export "$rays" >&2
echo "Date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2/1048576}' /proc/meminfo); load average at start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
"$candela" bench traversal --rays "$rays" --embree "$embree_trace" "$@"
echo
echo "Load average at the end: $(cut -d' ' -f1-3 /proc/loadavg) (above ~0.5 means other processes shared the 2 cores)."
