#!/usr/bin/env bash
# Check that two builds of candela give the same outputs (a refactor must not move a pixel):
#   bash scripts/same-output.sh OLD_BIN NEW_BIN [WORK_DIR]
# Renders every scene in scenes/ at a fixed seed and a few samples per pixel (with and without
# --illuminance/--falsecolour/--save-state), one adaptive render, a resumed render, a merge,
# refused options (messages and exit codes), and runs probe, falsecolour, luminaire, spectrum,
# convert, glare, report and two small annual runs (one with --view) with both binaries; then
# compares EXR pixel data and PNG/CSV bytes exactly, report JSON numbers exactly (timings
# excepted) and standard output with timings removed (scripts/same_output.py). Exit 0 when everything matches.
set -euo pipefail
old=$(realpath "$1"); new=$(realpath "$2")
root="$(cd "$(dirname "$0")/.." && pwd)"
work="${3:-$(mktemp -d)}"
mkdir -p "$work"; work=$(realpath "$work")
run_all() {
  local bin=$1 out=$2
  rm -rf "$out"; mkdir -p "$out"
  for scene in "$root"/scenes/*.ron; do
    name=$(basename "$scene" .ron)
    "$bin" render "$scene" --spp 2 --seed 7 --quiet --checkpoint-interval 0s --out "$out/$name" >"$out/$name.txt" 2>&1
    "$bin" render "$scene" --spp 1 --seed 11 --quiet --checkpoint-interval 0s --illuminance --falsecolour --save-state --units imperial --out "$out/$name-e" >"$out/$name-e.txt" 2>&1
  done
  "$bin" render "$root/scenes/furnace.ron" --target-error 5% --max-spp 64 --seed 3 --quiet --checkpoint-interval 0s --out "$out/furnace-adaptive" >"$out/furnace-adaptive.txt" 2>&1
  "$bin" render "$root/scenes/furnace.ron" --spp 1 --seed 12 --quiet --checkpoint-interval 0s --illuminance --save-state --out "$out/furnace-e2" >"$out/furnace-e2.txt" 2>&1
  "$bin" merge "$out/furnace-e.state" "$out/furnace-e2.state" -o "$out/merged" >"$out/merge.txt" 2>&1
  "$bin" probe "$out/office-e.exr" 100 100 --radius 3 --json >"$out/probe.txt" 2>&1
  "$bin" probe "$out/office-e.exr" 200 50 --units imperial >>"$out/probe.txt" 2>&1
  "$bin" falsecolour "$out/office-e.exr" --quantity illuminance --scale log --steps 8 --contours -o "$out/office-fc.png" >"$out/falsecolour.txt" 2>&1
  for f in "$root"/data/luminaires/*; do
    [ -f "$f" ] || continue
    "$bin" luminaire "$f" --diagram "$out/$(basename "$f").polar.png" >"$out/luminaire-$(basename "$f").txt" 2>&1
  done
  "$bin" render "$root/scenes/cornell-box.ron" --spp 1 --seed 5 --quiet --checkpoint-interval 0s --save-state --out "$out/resumed" >"$out/resume.txt" 2>&1
  "$bin" render "$root/scenes/cornell-box.ron" --spp 3 --seed 5 --quiet --checkpoint-interval 0s --resume --out "$out/resumed" >>"$out/resume.txt" 2>&1
  # Refusals: their messages and exit codes.
  for args in "--threads 0" "--exposure 1e9" "--target-error 5% --target-fraction 2" "--max-spp 0" "--resume --seed 99"; do
    # shellcheck disable=SC2086
    "$bin" render "$root/scenes/cornell-box.ron" --quiet --out "$out/resumed" $args >>"$out/refusals.txt" 2>&1 && echo "exit 0" >>"$out/refusals.txt" || echo "exit $?" >>"$out/refusals.txt"
  done
  "$bin" render "$out/no-such-scene.ron" >>"$out/refusals.txt" 2>&1 || echo "exit $?" >>"$out/refusals.txt"
  "$bin" merge "$out/furnace-e.state" "$out/furnace-e.state" -o "$out/twice" >>"$out/refusals.txt" 2>&1 || echo "exit $?" >>"$out/refusals.txt"
  "$bin" spectrum D65 --json >"$out/spectrum.txt" 2>&1
  "$bin" spectrum blackbody:3000K >>"$out/spectrum.txt" 2>&1
  "$bin" convert 100 lx fc >"$out/convert.txt" 2>&1
  "$bin" spectrum FL2 --observer 1964 --method astm-e308 --efficacy-rule trapezoid --cvg "$out/fl2-cvg.png" >>"$out/spectrum.txt" 2>&1
  "$bin" spectrum LED-B3 --json >>"$out/spectrum.txt" 2>&1
  "$bin" spectrum "$root/data/cornell-box.csv" --interpolation linear >>"$out/spectrum.txt" 2>&1 || echo "exit $?" >>"$out/spectrum.txt"
  # The rest of the subcommands: glare, the HTML report, an annual run (with the view and the
  # coefficients) and its refusals.
  "$bin" glare "$out/glare-office.exr" --json >"$out/glare.txt" 2>&1 || echo "exit $?" >>"$out/glare.txt"
  "$bin" glare "$out/glare-office.hdr" >>"$out/glare.txt" 2>&1 || echo "exit $?" >>"$out/glare.txt"
  "$bin" report "$out/office-e.exr" -o "$out/office-report.html" >"$out/report.txt" 2>&1 || echo "exit $?" >>"$out/report.txt"
  local epw="$work/year.epw"
  "$bin" annual "$root/scenes/annual-shoebox.ron" --weather "$epw" --mf 1 --sky-samples 64 --sun-samples 32 --direct-samples 8 --draws 20 --coefficients --seed 4 --threads 2 --quiet --out "$out/annual" >"$out/annual.txt" 2>&1 || echo "exit $?" >>"$out/annual.txt"
  "$bin" annual "$root/scenes/annual-glare.ron" --weather "$epw" --mf 1 --sky-samples 32 --sun-samples 16 --direct-samples 4 --draws 0 --view --view-resolution 16 --view-sky-samples 8 --view-sun-samples 2 --seed 4 --threads 2 --quiet --out "$out/annual-view" >"$out/annual-view.txt" 2>&1 || echo "exit $?" >>"$out/annual-view.txt"
  for args in "--mf 9" "--occupied 18-8" "--udi x-3" "--draws 1"; do
    # shellcheck disable=SC2086
    "$bin" annual "$root/scenes/annual-shoebox.ron" --weather "$epw" --quiet --out "$out/annual-refused" $args >>"$out/annual-refusals.txt" 2>&1 && echo "exit 0" >>"$out/annual-refusals.txt" || echo "exit $?" >>"$out/annual-refusals.txt"
  done
}
# A whole synthetic year (every 8th day lit) for the annual runs: needs ladybug-core in target/venv
# (scripts/setup_python.sh).
"$root/target/venv/bin/python" "$root/scripts/synthetic_epw.py" "$work/year.epw" --every 8 >/dev/null
(cd "$work" && run_all "$old" "$work/old")
(cd "$work" && run_all "$new" "$work/new")
python3 "$root/scripts/same_output.py" "$work/old" "$work/new"
