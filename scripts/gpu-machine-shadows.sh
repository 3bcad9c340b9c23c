#!/usr/bin/env bash
# Exact shadows (issue 28) on the GPU machine: Sponza 1920x1080, reference camera, t = 1,
# each workload without and with shadows; deferred compact/compute and Forward+ at 1,000
# and 5,000 lights (radius 2 m), and with the tree far field at 100,000 (radius 0.5 m)
# and 1,000,000 (radius 0.25 m) lights. The images are the README's side-by-side pair.
# Usage: scripts/gpu-machine-shadows.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
for shadows in off exact; do
  for lights in 1000 5000; do
    run "deferred_${lights}_$shadows" --pipeline deferred --gbuffer compact --lighting compute --lights "$lights" --shadows "$shadows"
    run "fplus_${lights}_$shadows" --pipeline forward-plus --lights "$lights" --shadows "$shadows"
  done
  run "deferred_100k_r05_tree1_$shadows" --pipeline deferred --gbuffer compact --lighting compute --lights 100000 --radius 0.5 --far-field tree:1 --shadows "$shadows"
  run "deferred_1m_r025_tree1_$shadows" --pipeline deferred --gbuffer compact --lighting compute --lights 1000000 --radius 0.25 --far-field tree:1 --shadows "$shadows"
done
