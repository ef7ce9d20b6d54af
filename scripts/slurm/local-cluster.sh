#!/usr/bin/env bash
# A one-node Slurm on this machine, for trying the cluster path without a
# cluster (and for tests/integration/test_slurm.sh and bench/slurm_vs_local.sh).
# As a command:
#   scripts/slurm/local-cluster.sh start [DIR [CPUS]]  starts it (DIR default
#       /tmp/tcbench-slurm, CPUS default all), prints the export to run
#   scripts/slurm/local-cluster.sh env [DIR]   prints `export SLURM_CONF=...`:
#       eval "$(scripts/slurm/local-cluster.sh env)"
#   scripts/slurm/local-cluster.sh stop [DIR]  stops it
#   scripts/slurm/local-cluster.sh --help
# Sourced, it defines:
#   slurm_local_start DIR CPUS   starts munged (as the munge user, socket in
#                                DIR), slurmctld and slurmd with a config
#                                written to DIR/slurm.conf, waits for the node
#                                and exports SLURM_CONF; on failure prints
#                                why and returns 1 (what did start keeps
#                                running: call slurm_local_stop)
#   slurm_local_stop DIR         stops the three daemons (TERM, then KILL)
#   slurm_local_missing          prints what is missing and returns 0, or 1
# Needs root and Debian's slurm-wlm and munge (Slurm 22.05): SlurmUser=root,
# proctrack/linuxproc and task/none so that no systemd or cgroup is needed.
# DIR must be readable by the munge user (mode 755).

slurm_local_missing() {
    [ "$(id -u)" -eq 0 ] || { echo "needs root to start slurmd and munged"; return 0; }
    local b
    for b in munged slurmctld slurmd sbatch scontrol squeue sinfo runuser; do
        command -v "$b" > /dev/null || { echo "$b not found (scripts/setup.sh --tests installs slurm-wlm and munge)"; return 0; }
    done
    [ -r /etc/munge/munge.key ] || { echo "no /etc/munge/munge.key (the munge package makes it)"; return 0; }
    return 1
}

slurm_local_start() {
    local dir=${1:?slurm_local_start DIR CPUS} cpus=${2:?slurm_local_start DIR CPUS}
    mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
    chown munge:munge "$dir/munge" && chmod 755 "$dir/munge"
    runuser -u munge -- munged --socket="$dir/munge/sock" --pid-file="$dir/munge/pid" \
        --log-file="$dir/munge/log" --seed-file="$dir/munge/seed" ||
        { echo "munged did not start: $(cat "$dir/munge/log" 2> /dev/null)"; return 1; }
    local host port
    host=$(hostname -s)
    port=$((20000 + RANDOM % 20000))
    cat > "$dir/slurm.conf" <<CONF
ClusterName=tcblocal
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$dir/munge/sock
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
SchedulerParameters=sched_interval=2
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
    export SLURM_CONF="$dir/slurm.conf"
    slurmctld -f "$SLURM_CONF" || { echo "slurmctld did not start: $(tail -3 "$dir/slurmctld.log" 2> /dev/null)"; return 1; }
    slurmd -f "$SLURM_CONF" || { echo "slurmd did not start: $(tail -3 "$dir/slurmd.log" 2> /dev/null)"; return 1; }
    local _
    for _ in $(seq 100); do sinfo -h -o %t 2> /dev/null | grep -q idle && return 0; sleep 0.2; done
    echo "the node did not come up: $(tail -3 "$dir/slurmd.log" 2> /dev/null)"
    return 1
}

slurm_local_stop() {
    local dir=${1:?slurm_local_stop DIR} f pids=()
    # Its jobs first: slurmd waits for their steps before it exits.
    if [ -s "$dir/slurmctld.pid" ]; then
        SLURM_CONF="$dir/slurm.conf" scancel --me --full --signal=KILL 2> /dev/null
        SLURM_CONF="$dir/slurm.conf" scancel --me 2> /dev/null
        for _ in $(seq 20); do [ -z "$(SLURM_CONF="$dir/slurm.conf" squeue -h 2> /dev/null)" ] && break; sleep 0.25; done
    fi
    for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/pid"; do
        [ -s "$f" ] && pids+=("$(cat "$f")")
    done
    [ ${#pids[@]} -gt 0 ] || return 0
    kill "${pids[@]}" 2> /dev/null
    sleep 1
    kill -9 "${pids[@]}" 2> /dev/null || true
}

# The command: start, env, stop, --help (only when run, not when sourced).
slurm_local_main() {
    local cmd=${1:---help} dir=${2:-/tmp/tcbench-slurm}
    case "$cmd" in
        start)
            local why
            if why=$(slurm_local_missing); then echo "local-cluster.sh: $why" >&2; return 1; fi
            [ -e "$dir/slurmctld.pid" ] && kill -0 "$(cat "$dir/slurmctld.pid")" 2> /dev/null &&
                { echo "local-cluster.sh: already running in $dir (local-cluster.sh stop $dir)" >&2; return 1; }
            mkdir -p "$dir" && chmod 755 "$dir"
            why=$(slurm_local_start "$dir" "${3:-$(nproc)}") ||
                { echo "local-cluster.sh: $why (local-cluster.sh stop $dir stops what did start)" >&2; return 1; }
            echo "a one-node Slurm runs in $dir; for sbatch, squeue and scancel:"
            echo "export SLURM_CONF=$dir/slurm.conf" ;;
        env)
            [ -s "$dir/slurm.conf" ] || { echo "local-cluster.sh: no $dir/slurm.conf (local-cluster.sh start $dir)" >&2; return 1; }
            echo "export SLURM_CONF=$dir/slurm.conf" ;;
        stop) slurm_local_stop "$dir" ;;
        -h|--help) sed -n '2,/^$/s/^# \{0,1\}//p' "${BASH_SOURCE[0]}" ;;
        *) echo "local-cluster.sh: unknown command '$cmd' (start, env, stop, --help)" >&2; return 2 ;;
    esac
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
    set -u
    slurm_local_main "$@"
fi
