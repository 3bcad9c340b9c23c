#!/bin/sh
# The soak on the GPU machine (see docs/results/nvidia-h200/README.md): the same schedule
# as on lavapipe, 100,000 frames at 250 per phase and 3,600 frames at 1 per phase.
# Run from the repository root with the release binary and its libraries in devicebin/.
set -u
export LD_LIBRARY_PATH="$PWD/devicebin" WGPU_BACKEND=vulkan MANYLIGHTS_ASSETS="$PWD/assets"
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
out="${OUT:-soak-out}"
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$out/gpu.txt" 2>&1
./devicebin/manylights soak --frames 100000 --phase-frames 250 --report "$out/soak-100k.json" > "$out/soak-100k.txt" 2>&1
./devicebin/manylights soak --frames 3600 --phase-frames 1 --report "$out/soak-3600-p1.json" > "$out/soak-3600-p1.txt" 2>&1
tail -n 6 "$out"/soak-*.txt
