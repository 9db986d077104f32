#!/usr/bin/env bash
# Runs COMMAND... while a real single-node Slurm cluster is up on this machine: munged,
# slurmctld -D and slurmd -D (Debian's slurmctld slurmd slurm-client munge, 22.05) with a generated
# slurm.conf, state and logs in a temporary folder, and SLURM_CONF exported for COMMAND. Every
# daemon started here is stopped when this script ends, however it ends (trap). Needs root (the
# daemons run jobs as the submitting user and munged checks its key's owner).
#   MMH_SLURM_MAX_ARRAY_SIZE   the cluster's MaxArraySize (default 1001)
set -euo pipefail

if [[ $(id -u) -ne 0 ]]; then
  echo "with_slurm_cluster: needs root (munged, slurmctld and slurmd run as root here)" >&2
  exit 77
fi
for tool in munged slurmctld slurmd sbatch scontrol squeue sinfo; do
  command -v "$tool" >/dev/null || { echo "with_slurm_cluster: $tool is not installed" >&2; exit 77; }
done

tmp="$(mktemp -d /tmp/mmhslurm.XXXXXX)"
pids=()
cleanup() {
  local status=$?
  for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
  for _ in $(seq 50); do
    local alive=0
    for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [[ $alive -eq 0 ]] && break
    sleep 0.1
  done
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; done
  if [[ $status -ne 0 && -n "${MMH_SLURM_KEEP_LOGS:-}" ]]; then
    echo "with_slurm_cluster: logs kept in $tmp" >&2
  else
    rm -rf "$tmp"
  fi
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# A port nothing listens on (random in 20000-59999).
free_port() {
  local port
  while true; do
    port=$((20000 + RANDOM % 40000))
    (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || { echo "$port"; return; }
  done
}

mkdir -p "$tmp/state" "$tmp/spool" "$tmp/munge"
chmod 700 "$tmp/munge"
dd if=/dev/urandom of="$tmp/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge/munge.key"
munged --foreground --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/socket" \
  --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/munge/munged.log" \
  --seed-file="$tmp/munge/seed" >"$tmp/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 100); do [[ -S "$tmp/munge/socket" ]] && break; sleep 0.05; done
[[ -S "$tmp/munge/socket" ]] || { cat "$tmp/munged.out" >&2; echo "munged did not start" >&2; exit 1; }

cpus=$(nproc)
cat >"$tmp/slurm.conf" <<CONF
ClusterName=mmhtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge/socket,cred_expire=10
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/builtin
MpiDefault=none
ReturnToService=2
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobRequeue=1
MaxArraySize=${MMH_SLURM_MAX_ARRAY_SIZE:-1001}
MinJobAge=600
KillWait=2
InactiveLimit=0
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=mmhnode NodeHostname=$(hostname) NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=mmh Nodes=mmhnode Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -c -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N mmhnode -f "$SLURM_CONF" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 300); do
  state=$(sinfo -h -n mmhnode -o %T 2>/dev/null || true)
  [[ "$state" == idle ]] && break
  sleep 0.1
done
if [[ "$state" != idle ]]; then
  echo "with_slurm_cluster: the node did not become idle (state '$state')" >&2
  tail -n 20 "$tmp"/slurmctld.log "$tmp"/slurmd.log "$tmp"/*.out >&2 || true
  exit 1
fi
echo "with_slurm_cluster: cluster up ($SLURM_CONF)" >&2
"$@"
