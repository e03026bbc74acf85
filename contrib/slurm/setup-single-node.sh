#!/usr/bin/env bash
# Starts a one-node Slurm cluster on this machine for trying and testing the job scripts beside
# this file: munged, slurmctld and slurmd, configured in a private folder (nothing in /etc/slurm
# is read or written). Needs root and Debian's packages: apt-get install slurm-wlm munge.
#
#   source <(contrib/slurm/setup-single-node.sh)   # starts it (once) and prints `export SLURM_CONF=…`
#   contrib/slurm/setup-single-node.sh --stop       # stops the daemons it started
set -euo pipefail
dir=${ALHAZEN_SLURM_DIR:-/tmp/alhazen-slurm}
conf=$dir/slurm.conf

stop() {
    # Only a process of that name (a stale pid file may name another process by now).
    for daemon in slurmd slurmctld; do
        [ -f "$dir/$daemon.pid" ] && pkill -F "$dir/$daemon.pid" -x "$daemon" 2>/dev/null || true
    done
}
if [ "${1:-}" = "--stop" ]; then stop; exit 0; fi

for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" >/dev/null || { echo "$tool is missing: apt-get install slurm-wlm munge" >&2; exit 1; }
done

# munge: the key Debian's package made, the daemon as its own user.
if ! pgrep -x munged >/dev/null; then
    [ -f /etc/munge/munge.key ] || { mungekey --create 2>/dev/null || dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=128 status=none; }
    chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    chown munge:munge /run/munge /var/log/munge /var/lib/munge
    runuser -u munge -- /usr/sbin/munged
fi

host=$(hostname -s)
mkdir -p "$dir/state" "$dir/spool" "$dir/log"
memory=$(( $(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 1024 ))
cat > "$conf" <<CONF
ClusterName=alhazen
SlurmctldHost=$host
AuthType=auth/munge
SlurmUser=root
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
NodeName=$host CPUs=$(nproc) RealMemory=$memory State=UNKNOWN
PartitionName=main Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF

export SLURM_CONF=$conf
if ! sinfo -h >/dev/null 2>&1; then
    stop
    slurmctld -f "$conf"
    slurmd -f "$conf"
fi
for _ in $(seq 60); do
    state=$(sinfo -h -o %t 2>/dev/null || true)
    case $state in idle*|mix*|alloc*) echo "export SLURM_CONF=$conf"; exit 0 ;; esac
    scontrol update NodeName="$host" State=RESUME >/dev/null 2>&1 || true
    sleep 1
done
echo "the Slurm node did not come up (state '${state:-none}'); see $dir/log/" >&2
exit 1
