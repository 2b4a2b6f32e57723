#!/bin/bash
# A large dwellfit sensitivity study as a Slurm job array: N tasks each run one
# shard k/N of the same study (same flags, same seed), then one dependent job
# merges them. Submit from the repository root after a build:
#
#   jobs=$(sbatch --parsable docs/slurm/sensitivity_array.sh)
#   sbatch --dependency=afterok:$jobs --wrap \
#     "build/tools/sensitivity --merge $(printf 'study/shard%d,' $(seq 0 15) | sed 's/,$//') --output_dir study"
#
# Every shard writes fits.csv, summary.yaml and study.yaml into its own folder
# (all or nothing, listed in manifest.yaml); the merge checks that shards
# 0..N-1 of one study are all there and writes the fits in the order of one
# run: its fits.csv is byte for byte the one a single run would write.
#SBATCH --job-name=dwellfit-sensitivity
#SBATCH --array=0-15
#SBATCH --cpus-per-task=4
#SBATCH --time=01:00:00
#SBATCH --output=study/logs/shard-%a.log
set -euo pipefail
shards=16
mkdir -p study/logs
build/tools/sensitivity \
  --config datasets/thesis-numerical/beam.yaml \
  --plan datasets/thesis-numerical/plan.yaml \
  --replicas 100000 --noise 0.01 --first_seed 1 \
  --threads "${SLURM_CPUS_PER_TASK}" \
  --shard "${SLURM_ARRAY_TASK_ID}/${shards}" \
  --output_dir "study/shard${SLURM_ARRAY_TASK_ID}"
