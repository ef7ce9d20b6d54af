# A one-node Slurm on this machine, for trying the cluster path without a
# cluster (and for tests/integration/test_slurm.sh and bench/slurm_vs_local.sh).
# Source it, then:
#   slurm_local_start DIR CPUS   starts munged (as the munge user, socket in
#                                DIR), slurmctld and slurmd with a config
#                                written to DIR/slurm.conf, waits for the node
#                                and exports SLURM_CONF; on failure prints
#                                why and returns 1 (what did start keeps
#                                running: call slurm_local_stop)
#   slurm_local_stop DIR         stops the three daemons (TERM, then KILL)
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
    local dir=${1:?slurm_local_stop DIR} f
    for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/pid"; do
        [ -s "$f" ] && kill "$(cat "$f")" 2> /dev/null || true
    done
    sleep 1
    for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/pid"; do
        [ -s "$f" ] && kill -9 "$(cat "$f")" 2> /dev/null || true
    done
}
