#!/usr/bin/env bash
# Light assignment designs side by side on the GPU machine (issue 15): GPU time per pass
# (timestamp queries, median of 20 frames after warm-up) for each design, light count and
# clustered pipeline; Sponza, 1920x1080, reference camera, radius 2 m.
# Usage: scripts/gpu-machine-assignment.sh BIN OUT_DIR
# (BIN: a release `manylights` binary; on the GPU machine with the Vulkan loader on
# LD_LIBRARY_PATH and WGPU_BACKEND=vulkan.)
set -u
bin=$1
out=$2
mkdir -p "$out"
for pipeline in deferred forward-plus; do
  counts="5000 100000 1000000"
  # Forward+ shades 1,000,000 lights of 2 m in about 5.7 s a frame (fragment shading).
  [ "$pipeline" = forward-plus ] && counts="5000 100000"
  for lights in $counts; do
    for design in tile-masks atomic-fill; do
      echo "=== $pipeline, $lights lights, $design"
      "$bin" render --scene sponza --camera reference --size 1920x1080 --time 1 \
        --pipeline "$pipeline" --lights "$lights" --radius 2 --assignment "$design" \
        --frames 20 --stats --out "$out/${pipeline}_${lights}_${design}.png" 2>&1 |
        grep -E "^gpu|^clusters: [0-9]|^error"
    done
  done
done
