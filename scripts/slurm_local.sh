#!/usr/bin/env bash
# Runs examples/slurm on a real one-node Slurm cluster started here (Debian slurm-wlm and
# munge; as root), and checks that the merged render equals a local render of the same shards
# merged in another order, bit for bit:
#   bash scripts/slurm_local.sh CANDELA_BINARY [SHARDS] [SPP]
# It writes slurm.conf for this host with 2 CPUs, starts munged, slurmctld and slurmd on a
# private socket and spool (nothing outside its temporary directory is changed), submits
# examples/slurm/submit.sh (an array job of SHARDS shards and a merge job that depends on it),
# waits, compares (state, PNG and report byte for byte), and stops the daemons. Exit code 0 when the outputs match; 77 when it cannot
# run here (not root, or slurm-wlm/munge missing and not installable).
set -euo pipefail
candela=$(realpath "${1:?usage: $0 CANDELA_BINARY [SHARDS] [SPP]}")
shards=${2:-4}
spp=${3:-16}
repo=$(cd "$(dirname "$0")/.." && pwd)

if [ "$(id -u)" != 0 ]; then
    echo "slurm_local: skipped: needs root (to run munged, slurmctld and slurmd)" >&2
    exit 77
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    if command -v apt-get >/dev/null; then
        DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null ||
            { echo "slurm_local: skipped: apt-get could not install slurm-wlm and munge" >&2; exit 77; }
    else
        echo "slurm_local: skipped: slurm-wlm and munge are not installed and apt-get is missing" >&2
        exit 77
    fi
fi

d=$(mktemp -d /tmp/candela-slurm.XXXXXX)
host=$(hostname -s)
pids=()
stop() {
    for p in "${pids[@]}"; do
        kill "$p" 2>/dev/null || true
    done
    for p in "${pids[@]}"; do
        wait "$p" 2>/dev/null || true
    done
}
trap stop EXIT

# munge: its own key, socket and state under $d.
mkdir -p "$d/munge" "$d/spool/ctld" "$d/spool/d" "$d/work"
dd if=/dev/urandom of="$d/munge/munge.key" bs=1 count=1024 status=none
chmod 700 "$d/munge"
chmod 400 "$d/munge/munge.key"
munged --force --foreground --socket="$d/munge/munge.socket" --key-file="$d/munge/munge.key" \
    --pid-file="$d/munge/munged.pid" --log-file="$d/munge/munged.log" \
    --seed-file="$d/munge/munge.seed" >>"$d/munged.out" 2>&1 &
pids+=($!)

cat >"$d/slurm.conf" <<EOF
ClusterName=candela-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$d/munge/munge.socket
CredType=cred/munge
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$d/spool/ctld
SlurmdSpoolDir=$d/spool/d
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/slurmctld.log
SlurmdLogFile=$d/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MinJobAge=600
NodeName=$host CPUs=2 State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$d/slurm.conf
for _ in $(seq 50); do
    [ -S "$d/munge/munge.socket" ] && break
    sleep 0.1
done
slurmctld -D -i -f "$SLURM_CONF" >>"$d/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" >>"$d/slurmd.out" 2>&1 &
pids+=($!)
for i in $(seq 60); do
    if sinfo -h -o %T 2>/dev/null | grep -q idle; then
        break
    fi
    [ "$i" = 60 ] && { echo "slurm_local: the node never became idle" >&2; cat "$d"/*.out >&2; exit 1; }
    sleep 1
done
sinfo

# The scene, rendered in shards on the cluster...
# A furnace: inside a sphere that emits 1 cd/m² and reflects 70 %, every luminance is
# 1/0.3 cd/m² and every illuminance π/0.3 lx (the meter and the grid).
cat >"$d/work/scene.ron" <<'EOF'
(
    camera: (position: (0.1, -0.2, 0.05), look_at: (0, 0, 1), vfov_deg: 90, resolution: (32, 32)),
    render: (spp: 16),
    materials: { "wall": Diffuse(reflectance: Constant(0.7)) },
    objects: [(
        shape: Sphere(center: (0, 0, 0), radius: 1),
        material: "wall",
        emission: (spectrum: Named("E"), amount: Luminance(1.0), two_sided: true),
    )],
    meters: [Illuminance(name: "centre", position: (0, 0, 0), normal: (0, 0, 1))],
    grids: [(name: "plane", origin: (-0.3, -0.2, -0.3), edge_u: (0.6, 0, 0), edge_v: (0, 0, 0.6), nx: 3, ny: 3)],
    measure: (samples: 1024),
)
EOF
cd "$d/work"
read -r array merge < <(CANDELA=$candela bash "$repo/examples/slurm/submit.sh" scene.ron render "$shards" "$spp" --cpus-per-task=1)
echo "submitted array job $array ($shards shards of $spp spp) and merge job $merge (afterok:$array)"
state=""
for i in $(seq 600); do
    state=$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p' | head -1)
    case "$state" in
        COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY) break ;;
    esac
    sleep 1
done
squeue || true
for f in candela-*.out; do
    echo "== $f"
    cat "$f"
done
scontrol show job "$array" | grep -E "JobId|JobState|ExitCode" || true
echo "merge job $merge: $state"
[ "$state" = COMPLETED ] || { echo "slurm_local: the merge job did not complete" >&2; tail -20 "$d/slurmctld.out" >&2; exit 1; }

# ... and the same shards rendered here one after another, merged in reverse order.
mkdir -p "$d/local" && cd "$d/local"
cp ../work/scene.ron .
for ((i = shards - 1; i >= 0; i--)); do
    "$candela" render scene.ron --shard "$i/$shards" --spp "$spp" --out render --quiet --threads 2 >/dev/null
done
states=()
for ((i = shards - 1; i >= 0; i--)); do
    states+=("render.shard-$i-of-$shards.state")
done
"$candela" merge "${states[@]}" -o render
# (The EXR's attributes are written in the order of a hash map, which changes between
# processes: the state holds the same sums bit for bit, the PNG the same pixels.)
for ext in state png report.json; do
    if cmp "$d/work/render.$ext" "$d/local/render.$ext"; then
        echo "slurm_local: render.$ext from Slurm equals the local merge ($(stat -c %s "$d/local/render.$ext") bytes)"
    else
        echo "slurm_local: render.$ext from Slurm differs from the local merge" >&2
        exit 1
    fi
done
rm -rf "$d"
echo "slurm_local: OK"
