#!/usr/bin/env bash
# The light loop's rate (issue 29): `manylights bench` on Sponza 1920x1080, reference
# camera, deferred compact with compute and tiles lighting, at 5,000 and 100,000 lights
# (threshold 0.05 at intensity 0.2: radius 2 m) and 1,000,000 (threshold 3.2: radius 0.25
# m), no reference (the lab's light evaluations: visible pixels x their cluster's list
# length, and their rate over the lighting pass). Then the README's headline matrix.
# BASE_BIN (optional): a build of an earlier commit, measured the same way first, so both
# come from one machine and one warm-up.
# Usage: scripts/gpu-machine-loop-rate.sh BIN OUT_DIR [BASE_BIN] (on the GPU machine).
set -u
bin=$1
out=$2
base=${3:-}
mkdir -p "$out"
# config NAME LIGHTS THRESHOLD: a bench matrix of both lighting paths without a reference.
config() {
  cat > "$out/$1.toml" <<TOML
pipelines = ["deferred"]
lights = [$2]
sizes = ["1920x1080"]
lighting = ["compute", "tiles"]
thresholds = [$3]
naive_light_limit = 0
reference_light_limit = 0
camera = "reference"
TOML
}
config loop-rate "5000, 100000" 0.05
config loop-rate-1m 1000000 3.2
bench() {
  local which=$1 binary=$2
  for config in loop-rate loop-rate-1m; do
    echo "### $which $config"
    timeout -s INT 280 "$binary" bench --config "$out/$config.toml" --out "$out/$which-$config" 2>&1 | tail -2
  done
}
[ -n "$base" ] && bench base "$base"
bench new "$bin"
[ -n "$base" ] && bench base-again "$base"
echo "### headline"
bash "$(dirname "$0")/gpu-machine-headline.sh" "$bin" "$out/headline"
