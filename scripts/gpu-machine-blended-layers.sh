#!/usr/bin/env bash
# Issue 61: blended surfaces shaded in compute as per-pixel layers. sponza-glass at
# 1920x1080, median of 10 frames after warm-up (`render --frames 10`), from the reference
# camera (inside) and two the tests do not use (gallery, floor), at 1,000 and 10,000
# lights: deferred compact/tiles (the default: layers), the same with weighted
# transparency (the forward blended pass), deferred's fragment path (the forward sorted
# pass, as before issue 61) and Forward+.
# Usage: scripts/gpu-machine-blended-layers.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
# The embers' emission and lights came after (issue 63): off, as measured.
common=(render --scene sponza-glass --size 1920x1080 --frames 10 --time 1 --emissive-lights off)
run() {
  local name=$1
  shift
  echo "=== $name"
  "$bin" "${common[@]}" --out "$out/$name.png" "$@" 2>&1 | grep -E "^gpu|^blended|^error"
}
# Warm-up: the clock idles low until work arrives.
"$bin" "${common[@]}" --frames 30 --lights 10000 --out "$out/warm.png" > /dev/null 2>&1
for camera in reference gallery floor; do
  for lights in 1000 10000; do
    run "deferred_layers_${camera}_$lights" --camera "$camera" --lights "$lights" --pipeline deferred
    run "deferred_weighted_${camera}_$lights" --camera "$camera" --lights "$lights" --pipeline deferred --transparency weighted
    run "deferred_fragment_${camera}_$lights" --camera "$camera" --lights "$lights" --pipeline deferred --lighting fragment
    run "forward_plus_${camera}_$lights" --camera "$camera" --lights "$lights" --pipeline forward-plus
  done
done
