#!/usr/bin/env bash
# The deferred lighting paths side by side (issue 29): the per-pixel compute loop against
# the tile-shared loop (`--lighting tiles`, shaders/cluster/tile_lights.wgsl) at 5,000 and
# 100,000 lights (radius 2 m) and 1,000,000 (radius 0.25 m, with and without tree:1), and
# the same with half the lights spots (the program with the cone's code); deferred compact,
# Sponza 1920x1080, reference camera, median of 10 frames after warm-up, two rounds.
# BASE_BIN (optional): a build of an earlier commit, run on the compute path for comparison.
# Usage: scripts/gpu-machine-tiles.sh BIN OUT_DIR [BASE_BIN] (on the GPU machine).
set -u
out=$2
base=${3:-}
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
workloads=(
  "5k --lights 5000"
  "100k --lights 100000"
  "1m_r025 --lights 1000000 --radius 0.25"
  "1m_r025_tree1 --lights 1000000 --radius 0.25 --far-field tree:1"
  "5k_spots --lights 5000 --spot-fraction 0.5"
  "100k_spots --lights 100000 --spot-fraction 0.5"
)
for round in 1 2; do
  echo "### round $round"
  for workload in "${workloads[@]}"; do
    read -r name args <<<"$workload"
    bin=$1
    for lighting in compute tiles; do
      # shellcheck disable=SC2086
      run "${name}_${lighting}" --pipeline deferred --gbuffer compact --lighting "$lighting" $args
    done
    if [ -n "$base" ]; then
      bin=$base
      # shellcheck disable=SC2086
      run "${name}_base_compute" --pipeline deferred --gbuffer compact --lighting compute $args
    fi
  done
done
