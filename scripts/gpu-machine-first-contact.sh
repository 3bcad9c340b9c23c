#!/usr/bin/env bash
# First-contact measurements on the GPU machine: GPU times with and without --stats at
# 100,000 and 1,000,000 lights (Sponza, 1920x1080, reference camera, default pipeline:
# deferred compact + compute lighting), the wall-clock cost of --stats, the README frames,
# and the default viewer's frame rate under Xvfb.
# Usage: scripts/gpu-machine-first-contact.sh BIN OUT_DIR
# (BIN: a release `manylights` binary; on the GPU machine with the Vulkan loader on
# LD_LIBRARY_PATH, WGPU_BACKEND=vulkan; for the viewer, Xvfb on DISPLAY.)
set -u
bin=$1
out=$2
now() { date +%s.%N; }
render_timed() {
  local name=$1
  shift
  echo "=== $name: $*"
  local start
  start=$(now)
  "$bin" render --scene sponza --camera reference --size 1920x1080 --time 1 \
    --out "$out/$name.png" "$@" 2>&1 | grep -E "^gpu|^warm|^clusters|^exposure|^error"
  awk -v a="$start" -v b="$(now)" 'BEGIN { printf "wall clock: %.2f s\n", b - a }'
}
for lights in 100000 1000000; do
  render_timed "nostats_$lights" --lights "$lights" --frames 10
  render_timed "stats_$lights" --lights "$lights" --frames 10 --stats
  # Once more without, to see the run-to-run spread.
  render_timed "nostats_again_$lights" --lights "$lights" --frames 10
done
# The viewer's defaults (1280x720, 1,000 lights, deferred, automatic exposure, statistics
# on), headless: the frame loop's rate bounds what the window shows.
echo "=== viewer defaults, headless"
"$bin" render --size 1280x720 --frames 300 --stats --out "$out/viewer_defaults.png" 2>&1 |
  grep -E "^gpu total|^frame loop|^warm|^error"
