#!/usr/bin/env bash
# Shadows at a million lights (issue 47) on the GPU machine: every shadow mode at 1,000,000
# lights with the tree far field (tolerance 0.1, intensity 0.002), deferred compact/tiles,
# Sponza 1920x1080, reference camera, t = 1, median of 10 frames after warm-up. The
# million-light rows of scripts/gpu-machine-shadow-rays.sh, measured again since a ray
# that keeps a far-field aggregate aims at one of its lights, with the history beside them.
# Usage: scripts/gpu-machine-shadow-rays-1m.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
for shadows in off exact rays:1 rays:2 rays:4 rays:1+spatial rays:2+spatial rays:1+spatial+temporal; do
  name=${shadows//[:+]/_}
  run "deferred_1m_tree_$name" --pipeline deferred --gbuffer compact --lighting tiles --lights 1000000 \
    --far-field tree:0.1 --intensity 0.002 --shadows "$shadows"
done
