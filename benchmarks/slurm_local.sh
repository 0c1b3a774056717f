#!/usr/bin/env bash
# A real SLURM run of the miniature campaign on this machine: a single-node cluster on
# localhost (Debian's slurm-wlm and munge), then the campaign through profiles/slurm.
#
#   sudo apt-get install -y slurm-wlm munge      # once
#   bash benchmarks/slurm_local.sh [WORKDIR]      # as root (it writes /etc/slurm, starts daemons)
#   bash benchmarks/slurm_local.sh --check        # what it needs, found or not; changes nothing
#
# No accounting database is set up: the executor plugin is told to poll job states with
# squeue (--slurm-status-command squeue), and MinJobAge keeps finished jobs visible to it.
# With slurmdbd and sacct a real cluster needs none of that.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
PY="${PYTHON:-python}"
cd "$ROOT" && "$PY" -m benchmarks.common  # date, host, commit

if [ "${1:-}" = "--check" ]; then
  echo "| needs | found |"
  echo "|---|---|"
  missing=0
  for cmd in slurmctld slurmd munged sinfo squeue snakemake; do
    where="$(command -v "$cmd" 2>/dev/null || ls "/usr/sbin/$cmd" 2>/dev/null || true)"
    echo "| $cmd | ${where:-no} |"
    [ -n "$where" ] || missing=$((missing + 1))
  done
  root="$([ "$(id -u)" -eq 0 ] && echo yes || echo no)"
  echo "| root | $root |"
  [ "$root" = yes ] || missing=$((missing + 1))
  if [ "$missing" -eq 0 ]; then
    echo "summary: ready for a SLURM run (bash benchmarks/slurm_local.sh)"
  else
    echo "summary: $missing of 7 needs missing: not run (sudo apt-get install -y slurm-wlm munge; run as root)"
  fi
  exit 0
fi

WORK="${1:-/tmp/sph-surge-slurm}"
START=$SECONDS
HOST="$(hostname -s)"
CPUS="$(nproc)"
MEM_MB="$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 1024 ))"

mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat > /etc/slurm/slurm.conf <<CONF
ClusterName=local
SlurmctldHost=${HOST}
SlurmUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
MinJobAge=3600
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=${HOST} CPUs=${CPUS} RealMemory=${MEM_MB} State=UNKNOWN
PartitionName=local Nodes=${HOST} Default=YES MaxTime=INFINITE State=UP
CONF

mkdir -p /run/munge && chown munge:munge /run/munge
pgrep -x munged >/dev/null || su -s /bin/sh munge -c /usr/sbin/munged
pgrep -x slurmctld >/dev/null || /usr/sbin/slurmctld
pgrep -x slurmd >/dev/null || /usr/sbin/slurmd
for _ in $(seq 30); do
  sinfo -h -o "%T" 2>/dev/null | grep -qE "idle|mixed|allocated" && break
  sleep 1
done
sinfo

python -m pip install -q snakemake-executor-plugin-slurm
rm -rf "$WORK"; mkdir -p "$WORK"
cd "$WORK"
# the profile's resources, with this cluster's partition; squeue polls the job states
snakemake -s "$ROOT/Snakefile" --configfile "$ROOT/tests/data/mini.yaml" \
    --profile "$ROOT/profiles/slurm" --default-resources slurm_partition=local runtime=10 mem_mb=1000 \
    --set-resources run_case:cpus_per_task=1 run_case:mem_mb=2000 \
    --set-threads run_case=1 --slurm-status-command squeue --jobs 4 \
    2>&1 | tee "$WORK/snakemake.log"
echo "--- jobs (squeue, finished ones kept for MinJobAge):"
squeue -t all -o "%.6i %.45k %.10T %.8M %.4C"
ls -l "$WORK/reports/mini/report.html"
echo "summary: the miniature campaign through profiles/slurm in $((SECONDS - START)) s"
