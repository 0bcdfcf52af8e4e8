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
if [ ! -f "$work/exr7-16384.exr" ]; then
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
    "bench traversal, 8192^2 rays|bench traversal --resolution 8192 --triangles 1000|--resolution"
    "glTF buffer /etc/passwd|render --quiet --out out/gb gltf-buffer-etc.ron|outside the model's folder"
    "glTF image ../../etc/passwd|render --quiet --out out/gi gltf-image-up.ron|outside the model's folder"
    "glTF POSITION names no accessor|render --quiet --out out/ga gltf-no-accessor.ron|accessor 9"
    "glTF node scaled past 10^12 m|render --quiet --out out/gn gltf-far-node.ron|gltf-far-node"
    "OBJ mtllib /etc/passwd|render --quiet --out out/om obj-mtllib-etc.ron|outside the model's folder"
    "OBJ vertex at 10^18 m|render --quiet --out out/ov obj-far-vertex.ron|vertex 1"
    "OBJ naming its library 5000 times|render --quiet --out out/o5 obj-5000-mtllib.ron|obj-5000-mtllib"
    "HDR VIEW -vth -vh 300, glare|glare view-vth-300.hdr|view-vth-300.hdr"
    "HDR VIEW -vtv -vh 400, glare|glare view-vtv-400.hdr|view-vtv-400.hdr"
    "HDR of 200 kB declaring 16384^2, probe|probe big-16384.hdr 0 0|big-16384.hdr"
    "HDR declaring 16384^2, report|report big-16384.hdr -o out/big.html|big-16384.hdr"
    "HDR declaring 16384^2, falsecolour|falsecolour -o out/big.png big-16384.hdr|big-16384.hdr"
    "HDR declaring 16384^2, glare|glare big-16384.hdr|big-16384.hdr"
    "EXR bomb, report|report bomb-65536.exr -o out/bomb.html|bomb-65536.exr"
    "HDR 16384^2 in 197 kB, probe|probe hdr-16384.hdr 0 0|hdr-16384.hdr"
    "HDR 16384^2 in 197 kB, report|report -o out/hdr.html hdr-16384.hdr|hdr-16384.hdr"
    "HDR 16384^2 in 197 kB, falsecolour|falsecolour -o out/hdr.png hdr-16384.hdr|hdr-16384.hdr"
    "HDR 16384^2 fisheye in 197 kB, glare|glare hdr-16384v.hdr|hdr-16384v.hdr"
    "HDR declaring 30000^2 in 200 kB|probe hdr-30000.hdr 0 0|hdr-30000.hdr"
    "EXR of 7 channels 16384^2, probe|probe exr7-16384.exr 0 0|exr7-16384.exr"
    "EPW elevation 1e300 m|annual --quiet annual.ron --weather epw-elevation.epw -o out/e|epw-elevation.epw: line 1"
    "EPW time zone 5,5|annual --quiet annual.ron --weather epw-timezone-comma.epw -o out/e|epw-timezone-comma.epw: line 1"
    "EPW record of 31 February|annual --quiet annual.ron --weather epw-feb31.epw -o out/e|epw-feb31.epw: line"
    "EPW hour repeated|annual --quiet annual.ron --weather epw-repeated.epw -o out/e|epw-repeated.epw: line"
    "EPW hours swapped|annual --quiet annual.ron --weather epw-swapped.epw -o out/e|epw-swapped.epw: line"
    "EPW irradiance 9999 (missing)|annual --quiet annual.ron --weather epw-missing.epw -o out/e|epw-missing.epw: line"
    "EPW direct sun at 02:00|annual --quiet annual.ron --weather epw-night-sun.epw -o out/e|epw-night-sun.epw: line"
    "EPW of 48 hours, annual|annual --quiet annual.ron --weather epw-48-hours.epw -o out/e|epw-48-hours.epw"
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
