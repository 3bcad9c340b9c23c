#!/usr/bin/env bash
# Shadows with a ray budget (issue 47) on the GPU machine, part 1: GPU times. Sponza
# 1920x1080, reference camera, t = 1, median of 10 frames after warm-up; each workload with
# shadows off, exact and 1, 2 and 4 rays a pixel: deferred compact/tiles (the default) and
# Forward+ at 1,000, 5,000 and 100,000 lights (default radius), deferred with the tree far
# field (tolerance 0.1, intensity 0.002) at 1,000,000; deferred also with 1 and 2 rays and
# the spatial filter (rays:K+spatial; Forward+ refuses it). Exact shadows are left out
# where a frame would take seconds (Forward+ at 100,000 lights).
# Usage: scripts/gpu-machine-shadow-rays.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
source "$(dirname "$0")/gpu-machine-render.sh"
for lights in 1000 5000 100000; do
  for shadows in off exact rays:1 rays:2 rays:4; do
    name=${shadows/:/}
    run "deferred_${lights}_$name" --pipeline deferred --gbuffer compact --lighting tiles --lights "$lights" --shadows "$shadows"
    [ "$lights" = 100000 ] && [ "$shadows" = exact ] && continue
    run "fplus_${lights}_$name" --pipeline forward-plus --lights "$lights" --shadows "$shadows"
  done
  for shadows in rays:1+spatial rays:2+spatial; do
    name=${shadows/:/}
    run "deferred_${lights}_${name/+/_}" --pipeline deferred --gbuffer compact --lighting tiles --lights "$lights" --shadows "$shadows"
  done
done
for shadows in off exact rays:1 rays:2 rays:4 rays:1+spatial rays:2+spatial; do
  name=${shadows/:/}
  name=${name/+/_}
  run "deferred_1m_tree_$name" --pipeline deferred --gbuffer compact --lighting tiles --lights 1000000 \
    --far-field tree:0.1 --intensity 0.002 --shadows "$shadows"
done
