#!/usr/bin/env bash
# What leaving shadows out costs (issue 28): the lab's error of deferred compact/compute
# with shadows off and exact against the reference with visibility (`--reference-shadows
# exact`), and the shadow rays a frame traces. Sponza 1920x1080, 1,000 and 5,000 lights,
# radius 2 m; then 100,000 lights with the tree far field (radius 0.5 m; no reference
# image above 20,000 lights, the f64 samples only).
# Usage: scripts/gpu-machine-shadows-error.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
"$bin" bench --scenes sponza --sizes 1920x1080 --lights 1000,5000 --pipelines deferred \
  --shadows off,exact --reference-shadows exact --out "$out/bench-radius-2" 2>&1 | tail -n 12
"$bin" bench --scenes sponza --sizes 1920x1080 --lights 100000 --pipelines deferred \
  --thresholds 0.8 --far-fields tree:1 --shadows off,exact --reference-shadows exact \
  --out "$out/bench-100k-tree" 2>&1 | tail -n 8
