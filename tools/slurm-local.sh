#!/usr/bin/env bash
# A one-node Slurm on this machine (Debian, as root), to run asperity's cluster scripts for real
# (.ci/run does, for tests/study_shards.rs).
#
#   tools/slurm-local.sh start   installs slurm-wlm and munge when absent (apt-get), writes a
#                                one-node configuration for localhost into a new folder under
#                                /tmp, starts munged (unless one answers), slurmctld and slurmd,
#                                waits until the node is idle, and prints that folder's
#                                slurm.conf: `export SLURM_CONF=<it>` points Slurm's commands at it.
#   tools/slurm-local.sh stop STATE
#                                stops the daemons `start` started (by their process ids) and
#                                removes the folder STATE it made.
#
# The configuration needs no cgroups (proctrack/linuxproc, task/none), keeps no accounting, and
# keeps finished jobs for 10 minutes so that `scontrol show job` reports how they ended.
set -euo pipefail

fail() { echo "slurm-local: $*" >&2; exit 1; }

start() {
  [ "$(id -u)" = 0 ] || fail "needs root (it installs packages and starts daemons)"
  if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v sbatch >/dev/null \
    || ! command -v munged >/dev/null; then
    command -v apt-get >/dev/null || fail "slurm-wlm and munge are not installed and there is no apt-get"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq >&2 || fail "apt-get update failed"
    apt-get install -y -qq --no-install-recommends slurm-wlm munge >&2 || fail "apt-get install slurm-wlm munge failed"
  fi
  local state host cpus mem
  state=$(mktemp -d /tmp/asperity-slurm.XXXXXX)
  touch "$state/.slurm-local"
  mkdir -p "$state/spool" "$state/state"
  host=$(hostname -s)
  cpus=$(nproc)
  mem=$(( $(free -m | awk '/^Mem:/ {print $2}') * 9 / 10 ))
  cat > "$state/slurm.conf" <<CONF
# One-node Slurm for asperity's tests, written by tools/slurm-local.sh.
ClusterName=asperity-local
SlurmctldHost=$host
AuthType=auth/munge
SlurmUser=root
SlurmdUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
MinJobAge=600
StateSaveLocation=$state/state
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/slurmctld.log
SlurmdLogFile=$state/slurmd.log
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$state/slurm.conf

  if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    [ -s /etc/munge/munge.key ] || mungekey --create >&2 || fail "no munge key and mungekey failed"
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    chown munge:munge /etc/munge /etc/munge/munge.key /run/munge /var/log/munge /var/lib/munge
    chmod 0700 /etc/munge /var/log/munge /var/lib/munge
    chmod 0400 /etc/munge/munge.key
    runuser -u munge -- munged >&2 || fail "munged did not start"
    cat /run/munge/munged.pid > "$state/munged.pid"
  fi
  slurmctld >&2 || fail "slurmctld did not start (see $state/slurmctld.log)"
  slurmd >&2 || fail "slurmd did not start (see $state/slurmd.log)"
  local t
  for t in $(seq 60); do
    if [ "$(sinfo -h -n "$host" -o %T 2>/dev/null)" = idle ]; then
      echo "$SLURM_CONF"
      return 0
    fi
    sleep 1
  done
  fail "the node $host is not idle after 60 s: $(sinfo -h -o '%T %E' 2>&1 | head -1) (logs in $state)"
}

stop() {
  local state=${1:-}
  [ -n "$state" ] && [ -f "$state/.slurm-local" ] || fail "stop: $state is not a folder slurm-local.sh start made"
  local daemon pid
  for daemon in slurmd slurmctld munged; do
    if [ -s "$state/$daemon.pid" ]; then
      pid=$(cat "$state/$daemon.pid")
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    fi
  done
  rm -rf "$state"
}

case "${1:-}" in
  start) start ;;
  stop) stop "${2:-}" ;;
  *) fail "usage: tools/slurm-local.sh start | stop STATE" ;;
esac
