#!/usr/bin/env bash
# The visibility buffer against the G-buffer pass (issue 29): deferred with tiles lighting,
# G-buffer compact, packed (what the visibility buffer's resolve writes) and visibility, at
# 1,000, 5,000 and 100,000 lights (radius 2 m) and 1,000,000 (radius 0.25 m, tree:1:192);
# Sponza 1920x1080, reference camera, median of 10 frames after warm-up, two rounds.
# Usage: scripts/gpu-machine-visibility.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
workloads=(
  "1k --lights 1000"
  "5k --lights 5000"
  "100k --lights 100000"
  "1m_r025_tree1_192 --lights 1000000 --radius 0.25 --far-field tree:1:192"
)
for round in 1 2; do
  echo "### round $round"
  for workload in "${workloads[@]}"; do
    read -r name args <<<"$workload"
    for gbuffer in compact packed visibility; do
      # shellcheck disable=SC2086
      run "${name}_${gbuffer}" --pipeline deferred --gbuffer "$gbuffer" --lighting tiles $args
    done
  done
done
