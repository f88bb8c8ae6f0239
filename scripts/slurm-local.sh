#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, from Debian's packages, for the sweep's Slurm
# path (tests/slurm.rs, docs/sweeps.md):
#
#   scripts/slurm-local.sh up     # install slurmctld, slurmd, munge when missing; start them
#   scripts/slurm-local.sh down   # stop the daemons this script started
#   scripts/slurm-local.sh status
#
# Needs root (CI and the developers' machines run as root). The configuration lives in
# /etc/slurm/slurm.conf (written by `up`): proctrack/linuxproc and task/none (no cgroups
# needed), the node's CPUs and memory, no accounting, both daemons as root; munge with a
# fresh key. `up` waits until the node is idle (a few seconds); `down` stops the daemons
# by their pid files and is safe to run when nothing is up.
#
# It never touches a Slurm configuration it did not write: `up` refuses (exit 3, nothing
# changed) when /etc/slurm/slurm.conf exists without the marker line below, which only this
# script writes, so on a cluster node the site's scheduler, its spool directories and its
# daemons are left alone. tests/slurm.rs runs it only with MECANO_SLURM_TEST=1 (.ci/run).
set -euo pipefail

RUN=/run/mecano-slurm
CONF=/etc/slurm/slurm.conf
NODE=$(hostname -s)
MARK="# mecano-rs scripts/slurm-local.sh: a throw-away one-node cluster; this file may be rewritten."
# The first line the versions of this script before the marker wrote (stop 21-22): a
# configuration that starts with it is this script's too, left by an older checkout.
OLD_HEAD="# Written by mecano-rs scripts/slurm-local.sh: a one-node cluster on"

log() { echo "slurm-local: $*" >&2; }

install() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null \
        && command -v munged >/dev/null && command -v sbatch >/dev/null; then
        return
    fi
    log "installing slurmctld slurmd slurm-client munge (apt-get)"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends slurmctld slurmd slurm-client munge >/dev/null
}

write_conf() {
    local cpus mem
    cpus=$(nproc)
    mem=$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.8 }' /proc/meminfo)
    mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm "$RUN"
    cat > "$CONF" <<CONF
$MARK
# Written by mecano-rs scripts/slurm-local.sh: a one-node cluster on $NODE.
ClusterName=mecano
SlurmctldHost=$NODE
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=$RUN/slurmctld.pid
SlurmdPidFile=$RUN/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=300
KillWait=5
Waittime=0
NodeName=$NODE CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
}

start_munge() {
    mkdir -p /etc/munge /var/lib/munge /var/log/munge /run/munge
    if [ ! -s /etc/munge/munge.key ]; then
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
    chown -R munge:munge /etc/munge /var/lib/munge /var/log/munge /run/munge
    chmod 0700 /etc/munge /var/lib/munge /var/log/munge
    chmod 0400 /etc/munge/munge.key
    chmod 0755 /run/munge
    if [ -s /run/munge/munged.pid ] && kill -0 "$(cat /run/munge/munged.pid)" 2>/dev/null; then
        return
    fi
    runuser -u munge -- /usr/sbin/munged
    touch "$RUN/munge.ours"
}

stop_pid() { # pid file, name
    if [ -s "$1" ]; then
        local pid
        pid=$(cat "$1")
        if kill -0 "$pid" 2>/dev/null; then
            kill "$pid" 2>/dev/null || true
            for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
            kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null || true
            log "stopped $2 ($pid)"
        fi
        rm -f "$1"
    fi
}

# Refuses (exit 3) when a Slurm configuration exists that this script did not write.
ours_or_none() {
    if [ -e "$CONF" ] && ! grep -qxF "$MARK" "$CONF" \
        && ! head -n 1 "$CONF" | grep -qF "$OLD_HEAD"; then
        log "$CONF exists and was not written by this script: refusing to touch this host's Slurm"
        exit 3
    fi
}

up() {
    [ "$(id -u)" = 0 ] || { log "needs root"; exit 1; }
    ours_or_none
    install
    ours_or_none # a package's postinst may have written one
    write_conf
    start_munge
    stop_pid "$RUN/slurmd.pid" slurmd
    stop_pid "$RUN/slurmctld.pid" slurmctld
    # A fresh controller state each time: no jobs of an earlier run come back.
    rm -rf /var/spool/slurmctld/* /var/spool/slurmd/*
    slurmctld -i
    slurmd
    for _ in $(seq 60); do
        state=$(sinfo -h -n "$NODE" -o %t 2>/dev/null || true)
        case "$state" in
            idle*|mix*|alloc*) log "up: node $NODE $state"; return 0 ;;
            down*|drain*) scontrol update nodename="$NODE" state=resume 2>/dev/null || true ;;
        esac
        sleep 0.5
    done
    log "the node did not become idle; logs in /var/log/slurm/"
    tail -n 20 /var/log/slurm/slurmctld.log /var/log/slurm/slurmd.log >&2 || true
    exit 1
}

down() {
    stop_pid "$RUN/slurmd.pid" slurmd
    stop_pid "$RUN/slurmctld.pid" slurmctld
    if [ -e "$RUN/munge.ours" ]; then
        stop_pid /run/munge/munged.pid munged
        rm -f "$RUN/munge.ours"
    fi
}

case "${1:-}" in
    up) up ;;
    down) down ;;
    status) sinfo; squeue ;;
    *) echo "usage: $0 up|down|status" >&2; exit 2 ;;
esac
