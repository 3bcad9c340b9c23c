#!/usr/bin/env bash
# Issue 62 on the GPU machine: the post passes' GPU times (passes.txt: Sponza 1920x1080, each
# pipeline, without and with TAA and bloom, median of 10 frames after warm-up), then the lab's
# temporal metrics (docs/results/nvidia-h200/post/motion.toml).
# Usage: scripts/gpu-machine-post.sh BIN OUT_DIR (on the GPU machine).
set -u
bin=$1
out=$2
mkdir -p "$out"
common=(render --scene sponza --size 1920x1080 --frames 10 --time 1)
"$bin" "${common[@]}" --frames 30 --lights 10000 --out $out/warm.png > /dev/null 2>&1
for camera in reference outside; do
  for pipeline in deferred forward-plus naive; do
    for post in "--aa off" "--aa taa" "--aa taa --bloom 0.05" "--bloom 0.05"; do
      lights=1000; [ $pipeline = naive ] && lights=200
      echo "=== $camera $pipeline $lights $post"
      "$bin" "${common[@]}" --camera $camera --pipeline $pipeline --lights $lights $post --out $out/${camera}_${pipeline}_${post// /}.png 2>&1 | grep -E "^gpu (temporal|bloom|total|tonemap)|^error"
    done
  done
done
s=$(date +%s)
"$bin" bench --config docs/results/nvidia-h200/post/motion.toml --out $out/motion 2>&1 | tail -2
echo "motion bench took $(( $(date +%s) - s )) s"
cd $out && tar czf motion.tgz motion && rm -rf motion && mkdir -p png && mv *.png png/ && tar czf png.tgz png && rm -rf png
