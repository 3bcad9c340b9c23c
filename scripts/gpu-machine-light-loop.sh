#!/usr/bin/env bash
# The README's headline matrix twice, then the far field at 1,000,000 lights (radius 0.25 m,
# deferred compact with the default tiles lighting, with and without tree:1): what the light
# loop's program variants (issue 27, cluster::LightLoop) and the tile-shared loop (issue 29)
# were measured with.
# Usage: scripts/gpu-machine-light-loop.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
for round in 1 2; do
  echo "### round $round"
  bash "$(dirname "$0")/gpu-machine-headline.sh" "$bin" "$out"
  run far_tree1_1m_r025 --pipeline deferred --gbuffer compact --lighting tiles --lights 1000000 --radius 0.25 --far-field tree:1
  run nofar_1m_r025 --pipeline deferred --gbuffer compact --lighting tiles --lights 1000000 --radius 0.25
done
