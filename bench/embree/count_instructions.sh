#!/usr/bin/env bash
# Instructions per ray of candela's and Embree's kernels (callgrind), as in the "sixth look" of
# bench/embree/README.md. Needs valgrind, binutils (objdump, addr2line) and python3.
#
#   bash bench/embree/count_instructions.sh [CANDELA_BINARY]
#
# Uses the 100 k-triangle mesh with 128² primary rays plus their diffuse and shadow rays.
# CANDELA_BINARY defaults to target/release/candela (build it first; a build without LTO gives
# a more readable attribution). Output goes to target/bench/callgrind/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"
candela="${1:-$root/target/release/candela}"
embree_trace="$(bash bench/embree/build.sh)"
out="$root/target/bench/callgrind"
mkdir -p "$out"
rays="$out/rays100k.bin"
# Ray counts per batch, from the export's own summary.
counts="$("$candela" bench traversal --triangles 100000 --resolution 128 --export "$rays" 2>&1 | tail -1)"
primary=$(sed -E 's/.* ([0-9]+) primary.*/\1/' <<<"$counts")
diffuse=$(sed -E 's/.* ([0-9]+) diffuse.*/\1/' <<<"$counts")
shadow=$(sed -E 's/.* ([0-9]+) shadow.*/\1/' <<<"$counts")
closest=$((primary + diffuse))
for what in intersect_basic occluded; do
  valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file="$out/candela.$what" \
    --toggle-collect="candela::geometry::scene::SceneGeometry::$what" \
    "$candela" bench traversal --rays "$rays" --threads 1 --reps 1 --build-reps 1 --record basic \
    >/dev/null 2>&1
done
valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file="$out/embree" \
  --toggle-collect=worker "$embree_trace" "$rays" --quality medium --threads 1 --reps 1 \
  --build-reps 1 >/dev/null 2>&1
py="python3 bench/embree/count_instructions.py"
echo "candela, closest hit ($closest rays), instructions per ray:"
$py candela "$out/candela.intersect_basic" "$candela" "$closest"
echo
echo "candela, any hit ($shadow rays), instructions per ray:"
$py candela "$out/candela.occluded" "$candela" "$shadow"
echo
lib="$(ldd "$embree_trace" | awk '/libembree3/ {print $3}')"
echo "Embree, hot straight-line runs (per closest-hit ray; the any-hit kernel's runs read per"
echo "shadow ray after multiplying by $closest/$shadow):"
$py blocks "$out/embree" "$lib" "$closest" 1.0
