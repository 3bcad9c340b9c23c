#!/usr/bin/env bash
# How the radius trades against the tree's slots once a far field is on (issue 29, the
# budget's second dial): `manylights bench` on Sponza 1920x1080, reference camera, deferred
# compact/tiles, at 100,000 and 1,000,000 lights, radius 0.05, 0.1 and 0.25 m (thresholds
# 80, 20 and 3.2 at intensity 0.2), the tree at tolerance 1 with 64, 192 and 512 slots;
# every error against 256 f64 samples of the unbounded inverse-square reference.
# Usage: scripts/gpu-machine-far-radius.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
for lights in 100000 1000000; do
  cat > "$out/far-radius-$lights.toml" <<TOML
pipelines = ["deferred"]
lights = [$lights]
sizes = ["1920x1080"]
lighting = ["tiles"]
thresholds = [80, 20, 3.2]
far_fields = ["tree:1", "tree:1:192", "tree:1:512"]
naive_light_limit = 0
reference_light_limit = 0
camera = "reference"
TOML
  timeout -s INT 280 "$bin" bench --config "$out/far-radius-$lights.toml" --out "$out/lab-$lights" 2>&1 | tail -2
done
