#!/usr/bin/env bash
# The tree's slots dial at 1,000,000 lights (issue 29): `manylights bench` on Sponza
# 1920x1080, reference camera, deferred compact/tiles, radius 0.25 m and 0.5 m (thresholds
# 3.2 and 0.8 at intensity 0.2), the tree at tolerance 1 with 64 (the default), 128, 192
# and 256 slots and at tolerance 0.1 with 192, every error against 256 f64 samples of the
# unbounded inverse-square reference.
# Usage: scripts/gpu-machine-far-slots.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
cat > "$out/far-slots.toml" <<TOML
pipelines = ["deferred"]
lights = [1000000]
sizes = ["1920x1080"]
lighting = ["tiles"]
thresholds = [3.2, 0.8]
far_fields = ["off", "tree:1", "tree:1:128", "tree:1:192", "tree:1:256", "tree:0.1:192"]
naive_light_limit = 0
reference_light_limit = 0
camera = "reference"
TOML
timeout -s INT 500 "$bin" bench --config "$out/far-slots.toml" --out "$out/lab" 2>&1 | tail -2
