#!/usr/bin/env bash
# Checks the whole Slurm path on this machine: starts a single-node Slurm
# (Debian's slurm-wlm and munge, installed if missing), runs an experiment as
# a 3-task job array through experiments/slurm/sweep.sbatch, merges the shards
# after the array (a dependent job), runs the same experiment on one machine,
# and compares the files byte for byte. Stops the daemons at the end.
# Usage (as root, from the repository): experiments/slurm/check-local.sh [EXPERIMENT.json]
set -euo pipefail
top="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$top"
experiment=${1:-experiments/slurm/small.json}
work="$(mktemp -d)"
conf="$work/slurm"
mkdir -p "$conf" "$work/spool/ctld" "$work/spool/d" "$work/log"
cleanup() {
    [ -f "$work/slurmd.pid" ] && kill "$(cat "$work/slurmd.pid")" 2>/dev/null || true
    [ -f "$work/slurmctld.pid" ] && kill "$(cat "$work/slurmctld.pid")" 2>/dev/null || true
    [ -f "$work/munged.pid" ] && kill "$(cat "$work/munged.pid")" 2>/dev/null || true
    sleep 1
    rm -rf "$work"
}
trap cleanup EXIT

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    apt-get install -y slurm-wlm munge >/dev/null
fi
cargo build --release --quiet
varspec="$top/target/release/varspec"

# munge: a fresh key for this check only.
mkdir -p "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$work/munge/munge.key"
munged --key-file="$work/munge/munge.key" --socket="$work/munge/munge.socket" \
    --pid-file="$work/munged.pid" --log-file="$work/log/munged.log" --seed-file="$work/munge/seed" --force
export MUNGE_SOCKET="$work/munge/munge.socket"

host=$(hostname -s)
cpus=$(nproc)
cat > "$conf/slurm.conf" <<CONF
ClusterName=varspec-check
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$work/spool/ctld
SlurmdSpoolDir=$work/spool/d
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
SlurmctldPort=16817
SlurmdPort=16818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
ReturnToService=2
MpiDefault=none
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$conf/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qE 'idle|mix|alloc' && break
    sleep 1
done
sinfo

out="$work/sharded"
mkdir -p "$out"
array=$(VARSPEC="$varspec" sbatch --parsable --array=0-2 --chdir="$top" \
    --output="$work/log/task-%a.out" experiments/slurm/sweep.sbatch "$experiment" "$out")
merge=$(sbatch --parsable --dependency=afterok:"$array" --chdir="$top" \
    --output="$work/log/merge.out" --wrap "$varspec merge $out")
echo "submitted array $array and merge $merge"
for _ in $(seq 600); do
    [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ] && break
    sleep 1
done
cat "$work/log/merge.out"
"$varspec" experiment "$experiment" -o "$work/single" >/dev/null
status=0
for f in variances.csv slopes.csv README.md; do
    if cmp -s "$work/single/$f" "$out/$f"; then
        echo "$f: identical (Slurm array of 3 shards + merge = single run)"
    else
        echo "$f: DIFFERS"; status=1
    fi
done
exit $status
