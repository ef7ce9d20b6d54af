#!/usr/bin/env bash
# Submits a tcbench config as a Slurm job array over its missing cells.
#   scripts/slurm/submit.sh CONFIG [--tasks N] [--sbatch "ARGS"] [tcbench run options...]
# Without --tasks: one array task per missing cell (the array's indices are
# the cell ids). With --tasks N: N tasks, each running the cells whose id is
# its index modulo N (cells already done are skipped by tcbench itself).
# tcbench run options (--variant, --root D=DIR, --out DIR, --lock-timeout S)
# are passed to every task; TCBENCH names the binary (default: tcbench on
# PATH). Prints sbatch's job id line.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
tcbench=${TCBENCH:-tcbench}
config=${1:?usage: submit.sh CONFIG [--tasks N] [--sbatch "ARGS"] [tcbench run options]}
shift
tasks=0 sbatch_args="" run_args=()
while [ $# -gt 0 ]; do
    case "$1" in
        --tasks) tasks=${2:?--tasks needs a number}; shift 2 ;;
        --sbatch) sbatch_args=${2:?--sbatch needs its arguments}; shift 2 ;;
        *) run_args+=("$1"); shift ;;
    esac
done
# The status of the config as these options resolve it: the ids a run computes (missing, failed).
status_args=()
for ((k = 0; k < ${#run_args[@]}; k++)); do
    case "${run_args[k]}" in --variant|--root|--out) status_args+=("${run_args[k]}" "${run_args[k + 1]}"); k=$((k + 1)) ;; esac
done
array=$("$tcbench" status "$config" "${status_args[@]}" | sed -n 's/^resubmit the cells a run computes ([^)]*): --array=//p')
if [ -z "$array" ]; then echo "submit.sh: every cell of $config is done" >&2; exit 0; fi
export TCBENCH="$tcbench"
if [ "$tasks" -gt 0 ]; then
    # shellcheck disable=SC2086 # sbatch_args is a list of words
    exec sbatch $sbatch_args --array="0-$((tasks - 1))" --export=ALL,TCBENCH_SHARD=1 \
        "$here/tcbench-array.sbatch" "$config" "${run_args[@]}"
fi
# shellcheck disable=SC2086
exec sbatch $sbatch_args --array="$array" --export=ALL "$here/tcbench-array.sbatch" "$config" "${run_args[@]}"
