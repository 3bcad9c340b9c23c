#!/usr/bin/env bash
# Every published number issue 29's light-loop work moves, re-measured in two calls (each
# under the GPU machine's 10-minute limit). Part 1: the README's headline matrix, the light
# loop's evaluation rate, the README's two images' frames, the visibility buffer, the
# cluster grid under tiles lighting. Part 2: the tiles table, the far field's slots, the
# budget walk, the 5,000-light far-field preset and the spot table (deferred compact,
# compute and tiles, points against half spots culled by cone or sphere).
# Usage: scripts/gpu-machine-issue-29.sh BIN OUT_DIR 1|2 (on the GPU machine).
set -u
bin=$1
out=$2
part=$3
here=$(dirname "$0")
mkdir -p "$out"
if [ "$part" = 1 ]; then
  bash "$here/gpu-machine-headline.sh" "$bin" "$out/headline" > "$out/headline.txt" 2>&1
  bash "$here/gpu-machine-loop-rate.sh" "$bin" "$out/loop-rate" > "$out/loop-rate.txt" 2>&1
  bash "$here/gpu-machine-readme-images.sh" "$bin" "$out"
  bash "$here/gpu-machine-visibility.sh" "$bin" "$out/visibility" > "$out/visibility.txt" 2>&1
  bash "$here/gpu-machine-tile-grid.sh" "$bin" "$out/tile-grid" > "$out/tile-grid.txt" 2>&1
else
  bash "$here/gpu-machine-tiles.sh" "$bin" "$out/tiles" > "$out/tiles.txt" 2>&1
  bash "$here/gpu-machine-far-slots.sh" "$bin" "$out/far-slots" > "$out/far-slots.txt" 2>&1
  timeout 250 bash "$here/gpu-machine-budget.sh" "$bin" "$out/budget" > "$out/budget.txt" 2>&1
  timeout -s INT 200 "$bin" bench --preset far-field --out "$out/far-field-lab" > "$out/far-field.txt" 2>&1
  cat > "$out/spots.toml" <<TOML
pipelines = ["deferred"]
lights = [5000, 100000]
sizes = ["1920x1080"]
lighting = ["compute", "tiles"]
thresholds = [0.05]
spot_fractions = [0.0, 0.5]
spot_cullings = ["cone", "sphere"]
naive_light_limit = 0
reference_light_limit = 0
camera = "reference"
TOML
  timeout -s INT 150 "$bin" bench --config "$out/spots.toml" --out "$out/spots-lab" > "$out/spots.txt" 2>&1
fi
