#!/usr/bin/env bash
# Issue 63 on the GPU machine: area lights' frame times (frames.txt: Sponza 1920x1080,
# deferred (the default) and Forward+, points against 0.3 m squares and spheres, 10,000 and
# 100,000 lights, three cameras, median of 10 frames after warm-up), sponza-glass and
# sponza-embers lit by their embers (12,000 and 10,000 triangle lights) with and without
# shadows (embers.txt). The lab's accuracy of the embers
# against the reference with visibility is a bench of its own:
# `manylights bench --config docs/results/nvidia-h200/area-lights/embers.toml`.
# Usage: scripts/gpu-machine-area-lights.sh BIN OUT_DIR [PIPELINES] (on the GPU machine;
# PIPELINES defaults to "deferred forward-plus"; with ONLY_FRAMES=1 the embers are skipped).
set -u
bin=$1
out=$2
mkdir -p "$out"
common=(render --size 1920x1080 --frames 10 --time 1)
"$bin" "${common[@]}" --scene sponza --frames 30 --lights 10000 --out $out/warm.png > /dev/null 2>&1
for camera in reference gallery floor; do
  for pipeline in ${3:-deferred forward-plus}; do
    for lights in 10000 100000; do
      for shape in point rect:0.3 sphere:0.3; do
        echo "=== $camera $pipeline $lights ${shape%:*}"
        "$bin" "${common[@]}" --scene sponza --camera $camera --pipeline $pipeline --lights $lights \
          --light-shape $shape --out $out/${camera}_${pipeline}_${lights}_${shape%:*}.png 2>&1 \
          | grep -E "^gpu (lighting|total|shading|light assignment|g-buffer)|^error"
      done
    done
  done
done > $out/frames.txt
[ "${ONLY_FRAMES:-0}" = 1 ] && exit 0
for scene in sponza-glass sponza-embers; do
  for camera in reference gallery floor; do
    for emissive in on off; do
      for shadows in off "rays:1+spatial+temporal"; do
        echo "=== $scene $camera emissive-lights $emissive shadows $shadows"
        "$bin" "${common[@]}" --scene $scene --camera $camera --lights 1 --emissive-lights $emissive \
          --shadows $shadows --out "$out/embers_${scene}_${camera}_${emissive}_${shadows//[:+]/_}.png" 2>&1 \
          | grep -E "^gpu (total|lighting|shadow)|^emissive|^error"
      done
    done
  done
done > $out/embers.txt
cd $out && mkdir -p png && mv *.png png/ && tar czf png.tgz png && rm -rf png
