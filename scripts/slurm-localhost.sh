#!/usr/bin/env bash
# A single-node SLURM cluster on localhost for the tests (docs/slurm.md): munged, slurmctld and
# slurmd from Debian's slurm-wlm, started directly (no systemd in a container), one node
# `localhost` with every CPU of this machine in the partition `debug`.
# Usage (as root): scripts/slurm-localhost.sh start|stop|status
# Idempotent: `start` installs what is missing, rewrites the configuration and starts only the
# daemons that are not running; `stop` stops only the daemons it started (their pid files).
set -euo pipefail

conf_dir=/etc/slurm
state_dir=/var/lib/psq-slurm       # controller state and slurmd spool: this cluster's only
log_dir=/var/log/psq-slurm
run_dir=/run/psq-slurm             # pid files of the daemons this script started
munge_socket_dir=/run/munge

require_root() {
  if [ "$(id -u)" -ne 0 ]; then
    echo "slurm-localhost: run as root (it installs packages and starts system daemons)" >&2
    exit 1
  fi
}

install_packages() {
  local missing=()
  for p in slurm-wlm munge; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return
  echo "slurm-localhost: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -q
  apt-get install -y -q --no-install-recommends "${missing[@]}"
}

# The memory slurmd may hand out, in MB: all but 512 MB of this machine's.
real_memory_mb() {
  local total
  total=$(awk '/^MemTotal:/ {print int($2 / 1024)}' /proc/meminfo)
  echo $((total > 1024 ? total - 512 : total))
}

# Writes slurm.conf; false when it was already so (running daemons then need no restart).
write_config() {
  mkdir -p "$conf_dir" "$state_dir/ctld" "$state_dir/spool" "$log_dir" "$run_dir"
  local tmp="$conf_dir/.slurm.conf.tmp$$"
  # proctrack/linuxproc and task/none: no cgroups inside a container. KillWait 5: a cancelled
  # or requeued task gets SIGTERM (psq checkpoints) and SIGKILL 5 s later. No accounting
  # daemon: sacct answers "accounting storage is disabled" and psq slurm sync relies on squeue
  # and the tasks' result files (docs/slurm.md). ReturnToService=2: the node comes back after
  # a restart of slurmd without an scontrol update. DefMemPerCPU: a task without --mem takes
  # its CPU's share of the memory, not the whole node's, so tasks run side by side.
  cat >"$tmp" <<EOF
ClusterName=psq-localhost
SlurmctldHost=localhost
AuthType=auth/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$state_dir/ctld
SlurmdSpoolDir=$state_dir/spool
SlurmctldPidFile=$run_dir/slurmctld.pid
SlurmdPidFile=$run_dir/slurmd.pid
SlurmctldLogFile=$log_dir/slurmctld.log
SlurmdLogFile=$log_dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
ReturnToService=2
KillWait=5
MinJobAge=3600
InactiveLimit=0
SlurmctldTimeout=30
SlurmdTimeout=60
DefMemPerCPU=$(($(real_memory_mb) / $(nproc)))
NodeName=localhost CPUs=$(nproc) RealMemory=$(real_memory_mb) State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
  if cmp -s "$tmp" "$conf_dir/slurm.conf"; then
    rm -f "$tmp"
    return 1
  fi
  mv "$tmp" "$conf_dir/slurm.conf"
}

# True if the pid file names a live process.
running() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

start_munge() {
  mkdir -p "$munge_socket_dir"
  chown munge:munge "$munge_socket_dir"
  [ -f /etc/munge/munge.key ] || runuser -u munge -- /usr/sbin/mungekey --create
  if ! running "$run_dir/munged.pid"; then
    runuser -u munge -- /usr/sbin/munged --pid-file="$munge_socket_dir/munged.pid"
    cp "$munge_socket_dir/munged.pid" "$run_dir/munged.pid"
  fi
}

start_slurm() {
  running "$run_dir/slurmctld.pid" || /usr/sbin/slurmctld
  running "$run_dir/slurmd.pid" || /usr/sbin/slurmd
}

# Waits until the node is idle (or mixed/allocated) and a job can run: at most 60 s.
wait_ready() {
  for _ in $(seq 60); do
    local state
    state=$(sinfo --noheader --nodes=localhost --format=%T 2>/dev/null || true)
    case "$state" in
      idle* | mixed* | allocated*) echo "slurm-localhost: node localhost $state"; return 0 ;;
    esac
    sleep 1
  done
  echo "slurm-localhost: the node did not become ready; see $log_dir/*.log" >&2
  tail -n 20 "$log_dir"/slurmctld.log "$log_dir"/slurmd.log >&2 || true
  exit 1
}

stop_daemon() {
  local pid_file=$1
  running "$pid_file" || return 0
  local pid
  pid=$(cat "$pid_file")
  kill "$pid"
  for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  rm -f "$pid_file"
}

case "${1:-}" in
  start)
    require_root
    install_packages
    if write_config; then
      # A changed configuration (another machine size, a new psq): the daemons reread it.
      stop_daemon "$run_dir/slurmd.pid"
      stop_daemon "$run_dir/slurmctld.pid"
    fi
    start_munge
    start_slurm
    wait_ready
    ;;
  stop)
    require_root
    stop_daemon "$run_dir/slurmd.pid"
    stop_daemon "$run_dir/slurmctld.pid"
    stop_daemon "$run_dir/munged.pid"
    ;;
  status)
    for d in munged slurmctld slurmd; do
      if running "$run_dir/$d.pid"; then echo "$d running"; else echo "$d stopped"; fi
    done
    ;;
  *)
    echo "usage: $0 start|stop|status" >&2
    exit 2
    ;;
esac
