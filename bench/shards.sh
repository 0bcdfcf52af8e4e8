#!/usr/bin/env bash
# Sharded render against one render of the same total samples (bench/README.md, "Sharded render
# against one render"). Alternates, per round: one render at SPP spp with 2 threads; 4 shards of
# SPP/4 spp one after another with 2 threads each, then `candela merge` (seq4). Prints the medians
# of wall and CPU (user + system) seconds and of the per-round ratios to the single render.
#
#   bash bench/shards.sh [--rounds N] [--spp SPP] [--scene FILE] [--candela PATH]
set -euo pipefail
cd "$(dirname "$0")/.."

rounds=5
spp=256
scene=scenes/room-spot.ron
candela=""
while [ $# -gt 0 ]; do
    case "$1" in
    --rounds) rounds="$2"; shift 2 ;;
    --spp) spp="$2"; shift 2 ;;
    --scene) scene="$2"; shift 2 ;;
    --candela) candela="$2"; shift 2 ;;
    *) echo "bench/shards.sh: unknown argument $1" >&2; exit 2 ;;
    esac
done
if [ $((spp % 4)) -ne 0 ]; then
    echo "bench/shards.sh: --spp must be a multiple of 4 (got $spp)" >&2
    exit 2
fi
if [ -z "$candela" ]; then
    CARGO_PROFILE_RELEASE_LTO=false CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16 \
        cargo build --release --quiet
    candela=target/release/candela
fi

work=target/bench/shards
rm -rf "$work"
mkdir -p "$work"
log="$work/times.tsv"
: >"$log"

# Runs a command under /usr/bin/time and appends "LABEL ROUND WALL CPU" to the log.
timed() {
    local label="$1" round="$2"
    shift 2
    /usr/bin/time -f "%e %U %S" -o "$work/t" "$@" >/dev/null 2>"$work/err" ||
        { cat "$work/err" >&2; exit 1; }
    awk -v l="$label" -v r="$round" '{ printf "%s\t%s\t%s\t%.3f\n", l, r, $1, $2 + $3 }' \
        "$work/t" >>"$log"
}

for round in $(seq 1 "$rounds"); do
    rm -rf "$work/single" "$work/seq4"
    mkdir -p "$work/single" "$work/seq4"
    timed single "$round" "$candela" render "$scene" --spp "$spp" --threads 2 --quiet \
        --checkpoint-interval 0s --out "$work/single/room"
    for i in 0 1 2 3; do
        timed "shard$i" "$round" "$candela" render "$scene" --spp $((spp / 4)) --threads 2 \
            --quiet --checkpoint-interval 0s --shard "$i/4" --out "$work/seq4/room"
    done
    timed merge "$round" "$candela" merge "$work"/seq4/room.shard-*-of-4.state \
        --out "$work/seq4/merged"
done

python3 - "$log" "$rounds" "$spp" <<'EOF'
import statistics, sys
log, rounds, spp = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
rows = [line.split("\t") for line in open(log).read().splitlines()]
per = {}
for label, r, wall, cpu in rows:
    kind = "single" if label == "single" else "seq4"
    w, c = per.setdefault((kind, int(r)), [0.0, 0.0])
    per[(kind, int(r))] = [w + float(wall), c + float(cpu)]
med = statistics.median
for kind in ("single", "seq4"):
    walls = [per[(kind, r)][0] for r in range(1, rounds + 1)]
    cpus = [per[(kind, r)][1] for r in range(1, rounds + 1)]
    line = f"{kind:7s} wall {med(walls):8.2f} s  cpu {med(cpus):8.2f} s"
    if kind == "seq4":
        rw = [per[("seq4", r)][0] / per[("single", r)][0] for r in range(1, rounds + 1)]
        rc = [per[("seq4", r)][1] / per[("single", r)][1] for r in range(1, rounds + 1)]
        line += f"  wall ratio {med(rw):.3f}  cpu ratio {med(rc):.3f}"
    print(line)
print(f"({rounds} rounds, {spp} spp in total, medians; per-run times in {log})")
EOF
