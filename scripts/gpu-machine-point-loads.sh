#!/usr/bin/env bash
# What the 64-byte light costs point lights in the clustered lighting loop, on the GPU
# machine, one call: `bench` on Sponza 1920x1080, deferred compact/compute, 5,000 and
# 100,000 lights, radius 1 and 2 m (thresholds 0.2, 0.05), all point lights against half
# spots; compare the lighting pass with the same rows of
# docs/results/nvidia-h200/far-field/lab-100k. (Written for an experiment in which
# point-only frames read 32 bytes a light, reverted: see ARCHITECTURE.)
# Usage: scripts/gpu-machine-point-loads.sh BIN OUT_DIR  (BIN: a release `manylights`; on the
# GPU machine with the Vulkan loader on LD_LIBRARY_PATH and WGPU_BACKEND=vulkan)
set -u
bin=$1
out=$2
mkdir -p "$out"
cat > "$out/point-loads.toml" <<TOML
pipelines = ["deferred"]
lights = [5000, 100000]
sizes = ["1920x1080"]
thresholds = [0.2, 0.05]
spot_fractions = [0.0, 0.5]
naive_light_limit = 0
reference_light_limit = 0
TOML
timeout -s INT 400 "$bin" bench --config "$out/point-loads.toml" --out "$out/lab" 2>&1 | tail -3
