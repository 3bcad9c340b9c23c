#!/usr/bin/env bash
# The far field on the GPU machine (issue 16), the whole matrix in one call:
#  1. (part 5k) `bench --preset far-field`: Sponza 1920x1080, 5,000 lights, deferred compact/compute,
#     radius 1 to 14.1 m, far field off / tree / stochastic at three tolerances each, every
#     error against the unbounded reference (naive inverse-square image, f64 samples);
#  2. (part 100k) looser tree tolerances at 5,000 lights; 100,000 lights at 1920x1080 (error against the f64 samples only: naive is too slow);
#  3. 100,000 lights at 480x270 with the naive inverse-square reference image on the GPU;
#  4. per-pass times of single renders at 5,000, 100,000 and 1,000,000 lights.
# Usage: scripts/gpu-machine-far-field.sh BIN OUT_DIR [5k|100k]  (one part per call: each
# fits the GPU machine's 10 minutes; SIGINT before that keeps what was measured)
# (BIN: a release `manylights` binary; on the GPU machine with the Vulkan loader on
# LD_LIBRARY_PATH and WGPU_BACKEND=vulkan.)
set -u
bin=$1
out=$2
part=${3:-5k}
mkdir -p "$out"
if [ "$part" = 5k ]; then
  timeout -s INT 560 "$bin" bench --preset far-field --out "$out/lab" 2>&1 | tail -3
  exit 0
fi
cat > "$out/lab-100k.toml" <<TOML
pipelines = ["deferred"]
lights = [100000]
sizes = ["1920x1080"]
thresholds = [0.2, 0.05]
far_fields = ["off", "tree:3", "tree:0.3", "stochastic:16", "stochastic:4"]
naive_light_limit = 0
TOML
# Looser tree tolerances at 5,000 lights (the preset's tightest are far more accurate than
# the targets ask).
timeout -s INT 120 "$bin" bench --preset far-field --thresholds 0.2,0.05 \
  --far-fields tree:1,tree:3,tree:10 --out "$out/lab-tree-loose" 2>&1 | tail -1
timeout -s INT 170 "$bin" bench --config "$out/lab-100k.toml" --out "$out/lab-100k" 2>&1 | tail -3
sed -e 's/1920x1080/480x270/' "$out/lab-100k.toml" > "$out/lab-100k-small.toml"
echo "reference_light_limit = 100000" >> "$out/lab-100k-small.toml"
timeout -s INT 120 "$bin" bench --config "$out/lab-100k-small.toml" --out "$out/lab-100k-small" 2>&1 | tail -3
measure() {
  local name=$1
  shift
  echo "=== $name"
  timeout 20 "$bin" render --scene sponza --camera reference --time 1 --frames 20 --exposure 1 \
    --out "$out/$name.png" "$@" 2>&1 | grep -E "^gpu|^error|^wrote"
}
for lights in 5000 100000 1000000; do
  for far in off tree:1 stochastic:1; do
    measure "render_${lights}_${far}" --size 1920x1080 --lights "$lights" --far-field "$far"
  done
done
