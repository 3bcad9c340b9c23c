#!/usr/bin/env bash
# Where Forward+ wins (issue 45) on the GPU machine: the lab's `trade-offs` preset (every
# pipeline inside and outside the castle, Sponza without and with the blended banners
# and embers of `sponza-glass`, sorted and weighted, MSAA 1x, 4x and 8x for Forward+ and
# naive, 1920x1080, median of 10 frames after warm-up), one light count a run (the two
# together pass the 10 minutes a command may take), then the frames the README shows.
# Usage: scripts/gpu-machine-trade-offs.sh BIN OUT_DIR LIGHTS NAME [bench flags...] (on the
# GPU machine): the preset at LIGHTS (comma-separated), with the flags given (e.g.
# `--pipelines naive`), written to OUT_DIR/NAME; NAME `images`: the README's frames of
# sponza-glass (Forward+, LIGHTS lights, without and with 8x MSAA) instead.
set -u
bin=$1
out=$2
lights=$3
name=$4
shift 4
mkdir -p "$out"
if [ "$name" = images ]; then
  for view in reference outside; do
    for msaa in 1 8; do
      "$bin" render --scene sponza-glass --camera "$view" --pipeline forward-plus \
        --lights "$lights" --size 1920x1080 --frames 10 --time 1 --msaa "$msaa" --emissive-lights off \
        --out "$out/sponza-glass-$view-msaa$msaa.png" 2>&1 | grep -E "^gpu total|^error"
    done
  done
  exit 0
fi
"$bin" bench --preset trade-offs --lights "$lights" --out "$out/$name" "$@" 2>&1 | tail -3
