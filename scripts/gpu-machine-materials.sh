#!/usr/bin/env bash
# Issue 44: the price of glTF's metallic-roughness BRDF against Blinn-Phong. `manylights
# bench` on Sponza 1920x1080, reference camera, at 5,000 and 100,000 lights (default radius,
# 2 m): Forward+, and deferred with the tiles lighting on every G-buffer layout, each with
# both BRDFs; no reference image (the lab's light evaluations and their rate over the
# lighting pass, the passes' times, the G-buffer's bytes in REPORT.md). Then the README's
# headline matrix, which renders Sponza with its file's model, PBR, and the README's images
# (part 1); the headline matrix with Blinn-Phong (part 2).
# Usage: scripts/gpu-machine-materials.sh BIN OUT_DIR 1|2 (on the GPU machine).
set -u
bin=$1
out=$2
part=$3
here=$(dirname "$0")
mkdir -p "$out"
if [ "$part" = 2 ]; then
  EXTRA_ARGS="--shading blinn-phong" bash "$here/gpu-machine-headline.sh" "$bin" "$out/headline-blinn-phong" > "$out/headline-blinn-phong.txt" 2>&1
  exit 0
fi
cat > "$out/materials.toml" <<TOML
pipelines = ["forward-plus", "deferred"]
lights = [5000, 100000]
sizes = ["1920x1080"]
gbuffers = ["full", "compact", "packed", "visibility"]
lighting = ["tiles"]
shadings = ["pbr", "blinn-phong"]
naive_light_limit = 0
reference_light_limit = 0
camera = "reference"
TOML
echo "### materials"
timeout -s INT 420 "$bin" bench --config "$out/materials.toml" --out "$out/materials" 2>&1 | tail -2
bash "$here/gpu-machine-headline.sh" "$bin" "$out/headline" > "$out/headline.txt" 2>&1
bash "$here/gpu-machine-readme-images.sh" "$bin" "$out"
"$bin" render --scene lamps --lights 0 --size 1280x720 --out "$out/lamps.png" > "$out/lamps.txt" 2>&1
"$bin" render --scene spheres --lights 0 --size 1280x720 --out "$out/spheres.png" > "$out/spheres.txt" 2>&1
