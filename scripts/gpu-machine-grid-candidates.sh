#!/usr/bin/env bash
# Combined cluster-grid candidates at 5000 lights on Sponza, 1920x1080, three cameras: how
# the defaults were chosen. Usage as scripts/gpu-machine-forward-plus.sh.
set -u
bin=$1; out=$2
source "$(dirname "$0")/gpu-machine-render.sh"
# The camera varies here: each run names its own.
common=(render --scene sponza --size 1920x1080 --frames 10 --time 1)
for tiles in 16x9 32x18; do for slices in 32 48; do for scheme in linear log-near; do
  run "combo_${tiles}_${slices}_${scheme}" --camera reference --pipeline forward-plus --lights 5000 --tiles "$tiles" --slices "$slices" --z-scheme "$scheme"
done; done; done
for cam in gallery floor; do for scheme in linear log-near; do
  run "cam_${cam}_${scheme}_24" --camera $cam --pipeline forward-plus --lights 5000 --z-scheme $scheme
  run "cam_${cam}_${scheme}_48" --camera $cam --pipeline forward-plus --lights 5000 --slices 48 --z-scheme $scheme
done; done
