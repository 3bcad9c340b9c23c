#!/usr/bin/env bash
# The cluster grid under the tile-shared light loop (issue 29): deferred compact/tiles at
# 5,000 and 100,000 lights (radius 2 m), tiles 16x9 (the default), 32x18 and 8x5, slices
# 12, 24, 32, 48 (the default) and 64; Sponza 1920x1080, reference camera, median of 10
# frames after warm-up. Prints the lighting pass, the assignment and the frame.
# Usage: scripts/gpu-machine-tile-grid.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
for lights in 5000 100000; do
  for tiles in 16x9 32x18 8x5; do
    for slices in 12 24 32 48 64; do
      run "grid_${lights}_${tiles}_${slices}" --lights "$lights" --tiles "$tiles" --slices "$slices"
    done
  done
done
