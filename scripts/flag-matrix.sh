#!/usr/bin/env bash
# Renders one small frame per command-line flag that sets a frame setting (the rows of
# `SETTING_FLAGS` and the flags that combine fields) and prints one SHA-256 per image. Run
# it with the binaries before and after a change to the command line and diff the lists:
# a flag that moved to another spelling must still draw the same frame.
#
#   scripts/flag-matrix.sh BIN OUT_DIR > hashes.txt
set -euo pipefail
bin=${1:?usage: flag-matrix.sh BIN OUT_DIR}
out=${2:?usage: flag-matrix.sh BIN OUT_DIR}
mkdir -p "$out"

render() {
    local name=$1
    shift
    "$bin" render --warmup-seconds 0 --out "$out/$name.png" "$@" >/dev/null
    (cd "$out" && sha256sum "$name.png")
}

small=(--size 160x90)
render default "${small[@]}" --scene cornell
render lights "${small[@]}" --scene cornell --lights 77
render size --size 120x80 --scene cornell
render time "${small[@]}" --scene cornell --time 2.5
render seed "${small[@]}" --scene cornell --seed 7
render intensity "${small[@]}" --scene cornell --intensity 0.5
render saturation "${small[@]}" --scene cornell --saturation 0.3
render spots "${small[@]}" --scene cornell --spot-fraction 0.5 --spot-culling sphere
render emissive "${small[@]}" --scene lamps --emissive-lights off
render radius "${small[@]}" --scene cornell --radius 0.7
render threshold "${small[@]}" --scene cornell --threshold 0.1
render tonemap "${small[@]}" --scene cornell --tonemap reinhard
render gbuffer "${small[@]}" --scene sponza --gbuffer full --lighting compute
render packed "${small[@]}" --scene sponza --gbuffer packed --lighting fragment
render assignment "${small[@]}" --scene sponza --assignment atomic-fill --cluster-boxes grid
render forward-plus "${small[@]}" --scene sponza --pipeline forward-plus --lights 500
render naive "${small[@]}" --scene cornell --pipeline naive --lights 50
render exact "${small[@]}" --scene cornell --shadows exact --lights 40
render budget "${small[@]}" --scene cornell --budget 1000
render shape "${small[@]}" --scene cornell --light-shape sphere:0.2 --lights 50
render msaa "${small[@]}" --scene cornell --pipeline forward-plus --msaa 4
render bloom "${small[@]}" --scene cornell --bloom 0.05
render exposure "${small[@]}" --scene cornell --exposure-compensation 1
render far-field "${small[@]}" --scene sponza --far-field tree:0.2 --lights 2000
render grid "${small[@]}" --scene sponza --tiles 8x6 --slices 12 --z-scheme log
