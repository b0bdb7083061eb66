#!/usr/bin/env bash
# Brings up a single-node Slurm cluster on this machine (Debian's slurm-wlm:
# slurmctld and slurmd, with munge), submits a small frame as an array of 4
# parts and a dependent merge (submit.sh), waits for them, checks the merged
# frame byte for byte against one `sahara render`, and takes the cluster
# down again. Everything (configuration, munge key and socket, state, logs)
# lives in a temporary folder; the daemons listen on ports 16817-16818.
#
#   farm/slurm/local-cluster.sh SAHARA
#
# Installs slurmctld, slurmd, slurm-client and munge with apt-get when they
# are missing (as root). Exit status: 0 the frames match, 1 they do not (or
# a job failed), 77 this machine cannot run the cluster (nothing to
# install them with, or the daemons do not come up).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
sahara=$(realpath "$1")
scene=$(realpath "$here/../../scenes/cornell_glossy_glass.toml")
options=(--width 64 --height 48 --spp 16 --pass-spp 8)
cannot() { echo "local Slurm: $*"; exit 77; }

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
    || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
    [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null \
        || cannot "slurmctld, slurmd, sbatch or munged is missing and cannot be installed here"
    packages=(slurmctld slurmd slurm-client munge)
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y --no-install-recommends "${packages[@]}" >/dev/null 2>&1 \
        || { apt-get update >/dev/null 2>&1 && apt-get install -y --no-install-recommends "${packages[@]}" >/dev/null; } \
        || cannot "apt-get could not install ${packages[*]}"
fi

work=$(mktemp -d)
chmod 700 "$work"
pids=()
cleanup() {
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
    rm -rf "$work"
}
trap cleanup EXIT
host=$(hostname -s)
mkdir -p "$work/state" "$work/spool" "$work/munge" "$work/out"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge/munge.key"
socket=$work/munge/munge.socket
cat > "$work/slurm.conf" <<CONF
ClusterName=sahara-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=$(id -un)
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf

munged --force --socket="$socket" --key-file="$work/munge/munge.key" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
    --seed-file="$work/munge/munged.seed" \
    || cannot "munged does not start: $(cat "$work/munge/munged.log" 2>/dev/null)"
pids+=("$(cat "$work/munge/munged.pid")")
slurmctld -D -f "$SLURM_CONF" >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$work/slurmd.out" 2>&1 &
pids+=($!)
up=0
for _ in $(seq 60); do
    if sinfo -h -N -o '%T' 2>/dev/null | grep -qx idle; then up=1; break; fi
    sleep 0.5
done
if [ "$up" != 1 ]; then
    tail -5 "$work/slurmctld.log" "$work/slurmd.log" "$work"/*.out 2>/dev/null || true
    cannot "the node did not become idle within 30 s"
fi
echo "local Slurm: $(sinfo -h -o '%P %D node(s) %T')"

cd "$work/out"
read -r render merge < <(SAHARA=$sahara "$here/submit.sh" 4 "$work/out/parts" "$work/out/merged.exr" \
    "$scene" "${options[@]}")
echo "local Slurm: submitted array job $render (4 parts) and merge job $merge (afterok)"
state=
for _ in $(seq 240); do
    state=$(scontrol show job "$merge" 2>/dev/null | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
    case $state in COMPLETED | FAILED | CANCELLED | TIMEOUT | NODE_FAIL | OUT_OF_MEMORY) break ;; esac
    sleep 0.5
done
if [ "$state" != COMPLETED ]; then
    echo "local Slurm: the merge job ended $state"
    cat "$work/out"/*.log 2>/dev/null || true
    exit 1
fi
"$sahara" render "$scene" "${options[@]}" -o "$work/whole.exr" 2>/dev/null
if ! cmp "$work/out/merged.exr" "$work/whole.exr"; then
    echo "local Slurm: the merged frame differs from the single-process image"
    exit 1
fi
echo "local Slurm: 4 array tasks + dependent merge == single-process exr, byte for byte"
