# A private single-node Slurm cluster for tests: its own munge key and socket, configuration,
# state and spool, all in one temporary directory, on ports no other cluster uses. Sourced by
# tests/slurm/real_cluster.sh.
#
#   cluster_start DIR   start munged, slurmctld and slurmd (as the current user, which must be
#                       root: slurmd runs jobs as their submitter); exports SLURM_CONF
#   cluster_stop        stop every daemon cluster_start started, by pid
#   cluster_fail MSG    print MSG and the daemons' log tails, stop the cluster, exit 1

CLUSTER_PIDS=()
CLUSTER_DIR=""

cluster_logs() {
  local f
  for f in "$CLUSTER_DIR"/log/*.log; do
    [ -f "$f" ] || continue
    echo "---- last lines of $f" >&2
    tail -n 25 "$f" >&2
  done
}

cluster_fail() {
  echo "slurm test: FAILED: $*" >&2
  [ -n "$CLUSTER_DIR" ] && cluster_logs
  cluster_stop
  exit 1
}

cluster_stop() {
  local pid i
  for pid in "${CLUSTER_PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${CLUSTER_PIDS[@]}"; do
    for i in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
  done
  CLUSTER_PIDS=()
}

# A TCP port nothing listens on (from 20000 up, skipping the ones in use).
free_port() {
  local p
  for p in $(seq "$1" $(($1 + 2000))); do
    if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; then echo "$p"; return 0; fi
  done
  return 1
}

cluster_start() {
  CLUSTER_DIR=$1
  local d=$CLUSTER_DIR
  local missing=()
  for b in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
    command -v "$b" >/dev/null 2>&1 || missing+=("$b")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "slurm test: FAILED: ${missing[*]} not found; install Slurm and munge" \
      "(Debian/Ubuntu: apt-get install slurm-wlm munge; .ci/run does)" >&2
    exit 1
  fi
  [ "$(id -u)" = 0 ] || { echo "slurm test: FAILED: a private Slurm cluster needs root (slurmd)" >&2; exit 1; }
  mkdir -p "$d/munge" "$d/state" "$d/spool" "$d/log" "$d/run"
  chmod 711 "$d/munge"
  head -c 1024 /dev/urandom > "$d/munge/munge.key"
  chmod 400 "$d/munge/munge.key"
  munged --foreground --force --socket="$d/munge/munge.sock" --key-file="$d/munge/munge.key" \
    --pid-file="$d/munge/munged.pid" --log-file="$d/log/munged.log" \
    --seed-file="$d/munge/munged.seed" >"$d/log/munged.out" 2>&1 &
  CLUSTER_PIDS+=($!)
  local i
  for i in $(seq 1 100); do [ -S "$d/munge/munge.sock" ] && break; sleep 0.1; done
  [ -S "$d/munge/munge.sock" ] || cluster_fail "munged did not open its socket"
  local host ctl_port node_port cpus
  host=$(hostname -s)
  ctl_port=$(free_port 26817) || cluster_fail "no free port"
  node_port=$(free_port $((ctl_port + 1))) || cluster_fail "no free port"
  cpus=$(nproc)
  cat > "$d/slurm.conf" <<CONF
ClusterName=ugltest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctl_port
SlurmdPort=$node_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$d/munge/munge.sock
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/run/slurmctld.pid
SlurmdPidFile=$d/run/slurmd.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
ReturnToService=2
MinJobAge=600
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$d/slurm.conf"
  slurmctld -D -c -f "$SLURM_CONF" >"$d/log/slurmctld.out" 2>&1 &
  CLUSTER_PIDS+=($!)
  slurmd -D -f "$SLURM_CONF" >"$d/log/slurmd.out" 2>&1 &
  CLUSTER_PIDS+=($!)
  local state=""
  for i in $(seq 1 120); do
    state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
    [ "$state" = idle ] && return 0
    sleep 0.5
  done
  cluster_fail "the node did not become idle within 60 s (state: '${state:-none}')"
}
