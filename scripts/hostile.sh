#!/usr/bin/env bash
# The large hostile cases, each under a memory cap and a time limit: every one must end in an
# error naming the file (exit 1 or 2) or in a finished render (exit 0), within the limit, never
# in a crash (a signal, exit 101 or 134) or a kill by the limit. Prints a Markdown table and
# exits 1 if any case breaks that promise.
#
#   bash scripts/hostile.sh [CANDELA] [WORKDIR]
#
# CANDELA defaults to target/release/candela (built if missing); WORKDIR to target/hostile.
# HOSTILE_MEM_KB (default 4194304 = 4 GiB of address space) and HOSTILE_TIMEOUT (default 120 s)
# set the limits. The inputs are written by scripts/hostile_inputs.py (about 200 MB).
set -u
cd "$(dirname "$0")/.."
bin=${1:-target/release/candela}
work=${2:-target/hostile}
mem_kb=${HOSTILE_MEM_KB:-4194304}
limit=${HOSTILE_TIMEOUT:-120}
if [ ! -x "$bin" ]; then
    cargo build --release --quiet || exit 1
fi
bin=$(realpath "$bin")
mkdir -p "$work"
work=$(realpath "$work")
if [ ! -f "$work/bomb-65536.exr" ]; then
    python3 scripts/hostile_inputs.py "$work" || exit 1
fi
rm -f "$work/fifo.ron" && mkfifo "$work/fifo.ron"
mkdir -p "$work/out"

# name | command (run in $work) | the file a refusal must name
cases=(
    "10^5 coincident triangles|render --quiet --out out/c coincident-1e5.ron|coincident-1e5"
    "fan of 10^6 triangles|render --quiet --out out/f fan-1e6.ron|fan-1e6"
    "one face of 10^6 vertices|render --quiet --out out/p face-1e6.ron|face-1e6"
    "mesh is /dev/zero|render --quiet --out out/z mesh-dev-zero.ron|/dev/zero"
    "mtllib is /dev/zero|render --quiet --out out/m mtllib-dev-zero.ron|/dev/zero"
    "scene is a FIFO|render --quiet --out out/q fifo.ron|fifo.ron"
    "grid of 10^6 x 1|render --quiet --out out/g1 grid-1e6x1.ron|grids[0]"
    "grid of 10^4 x 10^4|render --quiet --out out/g2 grid-1e4x1e4.ron|grids[0]"
    "film of 65536^2|render --quiet --out out/h film-65536.ron|film-65536"
    "EXR bomb, probe|probe bomb-65536.exr 0 0|bomb-65536.exr"
    "EXR bomb, falsecolour|falsecolour -o out/bomb.png bomb-65536.exr|bomb-65536.exr"
    "IES claiming 10^9 angles|render --quiet --out out/i huge-angles.ron|huge-angles"
    "bench, 10^8 triangles|bench --spp 1 --triangles 100000000|triangles"
)

echo "| case | exit | seconds | peak RSS (MB) | outcome | message (first line) |"
echo "|---|---:|---:|---:|---|---|"
failed=0
for c in "${cases[@]}"; do
    IFS='|' read -r name cmd needle <<<"$c"
    start=$(date +%s.%N)
    (
        cd "$work" &&
            ulimit -v "$mem_kb" &&
            exec /usr/bin/time -f "%M" -o "$work/out/rss" timeout -k 5 "$limit" "$bin" $cmd \
                >"$work/out/stdout" 2>"$work/out/stderr"
    )
    code=$?
    secs=$(echo "$(date +%s.%N) - $start" | bc)
    rss=$(tail -1 "$work/out/rss" 2>/dev/null | grep -E '^[0-9]+$' || echo 0)
    msg=$(grep -v '^Command exited' "$work/out/stderr" | head -1 | cut -c1-110 | tr '|' '/')
    if [ "$code" = 0 ]; then
        outcome="rendered"
    elif { [ "$code" = 1 ] || [ "$code" = 2 ]; } && grep -qF -- "$needle" "$work/out/stderr"; then
        outcome="refused, names it"
    elif [ "$code" = 124 ] || [ "$code" = 137 ]; then
        outcome="**TIMEOUT**"
        failed=1
    else
        outcome="**FAILED**"
        failed=1
    fi
    printf '| %s | %s | %.1f | %d | %s | %s |\n' "$name" "$code" "$secs" $((rss / 1024)) "$outcome" "$msg"
done
rm -f "$work/fifo.ron"
exit $failed
