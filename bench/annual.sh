#!/usr/bin/env bash
# Annual daylight of scenes/annual-shoebox.ron: candela against Radiance's matrix method
# (scripts/radiance_annual.py), run time and peak memory side by side, alternated, medians
# (see bench/README.md, "Annual daylight: shoebox"):
#
#   bash bench/annual.sh                          # synthetic year, 3 alternated rounds
#   bash bench/annual.sh --rounds 1               # one round each
#   bash bench/annual.sh --epw FILE.epw           # another weather file
#   bash bench/annual.sh --candela PATH           # candela binary (default target/release/candela)
#   bash bench/annual.sh --candela-args "--sky-samples 8192" --radiance-args "--ad 32768"
#   bash bench/annual.sh --radiance-args "--sun-ir patches"   # inter-reflected sun from patch suns
#
# Radiance's defaults: the direct sun as 37 sub-suns over the disk (--sun-disk 37), each sunny
# hour's own sun for the inter-reflected sun (--sun-ir hourly, the costlier part on a full year).
#
# Needs the Python venv of scripts/setup_python.sh (ladybug-core for the synthetic year,
# pyradiance for Radiance's binaries, numpy). Results in target/bench/annual/: every run's
# /usr/bin/time -v log and JSON, and a Markdown table on stdout; progress on stderr.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

ROUNDS=3
EPW=""
CANDELA="$ROOT/target/release/candela"
CANDELA_ARGS=""
RADIANCE_ARGS=""
while [ $# -gt 0 ]; do
    case "$1" in
        --rounds) ROUNDS="$2"; shift 2 ;;
        --epw) EPW="$2"; shift 2 ;;
        --candela) CANDELA="$2"; shift 2 ;;
        --candela-args) CANDELA_ARGS="$2"; shift 2 ;;
        --radiance-args) RADIANCE_ARGS="$2"; shift 2 ;;
        *) echo "unknown argument: $1" >&2; exit 2 ;;
    esac
done

PY="${CANDELA_PYTHON:-$ROOT/target/venv/bin/python}"
if [ ! -x "$PY" ]; then
    bash scripts/setup_python.sh
fi
PKG="$("$PY" -c 'import os, pyradiance; print(os.path.dirname(pyradiance.__file__))')"
export PATH="$PKG/bin:$PATH"
export RAYPATH=".:$PKG/lib"

OUT="$ROOT/target/bench/annual"
mkdir -p "$OUT"
if [ -z "$EPW" ]; then
    EPW="$OUT/synthetic.epw"
    "$PY" scripts/synthetic_epw.py "$EPW"
fi
EPW="$(cd "$(dirname "$EPW")" && pwd)/$(basename "$EPW")"

run_candela() {
    local r="$1"
    if [ ! -x "$CANDELA" ]; then
        echo "candela: no binary at $CANDELA (cargo build --release, or --candela PATH); skipped" >&2
        return 0
    fi
    echo "round $r: candela annual" >&2
    # shellcheck disable=SC2086
    nice -n 19 /usr/bin/time -v -o "$OUT/candela-$r.time" \
        "$CANDELA" annual scenes/annual-shoebox.ron --weather "$EPW" --out "$OUT/candela-$r" \
        --quiet $CANDELA_ARGS >"$OUT/candela-$r.log"
}

run_radiance() {
    local r="$1"
    echo "round $r: scripts/radiance_annual.py" >&2
    # shellcheck disable=SC2086
    nice -n 19 /usr/bin/time -v -o "$OUT/radiance-$r.time" \
        "$PY" scripts/radiance_annual.py "$EPW" --work "$OUT/radiance-work-$r" $RADIANCE_ARGS \
        >"$OUT/radiance-$r.json"
}

for r in $(seq 1 "$ROUNDS"); do
    # Alternate which tool goes first, so a drift in the machine's load hits both.
    if [ $((r % 2)) -eq 1 ]; then
        run_candela "$r"; run_radiance "$r"
    else
        run_radiance "$r"; run_candela "$r"
    fi
done

"$PY" - "$OUT" "$ROUNDS" <<'PY'
import json, os, re, statistics, sys

out, rounds = sys.argv[1], int(sys.argv[2])


def gnu_time(path):
    """Wall seconds, CPU seconds and peak RSS (MiB) from a /usr/bin/time -v log."""
    text = open(path).read()
    m = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text)
    wall = 0.0
    for part in m.group(1).split(":"):
        wall = wall * 60 + float(part)
    user = float(re.search(r"User time \(seconds\): (\S+)", text).group(1))
    sys_ = float(re.search(r"System time \(seconds\): (\S+)", text).group(1))
    rss = float(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1)) / 1024
    return wall, user + sys_, rss


def find(obj, key):
    """First value under `key` anywhere in a JSON tree (candela's layout per grid)."""
    if isinstance(obj, dict):
        if key in obj:
            return obj[key]
        obj = list(obj.values())
    if isinstance(obj, list):
        for v in obj:
            f = find(v, key)
            if f is not None:
                return f
    return None


def as_fraction(v):
    if isinstance(v, dict):  # a value with its interval
        for k in ("value", "estimate", "mean"):
            if k in v:
                return v[k]
    return v


rows = []
for tool in ("candela", "radiance"):
    runs = [os.path.join(out, "%s-%d.time" % (tool, r)) for r in range(1, rounds + 1)]
    runs = [gnu_time(p) for p in runs if os.path.exists(p)]
    if not runs:
        continue
    sda = ase = None
    if tool == "candela":
        path = os.path.join(out, "candela-1.annual.json")
        if os.path.exists(path):
            j = json.load(open(path))
            sda, ase = as_fraction(find(j, "sda")), as_fraction(find(j, "ase"))
    else:
        j = json.load(open(os.path.join(out, "radiance-1.json")))
        sda, ase = j["metrics"]["sda300_50"], j["metrics"]["ase1000_250h"]
    rows.append((tool, len(runs), statistics.median(r[0] for r in runs),
                 statistics.median(r[1] for r in runs), statistics.median(r[2] for r in runs),
                 sda, ase))

fmt = lambda v: "-" if not isinstance(v, (int, float)) else "%.1f %%" % (100 * v)  # noqa: E731
print("| tool | runs | wall s (median) | CPU s (median) | peak RSS MiB (median) | sDA300/50% | ASE1000,250h |")
print("|---|---|---|---|---|---|---|")
for t, n, w, c, m, s, a in rows:
    print("| %s | %d | %.1f | %.1f | %.0f | %s | %s |" % (t, n, w, c, m, fmt(s), fmt(a)))

# Per point: DA300 and direct-sun hours > 1000 lx of round 1 (same point order: x fastest).
cpath, rpath = os.path.join(out, "candela-1.annual.json"), os.path.join(out, "radiance-1.json")
if os.path.exists(cpath) and os.path.exists(rpath):
    pts = find(json.load(open(cpath)), "points") or []
    rm = json.load(open(rpath))["metrics"]
    if len(pts) == len(rm["da300"]):
        dda = [as_fraction(p["da"]) - d for p, d in zip(pts, rm["da300"])]
        dsun = [as_fraction(p["sun_hours"]) - h for p, h in zip(pts, rm["sun_hours_over_1000lx"])]
        print()
        print("per point, candela - Radiance: DA300 mean %+.2f pp, max |.| %.2f pp; "
              "sun hours > 1000 lx mean %+.1f h, max |.| %.0f h"
              % (100 * sum(dda) / len(dda), 100 * max(map(abs, dda)),
                 sum(dsun) / len(dsun), max(map(abs, dsun))))
PY
