#!/usr/bin/env bash
# An ablation grid as a Slurm job array: one shard per array task, one core each.
#   sbatch --array=0-15 scripts/slurm_ablate.sh results/grid_verdict.json results/verdict
# then, once every task has finished:
#   ./build/apps/saresgs ablate merge --config results/grid_verdict.json --out results/verdict
# A task that is cancelled or preempted can be resubmitted as is: finished jobs are skipped
# and a killed job resumes from its checkpoint.
#SBATCH --job-name=saresgs-ablate
#SBATCH --cpus-per-task=1
#SBATCH --mem=4G
#SBATCH --time=12:00:00
set -euo pipefail
config="${1:?usage: sbatch --array=0-N scripts/slurm_ablate.sh GRID.json OUT}"
out="${2:?usage: sbatch --array=0-N scripts/slurm_ablate.sh GRID.json OUT}"
cd "${SLURM_SUBMIT_DIR:-$(dirname "$0")/..}"
# SHARDS: the grid's shard count when only some tasks are resubmitted (--array=3,7 makes
# SLURM_ARRAY_TASK_COUNT 2, not the grid's n): SHARDS=16 sbatch --array=3,7 ...
./build/apps/saresgs ablate --config "$config" --out "$out" \
  --shard "${SLURM_ARRAY_TASK_ID}/${SHARDS:-${SLURM_ARRAY_TASK_COUNT}}"
