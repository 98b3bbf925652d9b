#!/usr/bin/env bash
# A private one-node Slurm cluster on this machine, for the farm tests
# (tests/shots/slurm_test.cpp) and for trying `hairvox submit` by hand:
#
#   scripts/slurm-cluster.sh start DIR     start munged, slurmctld and slurmd
#   scripts/slurm-cluster.sh stop DIR      cancel its jobs, stop the daemons
#   scripts/slurm-cluster.sh status DIR    sinfo of the cluster
#   source DIR/env                         then sbatch, squeue, scontrol... talk to it
#
# Debian's slurm-wlm and munge, run as root with their own key, socket, ports,
# state directory and slurm.conf under DIR — nothing in /etc, /run or /var is
# read or written, and the machine's own Slurm or munge (if any) is left
# alone. No cgroups: ProctrackType=proctrack/linuxproc, TaskPlugin=task/none
# (containers and CI machines rarely let a daemon manage cgroups). The node is
# this machine with its CPUs and 1/2 of its memory, in one partition "farm",
# CR_CPU scheduling (one array task per CPU).
#
# `start` fails (exit 1, with the daemons' log lines) if a daemon does not
# come up or the node is not idle within HAIRVOX_SLURM_TIMEOUT seconds
# (default 60); it stops what it started first. `stop` ends only the
# processes whose ids it recorded in DIR (the daemons, then any job step
# whose slurmstepd runs from DIR's spool directory), SIGTERM then SIGKILL.
# Ports: two free TCP ports in 30000-59999 picked at random and checked with
# ss (HAIRVOX_SLURM_PORT=P uses P and P+1).
set -euo pipefail

usage() { echo "usage: $0 start|stop|status DIR" >&2; exit 2; }
(($# == 2)) || usage
cmd=$1
dir=$2
timeout=${HAIRVOX_SLURM_TIMEOUT:-60}

log() { echo "slurm-cluster: $*" >&2; }
die() { log "$*"; exit 1; }

# A pid file's process if it is alive.
alive_pid() {
  local file=$1 pid
  [[ -s $file ]] || return 1
  pid=$(<"$file")
  [[ $pid =~ ^[0-9]+$ ]] && kill -0 "$pid" 2>/dev/null && echo "$pid"
}

# SIGTERM, then SIGKILL after 10 s, to each listed pid.
end_pids() {
  local pids=("$@") p waited=0
  ((${#pids[@]} > 0)) || return 0
  kill -TERM "${pids[@]}" 2>/dev/null || true
  while ((waited < 100)); do
    local left=0
    for p in "${pids[@]}"; do kill -0 "$p" 2>/dev/null && left=1; done
    ((left == 0)) && return 0
    sleep 0.1
    waited=$((waited + 1))
  done
  kill -KILL "${pids[@]}" 2>/dev/null || true
}

# The slurmstepd processes of this cluster: those whose command line names
# its spool directory... slurmstepd does not show it, so those whose parent
# chain or environment point at DIR: SLURM_CONF in their environment.
cluster_steps() {
  local p
  for p in $(pgrep -x slurmstepd 2>/dev/null || true); do
    if tr '\0' '\n' <"/proc/$p/environ" 2>/dev/null | grep -qx "SLURM_CONF=$dir/slurm.conf"; then
      echo "$p"
    fi
  done
}

stop_cluster() {
  [[ -d $dir ]] || return 0
  if [[ -f $dir/env ]] && alive_pid "$dir/slurmctld.pid" >/dev/null; then
    (source "$dir/env" && scancel --full --quiet --user="$(id -un)" 2>/dev/null) || true
  fi
  local pids=() p
  for f in slurmd slurmctld; do
    if p=$(alive_pid "$dir/$f.pid"); then pids+=("$p"); fi
  done
  end_pids "${pids[@]}"
  mapfile -t pids < <(cluster_steps)
  end_pids "${pids[@]}"
  if p=$(alive_pid "$dir/munged.pid"); then end_pids "$p"; fi
  if [[ -f $dir/socket_dir ]]; then
    local sock
    sock=$(<"$dir/socket_dir")
    [[ $sock == /tmp/hvx-munge.* ]] && rm -rf "$sock"
  fi
  rm -f "$dir"/*.pid
}

free_port() { ! ss -Htln "sport = :$1" | grep -q .; }

pick_ports() {
  if [[ -n ${HAIRVOX_SLURM_PORT:-} ]]; then
    ctld_port=$HAIRVOX_SLURM_PORT
    slurmd_port=$((ctld_port + 1))
    return
  fi
  local i
  for i in $(seq 50); do
    ctld_port=$((30000 + RANDOM % 30000))
    slurmd_port=$((ctld_port + 1))
    if free_port "$ctld_port" && free_port "$slurmd_port"; then return; fi
  done
  die "no two free TCP ports found in 30000-59999"
}

# The last lines of each log, for a failure's message.
show_logs() {
  local f
  for f in "$dir"/munged.log "$dir"/slurmctld.log "$dir"/slurmd.log; do
    [[ -f $f ]] || continue
    log "--- last lines of $f:"
    tail -n 15 "$f" >&2 || true
  done
}

fail_start() {
  log "cannot start the cluster: $*"
  show_logs
  stop_cluster
  exit 1
}

start_cluster() {
  local tool
  for tool in munged slurmctld slurmd sinfo sbatch scontrol ss; do
    command -v "$tool" >/dev/null ||
      die "cannot start the cluster: '$tool' is not installed (bash scripts/setup.sh installs slurm-wlm and munge)"
  done
  (($(id -u) == 0)) || die "cannot start the cluster: run as root (the daemons run jobs as their users)"
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
  if alive_pid "$dir/slurmctld.pid" >/dev/null || alive_pid "$dir/munged.pid" >/dev/null; then
    log "a cluster is already running in $dir; stopping it first"
    stop_cluster
  fi
  rm -rf "$dir/state" "$dir/spool" "$dir"/*.log
  mkdir -p "$dir/state" "$dir/spool"

  # munge: its own key and a socket in a short /tmp path (a unix socket's
  # path is limited to 107 bytes; DIR may be long).
  local sockdir
  sockdir=$(mktemp -d /tmp/hvx-munge.XXXXXX)
  echo "$sockdir" >"$dir/socket_dir"
  local socket=$sockdir/munge.socket
  dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 status=none
  chmod 0400 "$dir/munge.key"
  munged --force --key-file="$dir/munge.key" --socket="$socket" \
    --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" \
    --seed-file="$dir/munged.seed" 2>>"$dir/munged.log" ||
    fail_start "munged exited with status $?"

  pick_ports
  local host cpus mem
  host=$(hostname -s)
  cpus=$(nproc)
  mem=$(awk '/MemTotal/ { print int($2 / 1024 / 2) }' /proc/meminfo)
  cat >"$dir/slurm.conf" <<EOF
# Written by scripts/slurm-cluster.sh: a private one-node cluster for tests.
ClusterName=hairvox
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
KillWait=10
MinJobAge=600
InactiveLimit=0
SlurmctldTimeout=30
SlurmdTimeout=60
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=farm Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  cat >"$dir/env" <<EOF
export SLURM_CONF=$dir/slurm.conf
EOF
  export SLURM_CONF=$dir/slurm.conf
  slurmctld -f "$SLURM_CONF" -i 2>>"$dir/slurmctld.log" || fail_start "slurmctld exited with status $?"
  slurmd -f "$SLURM_CONF" 2>>"$dir/slurmd.log" || fail_start "slurmd exited with status $?"

  local waited=0 state=""
  while ((waited < timeout * 4)); do
    state=$(sinfo --noheader --format=%t --nodes="$host" 2>/dev/null || true)
    [[ $state == idle ]] && break
    sleep 0.25
    waited=$((waited + 1))
  done
  [[ $state == idle ]] || fail_start "the node is '${state:-unknown}', not idle, after ${timeout} s"
  log "up in $dir: node $host ($cpus CPUs), partition farm, ports $ctld_port/$slurmd_port;" \
    "source $dir/env to use it"
}

case "$cmd" in
  start) start_cluster ;;
  stop) stop_cluster; log "stopped ($dir)" ;;
  status)
    [[ -f $dir/env ]] || die "no cluster in $dir"
    source "$dir/env"
    sinfo
    ;;
  *) usage ;;
esac
