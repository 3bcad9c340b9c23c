//! The crate's programs: the G-buffer pass per layout and BRDF, the lighting pass per
//! layout, path, emission and light loop, the codec probe, and every one of them for
//! `cargo xtask validate-shaders`.

use manylights_cluster::{ClusterView, LightLoop, ShadingOutput};
use manylights_gpu::{Program, ShaderDef};
use manylights_lights::{Falloff, Shading};
use manylights_visibility::Shadows;

use crate::blended_layers::{shade_program, shades_in_layers, store_program};
use crate::visibility::{classify_program, raster_program, resolve_program};
use crate::{GBufferChannel, GBufferLayout, LightingPath, SHADERS};

/// The G-buffer pass writing `layout` from surfaces built for `shading` (composed per
/// material variant of the scene).
pub fn gbuffer_program(layout: GBufferLayout, shading: Shading) -> Program {
    Program::shading_materials(
        format!("gbuffer_{layout} ({shading})"),
        &SHADERS,
        "deferred/gbuffer.wgsl",
    )
    .with_def(layout.shader_def(), ShaderDef::Bool(true))
    .with_shading(shading)
}

/// The lighting pass reading `layout` on `path` and running `light_loop`; `emissive` when
/// the scene has emissive materials (the G-buffer then has an emission target, added to
/// the shaded radiance).
pub fn lighting_program(
    layout: GBufferLayout,
    path: LightingPath,
    emissive: bool,
    light_loop: LightLoop,
) -> Program {
    let entry = match path {
        LightingPath::Fragment => "deferred/lighting_fragment.wgsl",
        LightingPath::Compute | LightingPath::Tiles => "deferred/lighting_compute.wgsl",
    };
    let suffix = if emissive { "_emissive" } else { "" };
    // Named by the layout it reads: the visibility buffer's is `packed`'s program.
    let program = Program::new(
        format!(
            "deferred_lighting_{}_{path}{suffix} ({})",
            layout.stored(),
            light_loop.label()
        ),
        &SHADERS,
        entry,
    )
    .with_def(layout.shader_def(), ShaderDef::Bool(true))
    .with_defs(light_loop.shader_defs());
    // Debug views run the per-pixel loop: the evaluation count is of the pixel's list.
    let program = if path == LightingPath::Tiles && light_loop.shades() {
        program.with_def("LIGHTING_TILES", ShaderDef::Bool(true))
    } else {
        program
    };
    if emissive {
        program.with_def("EMISSIVE", ShaderDef::Bool(true))
    } else {
        program
    }
}

/// The codecs of `codecs.wgsl` run on the GPU for tests (`tests/gpu_codecs.rs`): entry
/// `probe`, inputs at group 0 binding 0, outputs at binding 1.
pub fn codec_probe_program() -> Program {
    Program::new("codec_probe", &SHADERS, "deferred/codec_probe.wgsl")
}

/// Every program of this crate: every layout, lighting path and emission, each with loops
/// covering every falloff, far field and output (what `cargo xtask validate-shaders`
/// validates).
pub fn programs() -> Vec<Program> {
    let outputs: Vec<ShadingOutput> = std::iter::once(ShadingOutput::Shaded)
        .chain(ClusterView::ALL.map(ShadingOutput::Cluster))
        .chain(
            GBufferChannel::ALL
                .into_iter()
                .map(|channel| ShadingOutput::Pipeline(channel.shader_code())),
        )
        .collect();
    let loops = LightLoop::covering(&outputs);
    // The spatial shadow filter's inputs, written by the compute paths only.
    let filtered = LightLoop::new(Falloff::default(), None, ShadingOutput::Shaded)
        .with_shadows(Shadows::RaysSpatial(4));
    let mut programs = vec![
        codec_probe_program(),
        raster_program(false),
        raster_program(true),
        classify_program(),
        resolve_program(Shading::Pbr),
        resolve_program(Shading::BlinnPhong),
    ];
    // The blended layers: the store for each BRDF, the shading for each loop that shades
    // them (blended surfaces run the loop without its debug views, and loops with a far
    // field draw them forward), with and without emission.
    let mut blended_loops: Vec<LightLoop> = Vec::new();
    for light_loop in loops
        .iter()
        .filter_map(|light_loop| light_loop.for_blended())
    {
        if shades_in_layers(light_loop) && !blended_loops.contains(&light_loop) {
            blended_loops.push(light_loop);
        }
    }
    for emissive in [false, true] {
        programs.extend(Shading::ALL.map(|shading| store_program(shading, emissive)));
        for path in [LightingPath::Compute, LightingPath::Tiles] {
            for light_loop in &blended_loops {
                programs.push(shade_program(emissive, path, *light_loop));
            }
        }
    }
    // The visibility buffer's lighting is the packed layout's (its resolve writes packed).
    let stored = GBufferLayout::ALL.into_iter().filter(|l| l.stored() == *l);
    for layout in stored {
        programs.extend(Shading::ALL.map(|shading| gbuffer_program(layout, shading)));
        for path in LightingPath::ALL {
            for emissive in [false, true] {
                for light_loop in &loops {
                    programs.push(lighting_program(layout, path, emissive, *light_loop));
                }
                if path.is_compute() {
                    programs.push(lighting_program(layout, path, emissive, filtered));
                }
            }
        }
    }
    programs
}
