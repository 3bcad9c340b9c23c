#!/usr/bin/env bash
# Issue 58: a million shadowed lights against the GPU reference with visibility
# (`visibility::GpuVisibleReference`, 256 rays a pixel estimated beyond 256 lights), from
# the reference camera and two cameras no test uses (the side gallery's vault, a column of
# the upper gallery): `manylights bench` on Sponza 1920x1080, deferred compact/tiles,
# intensity 0.002, tree:0.1, with one ray a pixel unfiltered (`rays:1`) and filtered
# (`rays:1+spatial+temporal`). Every frame's FLIP, error map and seam measure are against
# the reference with visibility (`reference_light_limit = 0`); the report gives its time
# and mean relative standard error. RAYS replaces the reference's 256 rays a pixel.
# Usage: scripts/gpu-machine-visible-reference.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
cat > "$out/visible.toml" <<TOML
pipelines = ["deferred"]
lights = [1000000]
sizes = ["1920x1080"]
lighting = ["tiles"]
intensity = 0.002
far_fields = ["tree:0.1"]
shadows = ["rays:1", "rays:1+spatial+temporal"]
views = ["reference", "-9,1.8,5.5,0,20,70,0", "5,7.5,-4.5,180,5,60,0"]
naive_light_limit = 0
reference_light_limit = 0
reference_image_rays = ${RAYS:-256}
frames = 10
warmup_seconds = 4
TOML
timeout -s INT 560 "$bin" bench --config "$out/visible.toml" --out "$out/lab" 2>&1 | tail -4
