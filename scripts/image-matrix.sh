#!/usr/bin/env bash
# Renders a matrix of small frames (every pipeline, G-buffer layout, lighting path, debug
# view, falloff, tonemap and material variant the presets reach; each shadow route, blended
# surfaces, MSAA, far fields and spots) and prints one SHA-256 per image. Run it before and after a refactor on the same machine and diff the two lists: a
# refactor that claims "images unchanged" must leave every line as it was.
#
#   scripts/image-matrix.sh BIN OUT_DIR > hashes.txt
set -euo pipefail
bin=${1:?usage: image-matrix.sh BIN OUT_DIR}
out=${2:?usage: image-matrix.sh BIN OUT_DIR}
mkdir -p "$out"

render() {
    local name=$1
    shift
    # No warm-up: the frames drawn before the image must not depend on the machine's
    # speed (the shadow history accumulates over them).
    "$bin" render --size 160x90 --lights 300 --warmup-seconds 0 --out "$out/$name.png" "$@" >/dev/null
    (cd "$out" && sha256sum "$name.png")
}

for scene in cornell sponza pillars; do
    render "$scene-naive" --scene "$scene" --pipeline naive
    render "$scene-forward-plus" --scene "$scene" --pipeline forward-plus
    render "$scene-forward-plus-no-prepass" --scene "$scene" --pipeline forward-plus --no-depth-prepass
    for layout in full compact packed; do
        for lighting in fragment compute; do
            render "$scene-deferred-$layout-$lighting" --scene "$scene" --pipeline deferred \
                --gbuffer "$layout" --lighting "$lighting"
        done
    done
done
for view in heatmap slices evaluations; do
    render "sponza-forward-plus-$view" --scene sponza --pipeline forward-plus --debug-view "$view"
    render "sponza-deferred-$view" --scene sponza --pipeline deferred --debug-view "$view"
done
for view in albedo normal depth position; do
    for layout in full compact packed; do
        render "sponza-deferred-$layout-$view" --scene sponza --pipeline deferred \
            --gbuffer "$layout" --debug-view "$view"
    done
done
for falloff in reference-projects inverse-square; do
    render "sponza-naive-$falloff" --scene sponza --pipeline naive --falloff "$falloff"
done
render "sponza-forward-plus-reference-projects" --scene sponza --pipeline forward-plus --falloff reference-projects
render "sponza-deferred-reference-projects" --scene sponza --pipeline deferred --falloff reference-projects
for tonemap in none reinhard; do
    render "sponza-deferred-$tonemap" --scene sponza --tonemap "$tonemap"
done
render "sponza-deferred-fixed-exposure" --scene sponza --exposure 1
render "sponza-deferred-compensation" --scene sponza --exposure-compensation 1
render "sponza-deferred-atomic-fill" --scene sponza --assignment atomic-fill
render "sponza-forward-plus-linear-fitted" --scene sponza --pipeline forward-plus --z-scheme linear --z-range fitted
render "sponza-deferred-reverse-z" --scene sponza --reverse-z
render "cornell-deferred-orthographic" --scene cornell --orthographic 4
# Shadows in every pipeline and lighting path (the routes: in the loop, the forward shadow
# pass, deferred's compute lighting, with the filter and history), also under the debug
# views (whose loops trace unfiltered); blended surfaces, MSAA, far fields and spots.
for shadows in exact rays:1 rays:2 rays:1+spatial rays:1+spatial+temporal; do
    tag=${shadows//[:+]/_}
    for pipeline in naive forward-plus; do
        render "sponza-$pipeline-shadows-$tag" --scene sponza --pipeline "$pipeline" --shadows "$shadows"
    done
    for lighting in fragment compute tiles; do
        case "$shadows" in *spatial*) [ "$lighting" = fragment ] && continue ;; esac
        render "sponza-deferred-$lighting-shadows-$tag" --scene sponza --pipeline deferred \
            --lighting "$lighting" --shadows "$shadows"
    done
    render "sponza-forward-plus-evaluations-shadows-$tag" --scene sponza --pipeline forward-plus \
        --debug-view evaluations --shadows "$shadows"
    render "sponza-deferred-evaluations-shadows-$tag" --scene sponza --pipeline deferred \
        --debug-view evaluations --shadows "$shadows"
done
for pipeline in naive forward-plus deferred; do
    render "sponza-glass-$pipeline" --scene sponza-glass --pipeline "$pipeline"
    render "sponza-glass-$pipeline-weighted" --scene sponza-glass --pipeline "$pipeline" --transparency weighted
    render "sponza-glass-$pipeline-shadows" --scene sponza-glass --pipeline "$pipeline" \
        --shadows rays:1+spatial+temporal
done
render "sponza-forward-plus-msaa" --scene sponza --pipeline forward-plus --msaa 4
render "sponza-naive-msaa-exact" --scene sponza --pipeline naive --msaa 4 --shadows exact
render "sponza-deferred-far-tree" --scene sponza --far-field tree:1:64
render "sponza-deferred-far-stochastic" --scene sponza --far-field stochastic
render "sponza-deferred-spots" --scene sponza --spot-fraction 0.5
# The post stack and the generated lights' shapes, by their shortcut flags and by the paths
# they set (`--set`: the same settings, so the same image).
for pipeline in naive forward-plus deferred; do
    render "sponza-$pipeline-taa" --scene sponza --pipeline "$pipeline" --aa taa --frames 4
    render "sponza-$pipeline-bloom" --scene sponza --pipeline "$pipeline" --bloom 0.08
    render "sponza-$pipeline-rects" --scene sponza --pipeline "$pipeline" --light-shape rect:0.3
done
render "sponza-deferred-spheres" --scene sponza --light-shape sphere:0.3
render "sponza-deferred-bloom-by-path" --scene sponza --set post.bloom=0.08
render "sponza-deferred-rects-by-path" --scene sponza --set lights.shape=rect:0.3
