#!/usr/bin/env bash
# Submits a tcbench config as a Slurm job array over the cells a run would
# compute (missing, failed and stale ones, less those already queued).
#   scripts/slurm/submit.sh CONFIG [--tasks N] [--max-running K] [--sbatch "ARGS"] [tcbench run options...]
# Without --tasks: one array task per cell (the array's indices are the cell
# ids, so the largest id must be below the cluster's MaxArraySize). With
# --tasks N: N tasks, each running the cells whose id is its index modulo N
# (cells already done are skipped by tcbench itself). --max-running K lets
# at most K tasks of the array run at once (sbatch's --array=...%K).
# tcbench run options (--variant, --root D=DIR, --out DIR, --lock-timeout S)
# are passed to every task. The binary: $TCBENCH if set, else this
# checkout's build/tcbench, else tcbench on PATH; the line "submit.sh: using
# ..." says which. Every task needs it, the config and the run directory at
# the same paths (a shared file system). The job's comment names the run
# directory ("tcbench run=DIR", "tcbench shards=N run=DIR"), which is how
# `tcbench status` finds its queued tasks. Prints sbatch's job id line.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
usage='usage: submit.sh CONFIG [--tasks N] [--max-running K] [--sbatch "ARGS"] [tcbench run options]'
config=${1:?$usage}
shift
tasks=0 throttle="" sbatch_args="" run_args=()
while [ $# -gt 0 ]; do
    case "$1" in
        --tasks) tasks=${2:?--tasks needs a number}; shift 2 ;;
        --max-running) throttle=%${2:?--max-running needs a number}; shift 2 ;;
        --sbatch) sbatch_args=${2:?--sbatch needs its arguments}; shift 2 ;;
        *) run_args+=("$1"); shift ;;
    esac
done

# The binary: TCBENCH, this checkout's build, or PATH's; absolute, for the tasks.
build=$(cd "$here/../.." && pwd)/build/tcbench
if [ -n "${TCBENCH:-}" ]; then
    tcbench=$(command -v "$TCBENCH") || { echo "submit.sh: TCBENCH=$TCBENCH: no such program" >&2; exit 2; }
    from="TCBENCH"
elif [ -x "$build" ]; then
    tcbench=$build from="this checkout's build"
elif tcbench=$(command -v tcbench); then
    from="tcbench on PATH"
else
    echo "submit.sh: no tcbench: neither $build (cmake --build build) nor tcbench on PATH; or set TCBENCH=/path/to/tcbench" >&2
    exit 2
fi
tcbench=$(realpath "$tcbench")
echo "submit.sh: using $tcbench ($from)" >&2

# The status of the config as these options resolve it: the ids a run computes.
status_args=()
for ((k = 0; k < ${#run_args[@]}; k++)); do
    case "${run_args[k]}" in --variant|--root|--out) status_args+=("${run_args[k]}" "${run_args[k + 1]}"); k=$((k + 1)) ;; esac
done
status=$("$tcbench" status "$config" "${status_args[@]}")
array=$(sed -n 's/^resubmit the cells a run computes ([^)]*): --array=//p' <<< "$status")
if [ -z "$array" ]; then
    echo "submit.sh: nothing to submit: every cell of $config is done, running or queued (tcbench status)" >&2
    exit 0
fi
# The run directory as status resolved it, absolute: the job's comment.
run_dir=$(sed -n 's/^\(.*\): [0-9]* cells: .*/\1/p' <<< "$status")
mkdir -p "$run_dir"
run_dir=$(realpath "$run_dir")
# The mark that makes `tcbench status` ask squeue about this run directory
# (a run that never went through Slurm is not asked about).
printf '%s %s\n' "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "$config" >> "$run_dir/slurm-submissions.log"
export TCBENCH="$tcbench"
if [ "$tasks" -gt 0 ]; then
    # shellcheck disable=SC2086 # sbatch_args is a list of words
    exec sbatch $sbatch_args --array="0-$((tasks - 1))$throttle" --comment="tcbench shards=$tasks run=$run_dir" \
        --export=ALL,TCBENCH_SHARD=1 "$here/tcbench-array.sbatch" "$config" "${run_args[@]}"
fi
last=${array##*[,-]} # the largest id
max=$(scontrol show config 2> /dev/null | sed -n 's/^MaxArraySize *= *\([0-9]*\).*/\1/p')
if [ -n "$max" ] && [ "$last" -ge "$max" ]; then
    echo "submit.sh: cell $last is past this cluster's MaxArraySize ($max: array indices 0-$((max - 1))), and a task's index is its cell id; use --tasks N (N <= $max), each task running the cells whose id is its index modulo N" >&2
    exit 2
fi
# shellcheck disable=SC2086
exec sbatch $sbatch_args --array="$array$throttle" --comment="tcbench run=$run_dir" --export=ALL \
    "$here/tcbench-array.sbatch" "$config" "${run_args[@]}"
