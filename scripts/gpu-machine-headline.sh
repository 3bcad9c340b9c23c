#!/usr/bin/env bash
# The README's headline table: naive, Forward+ and deferred compact (fragment, compute and tiles
# lighting) at 1,000, 5,000 and 100,000 lights; Sponza, 1920x1080, reference camera, t = 1,
# default radius (2 m at the default intensity), median of 10 frames after warm-up.
# Usage: scripts/gpu-machine-headline.sh BIN OUT_DIR (on the GPU machine, see
# scripts/gpu-machine-forward-plus.sh).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
for lights in 1000 5000 100000; do
  # Naive shades every light at every pixel: 100,000 would take about 19 s a frame.
  [ "$lights" -le 5000 ] && run "naive_$lights" --pipeline naive --lights "$lights"
  run "fplus_$lights" --pipeline forward-plus --lights "$lights"
  for lighting in fragment compute tiles; do
    run "deferred_compact_${lighting}_$lights" --pipeline deferred --gbuffer compact --lighting "$lighting" --lights "$lights"
  done
done
