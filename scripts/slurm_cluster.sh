#!/usr/bin/env bash
# Single-node SLURM cluster on this machine, for the integration tests and for trying
# the SLURM profile without an institute cluster.
#
#   scripts/slurm_cluster.sh start    # install (if needed), configure, start; wait until the node is idle
#   scripts/slurm_cluster.sh stop     # stop slurmd, slurmctld and munged started by `start`
#   scripts/slurm_cluster.sh status   # exit 0 if the cluster answers and the node is up
#
# Needs root and Debian packages slurm-wlm and munge (installed with apt-get when missing
# and SLURM_CLUSTER_INSTALL=1, the default). No systemd: munged, slurmctld and slurmd are
# started directly. There is no accounting database, so `sacct` returns nothing; MinJobAge
# is raised so that finished jobs stay visible to `squeue` (Snakemake's SLURM executor then
# polls with `--slurm-status-command squeue`). Idempotent: `start` on a running cluster only
# waits for the node; `stop` on a stopped one does nothing.
#
# Environment: SLURM_CLUSTER_DIR (state, logs, pid files; default /tmp/slurm-shadowcam),
# SLURM_CLUSTER_PARTITION (default "debug"), SLURM_CLUSTER_INSTALL (0 = never apt-get).
set -euo pipefail

STATE=${SLURM_CLUSTER_DIR:-/tmp/slurm-shadowcam}
PARTITION=${SLURM_CLUSTER_PARTITION:-debug}
CONF_DIR=/etc/slurm
CONF=$CONF_DIR/slurm.conf
# The config this script writes is marked, so that it never overwrites a real site config.
MARK="# written by shadowcam scripts/slurm_cluster.sh"

die() { echo "slurm_cluster.sh: $*" >&2; exit 1; }

need_root() {
    [ "$(id -u)" -eq 0 ] || die "must run as root (munged, slurmctld and slurmd are started directly)"
}

install_packages() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v munged >/dev/null; then
        return
    fi
    [ "${SLURM_CLUSTER_INSTALL:-1}" = 1 ] || die "slurm-wlm/munge not installed (apt-get install -y slurm-wlm munge)"
    command -v apt-get >/dev/null || die "slurm-wlm/munge not installed and no apt-get to install them"
    echo "installing slurm-wlm and munge with apt-get" >&2
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q >&2
    apt-get install -y -q slurm-wlm munge >&2
}

write_config() {
    local host cpus mem_mb
    host=$(hostname -s)
    cpus=$(nproc)
    # leave 1 GiB to the OS; slurmd refuses a node that claims more memory than it has
    mem_mb=$(( $(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 1024 ))
    if [ -f "$CONF" ] && ! grep -qF "$MARK" "$CONF"; then
        die "$CONF exists and was not written by this script; refusing to overwrite a site config"
    fi
    mkdir -p "$CONF_DIR" "$STATE"/{ctld,d,log}
    cat >"$CONF" <<EOF
$MARK
ClusterName=shadowcam
SlurmctldHost=$host
AuthType=auth/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/d
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/log/slurmctld.log
SlurmdLogFile=$STATE/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
# cores and memory are consumable, so several 1-core jobs share the node
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
# no accounting database: keep finished jobs in squeue for 30 min (status polling)
MinJobAge=1800
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
NodeName=$host CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=$PARTITION Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    # jobs are tracked as plain processes (no cgroup confinement on a test node)
    printf "%s\nCgroupPlugin=autodetect\nIgnoreSystemd=yes\n" "$MARK" >"$CONF_DIR/cgroup.conf"
}

pid_alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }

start_munge() {
    if munge -n </dev/null >/dev/null 2>&1; then
        return
    fi
    mkdir -p /run/munge /var/log/munge /var/lib/munge
    chown munge:munge /run/munge /var/log/munge /var/lib/munge
    [ -f /etc/munge/munge.key ] || { mungekey --create >&2 && chown munge:munge /etc/munge/munge.key; }
    # munged drops to the munge user; --force tolerates a stale socket of a killed daemon
    runuser -u munge -- munged --force
    touch "$STATE/munged.ours"  # stop only a munged that this script started
    for _ in $(seq 50); do munge -n </dev/null >/dev/null 2>&1 && return; sleep 0.1; done
    die "munged did not start (see /var/log/munge/munged.log)"
}

node_state() { sinfo -h -N -o '%t' 2>/dev/null | head -n1 || true; }

start() {
    need_root
    install_packages
    write_config
    mkdir -p "$STATE"
    start_munge
    pid_alive "$STATE/slurmctld.pid" || slurmctld
    pid_alive "$STATE/slurmd.pid" || slurmd
    local state=""
    for _ in $(seq 120); do
        state=$(node_state)
        case "$state" in
            idle|mix|alloc) echo "SLURM node $(hostname -s) is $state (partition $PARTITION)"; return ;;
            down*|drain*|drng*|fail*)
                scontrol update nodename="$(hostname -s)" state=resume >/dev/null 2>&1 || true ;;
        esac
        sleep 0.5
    done
    die "node did not become idle within 60 s (state '$state'); logs in $STATE/log"
}

stop_daemon() {  # $1 pid file, $2 name
    pid_alive "$1" || return 0
    local pid
    pid=$(cat "$1")
    kill "$pid"
    for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
    echo "$2 (pid $pid) needed SIGKILL" >&2
}

stop() {
    need_root
    stop_daemon "$STATE/slurmd.pid" slurmd
    stop_daemon "$STATE/slurmctld.pid" slurmctld
    if [ -f "$STATE/munged.ours" ]; then
        stop_daemon /run/munge/munged.pid munged
        rm -f "$STATE/munged.ours"
    fi
    echo "SLURM cluster stopped"
}

status() {
    local state
    state=$(node_state)
    case "$state" in
        idle|mix|alloc) echo "SLURM node $(hostname -s) is $state"; return 0 ;;
        *) echo "SLURM cluster not running (node state '${state:-none}')"; return 1 ;;
    esac
}

case "${1:-}" in
    start) start ;;
    stop) stop ;;
    status) status ;;
    *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
