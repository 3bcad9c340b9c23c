#!/usr/bin/env bash
# Issue 60: PBR's pace. The README's headline (PBR), the materials matrix on the compact
# layout (Forward+ and deferred tiles, both BRDFs, 5,000 and 100,000 lights; REPORT.md),
# and deferred tiles with both BRDFs from cameras the tests do not use (gallery, floor)
# and at a million lights (radius 0.25 m, tree:1:192).
# Usage: scripts/gpu-machine-pbr-pace.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
here=$(dirname "$0")
mkdir -p "$out"
bash "$here/gpu-machine-headline.sh" "$bin" "$out/headline" > "$out/headline.txt" 2>&1
cat > "$out/materials.toml" <<TOML
pipelines = ["forward-plus", "deferred"]
lights = [5000, 100000]
sizes = ["1920x1080"]
gbuffers = ["compact"]
lighting = ["tiles"]
shadings = ["pbr", "blinn-phong"]
naive_light_limit = 0
reference_light_limit = 0
camera = "reference"
TOML
timeout -s INT 300 "$bin" bench --config "$out/materials.toml" --out "$out/materials" 2>&1 | tail -2
frame=(render --scene sponza --size 1920x1080 --frames 10 --time 1 --pipeline deferred --gbuffer compact --lighting tiles --out "$out/frame.png")
{
  for camera in gallery floor; do
    for lights in 5000 100000; do
      for shading in blinn-phong pbr; do
        echo "=== $camera $lights $shading"
        "$bin" "${frame[@]}" --camera "$camera" --lights "$lights" --shading "$shading" 2>&1 | grep -E "^gpu (lighting|total)"
      done
    done
  done
  for shading in blinn-phong pbr; do
    for camera in reference gallery; do
      echo "=== 1m $camera $shading"
      "$bin" "${frame[@]}" --camera "$camera" --lights 1000000 --radius 0.25 --far-field tree:1:192 --shading "$shading" 2>&1 | grep -E "^gpu (lighting|total)"
    done
  done
} > "$out/cameras.txt"
