#!/usr/bin/env bash
# Issue 58: a million lights against the GPU full-frame reference, from the reference camera
# and two cameras no test uses (the side gallery's vault, a column of the upper gallery):
# `manylights bench` on Sponza 1920x1080, deferred compact/tiles, intensity 0.002 (radius
# 0.2 m), without a far field and with the tree at tolerance 0.1 (64 slots) and 1 (192
# slots). Every frame's FLIP, error map and seam measure are against the GPU reference
# (`reference_light_limit = 0`). FAR_FIELDS (a TOML list) replaces the far fields, e.g.
# '["off", "tree:0.1", "tree:0.1:48", "tree:1:192"]'; INTENSITY replaces 0.002 (0.003125:
# radius 0.25 m). With REFINED=1 it runs the per-pixel refinement tried in docs/results.md:
# refine-at-pixel.patch applies to the shaders of commit 1965dde, not to later ones.
# Usage: scripts/gpu-machine-seams.sh BIN OUT_DIR (on the GPU machine, from the repository).
set -u
bin=$1
out=$2
mkdir -p "$out"
far_fields='["off", "tree:0.1", "tree:1:192"]'
if [ "${REFINED:-0}" = 1 ]; then
  rm -rf "$out/shaders" && cp -r shaders "$out/shaders"
  (cd "$out/shaders" && patch -p1 -s) < docs/results/nvidia-h200/issue-58/refine-at-pixel.patch
  export MANYLIGHTS_SHADER_DIR="$out/shaders"
  far_fields='["tree:0.1", "tree:1:192"]'
fi
far_fields=${FAR_FIELDS:-$far_fields}
cat > "$out/seams.toml" <<TOML
pipelines = ["deferred"]
lights = [1000000]
sizes = ["1920x1080"]
lighting = ["tiles"]
intensity = ${INTENSITY:-0.002}
far_fields = $far_fields
views = ["reference", "-9,1.8,5.5,0,20,70,0", "5,7.5,-4.5,180,5,60,0"]
naive_light_limit = 0
reference_light_limit = 0
frames = 10
warmup_seconds = 4
TOML
timeout -s INT 300 "$bin" bench --config "$out/seams.toml" --out "$out/lab" 2>&1 | tail -2
