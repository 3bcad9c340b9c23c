#!/usr/bin/env bash
# Issue 46 (exact shadows from rebuilt positions) on the GPU machine, before and after in
# one run: the binary's embedded shaders are main's (before), MANYLIGHTS_SHADER_DIR points
# the same binary at this tree's shaders (after).
# 1. The wall frame (floor, wall, one light, seen from 8 m above) in every pipeline and
#    G-buffer layout, 128x128.
# 2. Sponza's gallery corridor at a million lights with the tree far field, 1920x1080:
#    compact (the default) before and after, full for comparison.
# 3. The README's shadow table (scripts/gpu-machine-shadows.sh) after, and the default
#    deferred (compact/tiles) at 5,000 lights without and with shadows, before and after.
# Usage: scripts/gpu-machine-issue-46.sh BIN OUT_DIR SHADER_DIR (on the GPU machine).
set -u
bin=$1
out=$2
shaders=$3
mkdir -p "$out/wall" "$out/corridor" "$out/table"
wall=(render --scene wall --lights 0 --size 128x128 --exposure 1 --shadows exact)
for when in before after; do
  dir=""
  [ "$when" = after ] && dir=$shaders
  MANYLIGHTS_SHADER_DIR=$dir "$bin" "${wall[@]}" --pipeline naive --out "$out/wall/$when-naive.png" 2>&1 | grep -E "^error"
  MANYLIGHTS_SHADER_DIR=$dir "$bin" "${wall[@]}" --pipeline forward-plus --out "$out/wall/$when-forward-plus.png" 2>&1 | grep -E "^error"
  for layout in full compact packed visibility; do
    for lighting in fragment compute tiles; do
      MANYLIGHTS_SHADER_DIR=$dir "$bin" "${wall[@]}" --pipeline deferred --gbuffer "$layout" --lighting "$lighting" \
        --out "$out/wall/$when-$layout-$lighting.png" 2>&1 | grep -E "^error"
    done
  done
done
corridor=(render --scene sponza --camera 10,6.5,-3.5,107,-13,65 --time 4.1 --lights 1000000 --threshold 3.2
  --far-field tree:1:192 --shadows exact --size 1920x1080 --frames 10)
for case in before-compact after-compact after-full; do
  dir=""
  [ "${case%%-*}" = after ] && dir=$shaders
  echo "=== corridor $case"
  MANYLIGHTS_SHADER_DIR=$dir "$bin" "${corridor[@]}" --gbuffer "${case#*-}" --out "$out/corridor/$case.png" 2>&1 | grep -E "^gpu|^error"
done
source "$(dirname "$0")/gpu-machine-render.sh"
for when in before after; do
  dir=""
  [ "$when" = after ] && dir=$shaders
  for shadows in off exact; do
    MANYLIGHTS_SHADER_DIR=$dir out=$out/table run "default_5000_${shadows}_$when" --lights 5000 --shadows "$shadows"
  done
done
MANYLIGHTS_SHADER_DIR=$shaders bash "$(dirname "$0")/gpu-machine-shadows.sh" "$bin" "$out/table"
