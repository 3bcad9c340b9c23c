#!/usr/bin/env bash
# The README's two H200 images (Sponza, reference camera, 1280x720, the defaults: 5,000
# lights, and 1,000,000 at intensity 0.002), each rendered twice; the frames' GPU times in
# OUT_DIR/readme-images.txt, the images as OUT_DIR/readme-LIGHTS.png.
# Usage: scripts/gpu-machine-readme-images.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
for round in 1 2; do
  for lights in 5000 1000000; do
    echo "### round $round $lights"
    extra=()
    [ "$lights" = 1000000 ] && extra=(--intensity 0.002)
    "$bin" render --camera reference --size 1280x720 --lights "$lights" "${extra[@]}" \
      --out "$out/readme-$lights.png" 2>&1
  done
done > "$out/readme-images.txt"
