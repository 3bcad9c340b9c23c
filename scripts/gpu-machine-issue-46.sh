#!/usr/bin/env bash
# Issue 46 (exact shadows from rebuilt positions) on the GPU machine, before and after in
# one run: BEFORE is a release binary of main before the fix (374703f), AFTER one of this
# tree.
# 1. The wall frame (floor, wall, one light, seen from 8 m above; `--scene wall`) in every
#    pipeline, G-buffer layout and lighting path, 128x128.
# 2. Sponza's gallery corridor at a million lights with the tree far field, 1920x1080:
#    compact (the default) before and after, full for comparison.
# 3. The default deferred (compact/tiles) at 5,000 lights without and with shadows, before
#    and after, and the README's shadow table (scripts/gpu-machine-shadows.sh) after.
# Usage: scripts/gpu-machine-issue-46.sh BEFORE AFTER OUT_DIR (on the GPU machine).
set -u
before=$1
after=$2
out=$3
mkdir -p "$out/wall" "$out/corridor" "$out/table"
wall=(render --scene wall --lights 0 --size 128x128 --exposure 1 --shadows exact)
for when in before after; do
  bin=$before
  [ "$when" = after ] && bin=$after
  "$bin" "${wall[@]}" --pipeline naive --out "$out/wall/$when-naive.png" 2>&1 | grep -E "^error"
  "$bin" "${wall[@]}" --pipeline forward-plus --out "$out/wall/$when-forward-plus.png" 2>&1 | grep -E "^error"
  for layout in full compact packed visibility; do
    for lighting in fragment compute tiles; do
      "$bin" "${wall[@]}" --pipeline deferred --gbuffer "$layout" --lighting "$lighting" \
        --out "$out/wall/$when-$layout-$lighting.png" 2>&1 | grep -E "^error"
    done
  done
done
corridor=(render --scene sponza --camera 10,6.5,-3.5,107,-13,65 --time 4.1 --lights 1000000 --threshold 3.2
  --far-field tree:1:192 --shadows exact --size 1920x1080 --frames 10)
for case in before-compact after-compact after-full; do
  bin=$before
  [ "${case%%-*}" = after ] && bin=$after
  echo "=== corridor $case"
  "$bin" "${corridor[@]}" --gbuffer "${case#*-}" --out "$out/corridor/$case.png" 2>&1 | grep -E "^gpu|^error"
done
source "$(dirname "$0")/gpu-machine-render.sh"
for when in before after; do
  bin=$before
  [ "$when" = after ] && bin=$after
  for shadows in off exact; do
    out=$out/table run "default_5000_${shadows}_$when" --lights 5000 --shadows "$shadows"
  done
done
bash "$(dirname "$0")/gpu-machine-shadows.sh" "$after" "$out/table"
