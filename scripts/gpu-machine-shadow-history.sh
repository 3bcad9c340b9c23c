#!/usr/bin/env bash
# Shadows with a ray budget and history (issue 47) on the GPU machine: GPU times of the
# temporal accumulation beside the frame without shadows and with the spatial filter alone.
# Sponza 1920x1080, reference camera, t = 1, median of 10 frames after warm-up (the
# history fills during warm-up); deferred compact/tiles at 1,000, 5,000 and 100,000 lights
# (default radius) and at 1,000,000 with the tree far field (tolerance 0.1, intensity 0.002).
# Usage: scripts/gpu-machine-shadow-history.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
modes=(off rays:1+spatial rays:1+spatial+temporal rays:2+spatial+temporal)
for lights in 1000 5000 100000; do
  for shadows in "${modes[@]}"; do
    name=${shadows//[:+]/_}
    run "deferred_${lights}_$name" --pipeline deferred --gbuffer compact --lighting tiles --lights "$lights" --shadows "$shadows"
  done
done
for shadows in "${modes[@]}"; do
  name=${shadows//[:+]/_}
  run "deferred_1m_tree_$name" --pipeline deferred --gbuffer compact --lighting tiles --lights 1000000 \
    --far-field tree:0.1 --intensity 0.002 --shadows "$shadows"
done
