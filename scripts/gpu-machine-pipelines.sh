#!/usr/bin/env bash
# Every pipeline at its defaults on Sponza, 1920x1080, reference camera: Forward+ and
# deferred in every G-buffer layout on both lighting paths, 1,000 to 100,000 lights.
# Usage: scripts/gpu-machine-pipelines.sh BIN OUT_DIR (see scripts/gpu-machine-forward-plus.sh).
set -u
bin=$1
out=$2
source "$(dirname "$0")/gpu-machine-render.sh"
for lights in 1000 5000 20000 100000; do
  run "fplus_$lights" --pipeline forward-plus --lights "$lights"
  for gbuffer in full compact packed; do
    for lighting in fragment compute; do
      run "deferred_${gbuffer}_${lighting}_$lights" --pipeline deferred --gbuffer "$gbuffer" --lighting "$lighting" --lights "$lights"
    done
  done
done
