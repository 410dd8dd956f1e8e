#!/usr/bin/env bash
# A single-node Slurm cluster for the tests of rcfd-server's Slurm executor (tests/slurm):
#   start-slurm.sh DIR start   writes DIR/slurm.conf and a munge key, starts munged, slurmctld and slurmd
#                              (as root) and waits until the node takes jobs;
#   start-slurm.sh DIR stop    stops the daemons this script started (by the pids in DIR).
# Everything lives in DIR: the daemons' state, logs, sockets and ports of their own, so the cluster
# neither needs nor disturbs a site's Slurm or munge. Clients find it with SLURM_CONF=DIR/slurm.conf.
# Where Slurm cannot run (not root, slurm-wlm or munge not installed) `start` writes the reason to
# DIR/unavailable and exits 0: the tests then skip with that reason instead of failing.
set -euo pipefail
dir=${1:?usage: start-slurm.sh DIR start|stop}
action=${2:?usage: start-slurm.sh DIR start|stop}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
conf=$dir/slurm.conf

stop_daemons() {
  local name pid
  for name in slurmd slurmctld munged; do
    [ -f "$dir/$name.pid" ] || continue
    pid=$(cat "$dir/$name.pid")
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
      kill -TERM "$pid" 2>/dev/null || true
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null || true
    fi
    rm -f "$dir/$name.pid"
  done
}

unavailable() {
  echo "$1" > "$dir/unavailable"
  echo "start-slurm.sh: Slurm tests will be skipped: $1" >&2
  exit 0
}

# A free TCP port on loopback at or above $1.
free_port() {
  local port=$1
  # A connection that succeeds finds a listener there (bash's /dev/tcp: no tool needed).
  while (exec 3<> "/dev/tcp/127.0.0.1/$port") 2> /dev/null; do port=$((port + 1)); done
  echo "$port"
}

if [ "$action" = stop ]; then
  stop_daemons
  rm -f "$dir/ready"
  exit 0
fi
[ "$action" = start ] || { echo "start-slurm.sh: unknown action $action" >&2; exit 2; }

rm -f "$dir/unavailable" "$dir/ready"
[ "$(id -u)" -eq 0 ] || unavailable "the test cluster's daemons must run as root (this is uid $(id -u))"
for program in munged slurmctld slurmd sbatch squeue scontrol scancel; do
  command -v "$program" > /dev/null ||
    unavailable "$program is not installed (scripts/install-deps.sh installs slurm-wlm and munge)"
done

# A cluster left running by an earlier start is stopped: every run starts from an empty queue.
stop_daemons
rm -rf "$dir/state" "$dir/spool" "$dir/log" "$dir/munge" "$dir/munge-key"
mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/munge" "$dir/munge-key"
# munged wants its socket's directory open to all (every user's client talks to it) and its key private.
chmod 755 "$dir/munge"
chmod 700 "$dir/munge-key"
head -c 1024 /dev/urandom > "$dir/munge-key/munge.key"
chmod 400 "$dir/munge-key/munge.key"

node=$(hostname -s)
cpus=4  # more than this machine may have (config_overrides): tiny test jobs share the cores
ctld_port=$(free_port 16817)
slurmd_port=$(free_port $((ctld_port + 1)))
cat > "$conf" <<CONF
# Written by tests/slurm/start-slurm.sh: a single-node test cluster (docs/cluster.md).
ClusterName=rcfdtest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# No cgroups: the tests run in containers where Slurm's cgroup plugins cannot work.
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
# No slurmdbd: job states come from squeue, which keeps finished jobs for MinJobAge seconds.
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MinJobAge=600
# Seconds between SIGTERM and SIGKILL when a job ends by its time limit or a cancel: time to checkpoint.
KillWait=10
SchedulerType=sched/builtin
# A node an administrator set DOWN stays down until it is resumed (scontrol update ... state=resume).
ReturnToService=1
SlurmdParameters=config_overrides
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=4000 State=UNKNOWN
PartitionName=rcfdtest Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$conf

munged --socket="$dir/munge/munge.socket" --key-file="$dir/munge-key/munge.key" \
  --pid-file="$dir/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge-key/seed" \
  || unavailable "munged did not start (see $dir/log/munged.log)"
slurmctld -c -f "$conf" 2>> "$dir/log/slurmctld.stderr" || unavailable "slurmctld did not start (see $dir/log/slurmctld.log)"
slurmd -c -f "$conf" 2>> "$dir/log/slurmd.stderr" || unavailable "slurmd did not start (see $dir/log/slurmd.log)"

for _ in $(seq 300); do
  state=$(sinfo -h -n "$node" -o %T 2>/dev/null || true)
  if [ "$state" = idle ]; then
    echo "$node" > "$dir/ready"
    echo "start-slurm.sh: single-node Slurm up: SLURM_CONF=$conf (node $node, ports $ctld_port/$slurmd_port)"
    exit 0
  fi
  sleep 0.1
done
stop_daemons
unavailable "the node $node did not become idle within 30 s (state '${state:-none}'; see $dir/log)"
