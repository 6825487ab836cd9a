#!/bin/bash
# A real single-node Slurm cluster on this machine (docs/montecarlo.md, "Slurm check"):
# installs Debian's slurm-wlm and munge when missing, writes a minimal slurm.conf, starts
# munged, slurmctld and slurmd, submits the Monte Carlo of examples/montecarlo.toml as a job
# array of 4 shards and a dependent merge job (scripts/slurm/montecarlo.sbatch), waits (time
# limit), and checks that the merged folder is byte-identical to the unsharded local run.
# The daemons are stopped on exit, whatever happens. Needs root (apt-get, munge).
#
#   bash scripts/check_slurm.sh            (builds target/release/flexcraft if needed)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
limit=${SLURM_CHECK_TIMEOUT:-600}
shards=4

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq slurm-wlm munge >/dev/null
fi
cargo build --release --quiet
flexcraft=$root/target/release/flexcraft

work=$(mktemp -d /tmp/flexcraft-slurm.XXXXXX)
chmod 755 "$work"
pids=()
cleanup() {
    local rc=$?
    # Stop what this script started, by process id.
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
    if [ $rc -ne 0 ]; then
        for f in slurmctld.log slurmd.log munged.log; do
            [ -f "$work/$f" ] && { echo "--- $f (last lines)"; tail -n 20 "$work/$f"; }
        done
        ls "$work"/out/*.out 2>/dev/null | while read -r f; do echo "--- $f"; cat "$f"; done
    fi
    rm -rf "$work"
    exit $rc
}
trap cleanup EXIT

# munge: its own key (the package's /etc/munge/munge.key), socket and pid in the work folder,
# run as the munge user in the foreground (no systemd here).
mkdir -p "$work/munge"
chown munge:munge "$work/munge"
socket=$work/munge/munge.socket
runuser -u munge -- munged --foreground --socket="$socket" \
    --pid-file="$work/munge/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munge/seed" \
    >>"$work/munged.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [ -S "$socket" ] && break; sleep 0.1; done
[ -S "$socket" ] || { echo "munged did not start"; exit 1; }

host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$work/state" "$work/spool" "$work/out"
cat > "$work/slurm.conf" <<CONF
# Minimal single-node cluster for scripts/check_slurm.sh. No cgroups and no systemd in the
# container: processes are tracked through /proc (proctrack/linuxproc), tasks are not
# confined (task/none), no accounting.
ClusterName=flexcraft-check
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
SlurmctldPort=16817
SlurmdPort=16818
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
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=check Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf

slurmctld -D -i -f "$SLURM_CONF" >>"$work/slurmctld.log" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >>"$work/slurmd.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
    sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
    sleep 0.2
done
sinfo

scenario=$root/examples/montecarlo.toml
export FLEXCRAFT=$flexcraft
cd "$work/out"
array=$(sbatch --parsable --array=0-$((shards - 1)) --chdir="$work/out" \
    "$root/scripts/slurm/montecarlo.sbatch" "$scenario" "$work/out")
merge=$(sbatch --parsable --dependency=afterok:"$array" --chdir="$work/out" \
    --output="$work/out/merge-%j.out" "$root/scripts/slurm/montecarlo.sbatch" --merge "$work/out")
echo "submitted array job $array ($shards shards) and merge job $merge (afterok)"

start=$SECONDS
while squeue -h -j "$array,$merge" 2>/dev/null | grep -q .; do
    if (( SECONDS - start > limit )); then
        echo "timeout: the jobs did not finish within $limit s"; squeue; exit 1
    fi
    sleep 1
done
state=$(scontrol show job "$merge" 2>/dev/null | grep -o 'JobState=[A-Z]*' || true)
echo "merge job: ${state:-gone from the controller}"

"$flexcraft" montecarlo "$scenario" --out "$work/local" --quiet >/dev/null
diff -r "$work/local" "$work/out/merged"
echo "slurm check passed: $shards shards merged on Slurm == the unsharded local run, byte for byte"
