#!/usr/bin/env bash
# Light assignment on the GPU machine (issue 15): GPU time per pass (timestamp queries,
# median of 20 frames after warm-up) for each design and box choice, light count and
# clustered pipeline; Sponza, reference camera, radius 2 m, 1920x1080 (and 3840x2160 for
# deferred). `--stats` adds the list statistics (entries, false positives) as a pass of its
# own, which the totals in docs/results/nvidia-h200/assignment leave out.
# Usage: scripts/gpu-machine-assignment.sh BIN OUT_DIR
# (BIN: a release `manylights` binary; on the GPU machine with the Vulkan loader on
# LD_LIBRARY_PATH and WGPU_BACKEND=vulkan.)
set -u
bin=$1
out=$2
mkdir -p "$out"
measure() {
  local name=$1
  shift
  echo "=== $name"
  "$bin" render --scene sponza --camera reference --time 1 --radius 2 --frames 20 --stats \
    --out "$out/$name.png" "$@" 2>&1 | grep -E "^gpu|^clusters: [0-9]|^error"
}
for lights in 5000 100000 1000000; do
  for boxes in visible grid; do
    measure "deferred_${lights}_tile-masks_${boxes}" --size 1920x1080 --pipeline deferred \
      --lights "$lights" --assignment tile-masks --cluster-boxes "$boxes"
  done
  measure "deferred_${lights}_atomic-fill_visible" --size 1920x1080 --pipeline deferred \
    --lights "$lights" --assignment atomic-fill --cluster-boxes visible
done
# Forward+ shades 1,000,000 lights of 2 m in about 5.7 s a frame (fragment shading).
for lights in 5000 100000; do
  for boxes in visible grid; do
    measure "forward-plus_${lights}_tile-masks_${boxes}" --size 1920x1080 \
      --pipeline forward-plus --lights "$lights" --assignment tile-masks --cluster-boxes "$boxes"
  done
done
for lights in 5000 100000; do
  for boxes in visible grid; do
    measure "deferred_4k_${lights}_tile-masks_${boxes}" --size 3840x2160 --pipeline deferred \
      --lights "$lights" --assignment tile-masks --cluster-boxes "$boxes"
  done
done
