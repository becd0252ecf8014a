#!/bin/bash
# A Slurm job array renders an image sequence in four shards: `sbatch sequence.sh ARGS…`,
# ARGS being render's (the scene, the size, --frames and --out 'frames/####.png'). Each task
# renders its block of the frames (--shard env reads the array's variables) and writes only
# those not written yet (--resume), so a requeued or rerun task finishes what is missing.
# On GPU nodes add --gres=gpu:1 to sbatch's own options.
#SBATCH --job-name=manylights-sequence
#SBATCH --array=0-3
#SBATCH --requeue
exec manylights render "$@" --shard env --resume
