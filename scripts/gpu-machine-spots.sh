#!/usr/bin/env bash
# Spot lights on the GPU machine (issue 17), the whole matrix in one call:
#  1. `bench --preset spots`: Sponza 1920x1080, 5,000 and 100,000 lights, every pipeline,
#     no spots against half of them spots (20/30 degree cones), spots culled by their cone
#     and by their range sphere (the false-positive ratio of each), errors against the f64
#     reference (and naive's image where naive runs: 5,000 lights);
#  2. per-pass times of single renders (deferred compact/compute, the default) at 5,000 and
#     100,000 lights, half spots, cone and sphere culling.
# Usage: scripts/gpu-machine-spots.sh BIN OUT_DIR   (BIN: a release `manylights` binary; on
# the GPU machine with the Vulkan loader on LD_LIBRARY_PATH and WGPU_BACKEND=vulkan)
set -u
bin=$1
out=$2
mkdir -p "$out"
timeout -s INT 420 "$bin" bench --preset spots --out "$out/lab" 2>&1 | tail -3
measure() {
  local name=$1
  shift
  echo "=== $name"
  timeout 30 "$bin" render --scene sponza --camera reference --time 1 --frames 20 --exposure 1 \
    --size 1920x1080 --stats --out "$out/$name.png" "$@" 2>&1 | grep -E "^gpu|^error|^wrote|false|entries"
}
for lights in 5000 100000; do
  measure "render_${lights}_points" --lights "$lights"
  for culling in cone sphere; do
    measure "render_${lights}_half_spots_${culling}" --lights "$lights" --spot-fraction 0.5 --spot-culling "$culling"
  done
done
