#!/usr/bin/env bash
# Many-lights benchmark: CPU time for every work-plane grid point of a 500-luminaire building
# (bench/many_lights/gen_scene.py) to reach a relative standard error of TARGET (default 0.02)
# with light_sampler Bvh and Power, RUNS (default 3) alternated runs each, medians and their
# ratio; then the one-light Cornell box (scenes/bench-cornell.ron) with each sampler, to show the
# BVH's overhead where there is nothing to choose. CPU time (user + system) is robust to other
# processes on the machine; run it on otherwise idle cores for wall times.
#
# Usage: bench/many_lights.sh [TARGET] [RUNS]   (build first: cargo build --release;
# CANDELA=PATH times another binary)
set -euo pipefail
cd "$(dirname "$0")/.."
TARGET=${1:-0.02}
RUNS=${2:-3}
BIN=${CANDELA:-$PWD/target/release/candela}
DIR=$PWD/target/many_lights
mkdir -p "$DIR"
[ -x "$BIN" ] || { echo "build first: cargo build --release" >&2; exit 1; }

cpu() { # cpu seconds (user + system) of a command
  /usr/bin/time -o "$DIR/time.txt" -f "%U %S" "$@" >/dev/null 2>&1
  awk '{print $1 + $2}' "$DIR/time.txt"
}
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

for s in Bvh Power; do
  python3 bench/many_lights/gen_scene.py --out "$DIR/$s.ron" --sampler "$s" --target "$TARGET"
  mkdir -p "$DIR/out-$s"
  # Cornell box with this sampler.
  sed "s/render: (spp: 64,/render: (light_sampler: $s, spp: 64,/" scenes/bench-cornell.ron >"$DIR/cornell-$s.ron"
  grep -q "light_sampler: $s" "$DIR/cornell-$s.ron"
  mkdir -p "$DIR/out-cornell-$s"
done

declare -A T C
for r in $(seq "$RUNS"); do
  for s in Bvh Power; do
    t=$(cpu "$BIN" render "$DIR/$s.ron" --out "$DIR/out-$s/" --quiet --overwrite --checkpoint-interval 0s)
    T[$s]+="$t "
    avg=$(python3 -c "
import json; r = json.load(open('$DIR/out-$s/$s.report.json')); g = r['grids'][0]
v = [x for row in g['values'] for x in row]; e = [x for row in g['stderr'] for x in row]
print(f'E_avg {sum(v) / len(v):.1f} lx, worst relative se {max(a / b for a, b in zip(e, v)):.4f}, rays {r[\"timing\"][\"rays\"]}')")
    echo "run $r $s: building ${t} s CPU ($avg)"
    t=$(cpu "$BIN" render "$DIR/cornell-$s.ron" --out "$DIR/out-cornell-$s/" --quiet --overwrite --checkpoint-interval 0s)
    C[$s]+="$t "
    echo "run $r $s: Cornell box ${t} s CPU"
  done
done
for s in Bvh Power; do
  T[$s]=$(tr ' ' '\n' <<<"${T[$s]}" | grep . | median)
  C[$s]=$(tr ' ' '\n' <<<"${C[$s]}" | grep . | median)
done
echo "building, 500 luminaires, grid to relative se $TARGET: median CPU Bvh ${T[Bvh]} s, Power ${T[Power]} s, ratio $(awk "BEGIN {printf \"%.2f\", ${T[Power]} / ${T[Bvh]}}")"
echo "Cornell box (1 light, 256x256 at 64 spp): median CPU Bvh ${C[Bvh]} s, Power ${C[Power]} s, Bvh/Power $(awk "BEGIN {printf \"%.3f\", ${C[Bvh]} / ${C[Power]}}")"
