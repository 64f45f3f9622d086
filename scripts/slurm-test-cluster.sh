#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, from Debian's packages (slurm-wlm, munge), for
# trying `sortsim sweep --slurm` and for its integration test. Not for production: the
# daemons run as root, without cgroups or accounting.
#
#   scripts/slurm-test-cluster.sh start   # install if needed, start munged, slurmctld, slurmd
#   scripts/slurm-test-cluster.sh stop    # stop all three
#   scripts/slurm-test-cluster.sh env     # print the export line clients need
#
# Everything lives under $SORTSIM_SLURM_DIR (default /tmp/sortsim-slurm): slurm.conf, the
# daemons' logs, pid files and state. Clients (sbatch, squeue, sortsim --submit) find the
# cluster through SLURM_CONF=$SORTSIM_SLURM_DIR/slurm.conf. Needs root.
set -euo pipefail

dir="${SORTSIM_SLURM_DIR:-/tmp/sortsim-slurm}"
conf="$dir/slurm.conf"

install_packages() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null \
        && command -v sbatch >/dev/null && command -v munged >/dev/null; then
        return
    fi
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends slurm-wlm munge
}

start_munge() {
    if [ ! -s /etc/munge/munge.key ]; then
        mkdir -p /etc/munge
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=128 status=none
        chown munge:munge /etc/munge/munge.key 2>/dev/null || true
        chmod 400 /etc/munge/munge.key
    fi
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    chown munge:munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null || true
    if ! munge -n >/dev/null 2>&1; then
        if id munge >/dev/null 2>&1; then
            runuser -u munge -- munged
        else
            munged --force
        fi
    fi
    for _ in $(seq 50); do
        munge -n >/dev/null 2>&1 && return
        sleep 0.1
    done
    echo "munged did not start" >&2
    exit 1
}

write_conf() {
    local host cpus mem_mb
    host="$(hostname -s)"
    cpus="$(nproc)"
    mem_mb=$(($(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512))
    mkdir -p "$dir/state" "$dir/spool"
    cat >"$conf" <<EOF
ClusterName=sortsim-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CryptoType=crypto/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
DefMemPerCPU=1024
MpiDefault=none
ReturnToService=2
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
}

wait_idle() {
    for _ in $(seq 150); do
        state="$(SLURM_CONF="$conf" sinfo -h -o %T 2>/dev/null || true)"
        case "$state" in
        idle* | mixed* | allocated*) return ;;
        esac
        sleep 0.2
    done
    echo "the node did not come up (state: ${state:-none}); see $dir/slurmctld.log and $dir/slurmd.log" >&2
    exit 1
}

stop() {
    for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid"; do
        if [ -s "$pidfile" ]; then
            kill "$(cat "$pidfile")" 2>/dev/null || true
        fi
    done
    for _ in $(seq 50); do
        alive=0
        for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid"; do
            if [ -s "$pidfile" ] && kill -0 "$(cat "$pidfile")" 2>/dev/null; then alive=1; fi
        done
        [ "$alive" = 0 ] && break
        sleep 0.1
    done
    rm -f "$dir/slurmd.pid" "$dir/slurmctld.pid"
    if [ -s /run/munge/munged.pid ]; then
        kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true
    fi
}

case "${1:-}" in
start)
    install_packages
    stop
    start_munge
    write_conf
    # -c: a clean start, forgetting jobs of an earlier cluster in the same folder.
    slurmctld -c -f "$conf"
    slurmd -f "$conf"
    wait_idle
    echo "export SLURM_CONF=$conf"
    ;;
stop)
    stop
    ;;
env)
    echo "export SLURM_CONF=$conf"
    ;;
*)
    echo "usage: $0 start|stop|env" >&2
    exit 2
    ;;
esac
