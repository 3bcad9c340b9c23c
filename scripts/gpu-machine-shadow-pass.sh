#!/usr/bin/env bash
# The forward pipelines' shadow pass (issue 47) on the GPU machine: Forward+ and naive with
# one shadow ray a pixel traced in compute after their shading pass, beside deferred's rays
# traced in its compute lighting pass. Sponza 1920x1080, reference camera, t = 1, median
# of 10 frames after warm-up; Forward+ and deferred compact/tiles at 1,000, 5,000 and
# 100,000 lights (default radius) and at 1,000,000 with the tree far field (tolerance 0.1,
# intensity 0.002); naive at 1,000.
# Usage: scripts/gpu-machine-shadow-pass.sh BIN OUT_DIR [OLD_BIN] (on the GPU machine).
# OLD_BIN, a build from before the shadow pass (commit 9737966), measures Forward+ and naive
# tracing `rays:1` in their fragment shader (it is given this checkout's assets). With
# OLD_ONLY=1 only those runs are made.
set -u
bin=$1
out=$2
old=${3:-}
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
MANYLIGHTS_ASSETS="$(cd "$(dirname "$0")/.." && pwd)/assets"
export MANYLIGHTS_ASSETS
modes=(off rays:1 rays:1+spatial+temporal)
counts=("1000" "5000" "100000" "1000000 --far-field tree:0.1 --intensity 0.002")
for count in "${counts[@]}"; do
  # shellcheck disable=SC2206
  lights=($count)
  tag=${lights[0]}
  for shadows in "${modes[@]}"; do
    [ "${OLD_ONLY:-0}" = 1 ] && break
    name=${shadows//[:+]/_}
    run "forward_plus_${tag}_$name" --pipeline forward-plus --lights "${lights[@]}" --shadows "$shadows"
    run "deferred_${tag}_$name" --pipeline deferred --gbuffer compact --lighting tiles \
      --lights "${lights[@]}" --shadows "$shadows"
  done
  if [ -n "$old" ]; then
    bin=$old run "forward_plus_fragment_rays_${tag}_rays_1" --pipeline forward-plus \
      --lights "${lights[@]}" --shadows rays:1
  fi
done
for shadows in "${modes[@]}"; do
  [ "${OLD_ONLY:-0}" = 1 ] && break
  name=${shadows//[:+]/_}
  run "naive_1000_$name" --pipeline naive --lights 1000 --shadows "$shadows"
done
if [ -n "$old" ]; then
  bin=$old run "naive_fragment_rays_1000_rays_1" --pipeline naive --lights 1000 --shadows rays:1
fi
