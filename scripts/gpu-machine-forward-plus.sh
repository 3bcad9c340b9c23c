#!/usr/bin/env bash
# Naive vs Forward+ and the cluster-grid matrix on Sponza at 1920x1080, reference camera.
# Usage: scripts/gpu-machine-forward-plus.sh BIN OUT_DIR
# (BIN: a release `manylights` binary; on the GPU machine with the Vulkan loader on
# LD_LIBRARY_PATH, WGPU_BACKEND=vulkan and MANYLIGHTS_ASSETS pointing at assets/.)
set -u
bin=$1
out=$2
source "$(dirname "$0")/gpu-machine-render.sh"
for lights in 1000 5000; do
  run "naive_$lights" --pipeline naive --lights "$lights"
  run "fplus_$lights" --pipeline forward-plus --lights "$lights"
  run "fplus_noprepass_$lights" --pipeline forward-plus --lights "$lights" --no-depth-prepass
done
# Grid matrix at 5000 lights (the defaults when this ran: 16x9 tiles, 24 slices, log-near 1 m,
# fitted range; one setting varied at a time).
for tiles in 8x5 16x9 32x18 64x36; do run "tiles_$tiles" --pipeline forward-plus --lights 5000 --tiles "$tiles"; done
for slices in 8 16 24 32 48 64; do run "slices_$slices" --pipeline forward-plus --lights 5000 --slices "$slices"; done
for scheme in log log-near linear; do run "scheme_$scheme" --pipeline forward-plus --lights 5000 --z-scheme "$scheme"; done
for range in camera fitted; do run "range_$range" --pipeline forward-plus --lights 5000 --z-range "$range"; done
for lights in 20000 100000; do run "fplus_$lights" --pipeline forward-plus --lights "$lights"; done
