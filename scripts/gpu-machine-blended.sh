#!/usr/bin/env bash
# Blended surfaces (issue 45, part 1) on the GPU machine: the glass room (tinted panes and
# 400 sparks, assets/glass/glass.gltf) at 1920x1080 from its front camera, t = 1, median of
# 10 frames after warm-up, with cluster statistics. Forward+ and deferred compact/tiles at
# 1,000 and 10,000 lights (default radius), the cluster boxes grown over the blended
# objects (the default, `visible`) and the grid's whole boxes (`grid`), which need no
# growing; naive at 1,000.
# Usage: scripts/gpu-machine-blended.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
common=(render --scene glass --size 1920x1080 --frames 10 --time 1 --stats)
run() {
  local name=$1
  shift
  echo "=== $name"
  "$bin" "${common[@]}" --out "$out/$name.png" "$@" 2>&1 | grep -E "^gpu|^clusters|^error"
}
for lights in 1000 10000; do
  for boxes in visible grid; do
    run "forward_plus_${lights}_$boxes" --pipeline forward-plus --lights "$lights" --cluster-boxes "$boxes"
    run "deferred_${lights}_$boxes" --pipeline deferred --gbuffer compact --lighting tiles \
      --lights "$lights" --cluster-boxes "$boxes"
  done
done
run "naive_1000" --pipeline naive --lights 1000
