#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for `rmapgen prove --slurm` in make test
# (make slurm-test): Debian's munge and slurm-wlm (Slurm 22.05), every file in DIR (the key,
# the sockets, the config, the state, the logs), the daemons on localhost with root as the
# Slurm user, accounting off and no cgroups. Nothing outside DIR is read or written but the
# daemons' TCP ports (SLURM_PORT, default 16817, and the next one).
#
#   slurm-cluster.sh start DIR   starts munged, slurmctld and slurmd, waits until the node is
#                                idle, prints `export SLURM_CONF=DIR/slurm.conf`
#   slurm-cluster.sh stop DIR    stops every daemon it started (by its pid file) and waits
#                                until they are gone
#
# The daemons must run as root (the Slurm user here); a real cluster has its own, and
# `rmapgen prove --slurm` only needs sbatch and scancel on PATH and SLURM_CONF (or the
# site's /etc/slurm/slurm.conf). Fails loudly (exit 1) when a daemon does not come up, after
# stopping the others; its log is printed.
set -euo pipefail
cmd=${1:-}; dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: slurm-cluster.sh start|stop DIR" >&2; exit 2; }
port=${SLURM_PORT:-16817}

stop() {
  local name pid
  for name in slurmd slurmctld munged; do
    [ -f "$dir/$name.pid" ] || continue
    pid=$(cat "$dir/$name.pid")
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null || true
    fi
    rm -f "$dir/$name.pid"
  done
}

fail() {
  echo "slurm-cluster: $1" >&2
  [ -f "$2" ] && tail -20 "$2" >&2
  stop
  exit 1
}

case $cmd in
stop)
  stop
  echo "slurm-cluster: stopped (files kept in $dir)"
  ;;
start)
  [ "$(id -u)" = 0 ] || { echo "slurm-cluster: the one-node cluster runs its daemons as root" >&2; exit 1; }
  for p in munged slurmctld slurmd sbatch; do
    command -v "$p" >/dev/null || { echo "slurm-cluster: $p not found: apt-get install slurm-wlm munge" >&2; exit 1; }
  done
  stop
  dir=$(mkdir -p "$dir" && cd "$dir" && pwd)
  rm -rf "$dir/state" "$dir/spool" "$dir/munge"
  mkdir -p "$dir/state" "$dir/spool" "$dir/munge/key"
  # munged checks that its key is its own and private, and that its socket's directory is
  # open to every client but writable only by it.
  chmod 755 "$dir/munge"
  chmod 700 "$dir/munge/key"
  dd if=/dev/urandom of="$dir/munge/key/munge.key" bs=1024 count=1 status=none
  chmod 600 "$dir/munge/key/munge.key"
  node=$(hostname -s)
  cpus=$(nproc)
  cat > "$dir/slurm.conf" <<EOF
# Written by scripts/slurm-cluster.sh: a one-node cluster for rmapgen's tests.
ClusterName=rmapgen
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MinJobAge=600
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
  munged --key-file "$dir/munge/key/munge.key" --socket "$dir/munge/munge.socket" \
    --pid-file "$dir/munged.pid" --log-file "$dir/munged.log" --seed-file "$dir/munge/key/munge.seed" \
    || fail "munged did not start" "$dir/munged.log"
  export SLURM_CONF=$dir/slurm.conf
  slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start" "$dir/slurmctld.log"
  slurmd -f "$SLURM_CONF" || fail "slurmd did not start" "$dir/slurmd.log"
  for _ in $(seq 100); do
    state=$(sinfo -h -N -o %t 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.2
  done
  [ "$state" = idle ] || fail "the node is not idle after 20 s (sinfo: ${state:-nothing})" "$dir/slurmctld.log"
  echo "slurm-cluster: $node up ($cpus CPUs) in $dir"
  echo "export SLURM_CONF=$SLURM_CONF"
  ;;
*)
  echo "usage: slurm-cluster.sh start|stop DIR" >&2; exit 2
  ;;
esac
