#!/usr/bin/env bash
# The frame-time budget (issue 29): `render --budget 8 --walk 60` on Sponza 1920x1080,
# deferred compact/tiles, the camera moving through the scene's presets (60 frames from one
# to the next, interpolated) with the lights animated, at 1,000, 10,000, 100,000 and
# 1,000,000 lights asking for a 2 m radius, without a far field and with the tree at
# tolerance 1 and 512 slots (the budget takes the radius, then the slots); 600 timed frames
# each after the warm-up. Prints how many frames stayed within the budget, the 95th
# percentile and the radii (and slots) chosen.
# Usage: scripts/gpu-machine-budget.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
for far in off tree:1:512; do
  for lights in 1000 10000 100000 1000000; do
    echo "=== $lights lights, far field $far"
    "$bin" render --scene sponza --size 1920x1080 --lights "$lights" --radius 2 --budget 8 \
      --far-field "$far" --walk 60 --frames 600 --out "$out/budget_${lights}_$far.png" 2>&1 |
      grep -E "^budget|^warm-up|^error"
  done
done
