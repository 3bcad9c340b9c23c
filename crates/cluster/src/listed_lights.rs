//! The light lists in an engine's own shader (`shaders/cluster/listed_lights.wgsl`): the
//! WGSL that walks the lights reaching a point, as one source to put before the engine's
//! own, the bind group layout that source declares, and the bind group of this frame's
//! lists ([`GpuClusters`]) and lights ([`GpuLights`]). manylights' own loops walk the lists
//! through the same WGSL functions (`cluster_lights.wgsl`, `tile_lights.wgsl`), bound at
//! [`MANYLIGHTS_GROUP`].

use manylights_gpu::binding::{bind_group, bind_group_layout, storage_entry, uniform_entry};
use manylights_gpu::{GpuContext, GpuResult, Program, ShaderDef, ShaderLibrary, wgpu};
use manylights_lights::GpuLights;

use crate::GpuClusters;

/// The bind group index manylights' own lighting passes bind the lists at (the pipeline
/// crate's `LIGHTING_GROUP`, which shares it with their other lighting inputs).
pub const MANYLIGHTS_GROUP: u32 = 3;

/// The prefix of every name in [`ListedLights::wgsl`]'s source: `manylights_lights_at`,
/// `manylights_listed_light`, `manylights_lights`, `manylights_NOT_LISTED`, ...
pub const WGSL_PREFIX: &str = "manylights_";

/// The light lists as an engine's shader reads them, at the bind group index it chose.
///
/// What it takes: a [`GpuClusters`] prepared for the frame and the [`GpuLights`] it
/// assigned. What it gives: the WGSL ([`ListedLights::wgsl`]), the layout of its group
/// ([`ListedLights::layout`]) and the group itself ([`ListedLights::bind_group`]). The
/// engine's shader then walks, per pixel, the lights whose range reaches its cluster:
///
/// ```wgsl
/// let list = manylights_lights_at(position.xy, view_depth);
/// for (var i = 0u; i < list.candidates; i++) {
///     let index = manylights_listed_light(list, i);
///     if index == manylights_NOT_LISTED { continue; }
///     let light = manylights_lights[index];
///     radiance += my_brdf(light, ...) * manylights_windowed_falloff(d2, light.radius);
/// }
/// ```
/// `view_depth` is the point's positive distance along the camera's view direction, as
/// the grid ([`crate::ClusterGrid::for_view`]) slices it.
#[derive(Debug)]
pub struct ListedLights {
    group: u32,
    layout: wgpu::BindGroupLayout,
}

impl ListedLights {
    /// The bindings the WGSL declares, in its group: 0 the grid, 1 the list offsets, 2 the
    /// lists' light indices, 3 the lights, 5 the lights in view space, 6 the clusters'
    /// boxes (4 and 7 to 16 are manylights' own lighting inputs).
    pub const BINDINGS: [u32; 6] = [0, 1, 2, 3, 5, 6];

    /// The layout entries of [`ListedLights::BINDINGS`], visible to `stages`: what an
    /// engine puts in a layout of its own (alone, or beside bindings of its own that take
    /// other numbers).
    pub fn layout_entries(stages: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 6] {
        [
            uniform_entry(0, stages),
            storage_entry(1, stages, true),
            storage_entry(2, stages, true),
            storage_entry(3, stages, true),
            storage_entry(5, stages, true),
            storage_entry(6, stages, true),
        ]
    }

    /// The lists at bind group `group` of the engine's shader, for its fragment and
    /// compute stages.
    pub fn new(context: &GpuContext, group: u32) -> Self {
        let stages = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        Self {
            group,
            layout: bind_group_layout(context, "listed lights", &Self::layout_entries(stages)),
        }
    }

    /// The bind group index the WGSL declares.
    pub fn group(&self) -> u32 {
        self.group
    }

    /// The layout of the group, for the engine's pipeline layout at [`ListedLights::group`].
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The program of `cluster/listed_lights.wgsl` at this group, for a caller composing
    /// with manylights' [`ShaderLibrary`].
    pub fn program(&self) -> Program {
        Program::new(
            "listed_lights",
            &crate::SHADERS,
            "cluster/listed_lights.wgsl",
        )
        .with_def("LISTED_LIGHTS_GROUP", ShaderDef::UInt(self.group))
    }

    /// The WGSL, self-contained (no `#import`s, no shader defs), with every name
    /// prefixed by [`WGSL_PREFIX`]: put it before the engine's own WGSL in one module.
    /// It declares [`ListedLights::BINDINGS`] at [`ListedLights::group`] and nothing else
    /// (no entry point, no other binding), and the `Light` struct as
    /// `manylights_Light` (the layout of [`manylights_lights::Light`]). `library` is where
    /// the WGSL is read from: [`ShaderLibrary::Embedded`], or the one the engine gave
    /// [`GpuClusters::new`].
    pub fn wgsl(&self, library: &ShaderLibrary) -> GpuResult<String> {
        library
            .compose(&self.program(), Default::default())?
            .to_wgsl(WGSL_PREFIX)
    }

    /// This frame's group: `clusters`' lists (after its `prepare` for the frame; make the
    /// group again when `prepare` says it rebuilt its buffers) and `lights`, the lights
    /// they were assigned from.
    pub fn bind_group(
        &self,
        context: &GpuContext,
        clusters: &GpuClusters,
        lights: &GpuLights,
    ) -> GpuResult<wgpu::BindGroup> {
        let buffers = [
            clusters.params_buffer(),
            clusters.offsets_buffer()?,
            clusters.indices_buffer()?,
            &lights.buffer,
            clusters.view_lights_buffer()?,
            clusters.bounds_buffer()?,
        ];
        let resources = Self::BINDINGS
            .into_iter()
            .zip(buffers.map(wgpu::Buffer::as_entire_binding));
        Ok(bind_group(
            context,
            "listed lights",
            &self.layout,
            resources,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The source an engine gets, parsed back as a plain WGSL front end would: it declares
    /// the six bindings at the engine's group and nothing else, and every name it adds to
    /// the engine's module has the prefix.
    #[test]
    fn the_wgsl_declares_the_six_bindings_at_the_engines_group_with_every_name_prefixed() {
        for group in [0, 1, 3] {
            let program = Program::new(
                "listed_lights",
                &crate::SHADERS,
                "cluster/listed_lights.wgsl",
            )
            .with_def("LISTED_LIGHTS_GROUP", ShaderDef::UInt(group));
            let source = ShaderLibrary::Embedded
                .compose(&program, Default::default())
                .and_then(|composed| composed.to_wgsl(WGSL_PREFIX))
                .expect("the listed lights' WGSL");
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}\n{source}", e.emit_to_string(&source)));
            let mut bindings: Vec<(u32, u32)> = module
                .global_variables
                .iter()
                .filter_map(|(_, global)| global.binding.as_ref())
                .map(|binding| (binding.group, binding.binding))
                .collect();
            bindings.sort_unstable();
            let expected: Vec<(u32, u32)> =
                ListedLights::BINDINGS.iter().map(|&b| (group, b)).collect();
            assert_eq!(bindings, expected, "{source}");
            let names = module
                .types
                .iter()
                .filter_map(|(_, ty)| ty.name.clone())
                .chain(module.constants.iter().filter_map(|(_, c)| c.name.clone()))
                .chain(
                    module
                        .global_variables
                        .iter()
                        .filter_map(|(_, g)| g.name.clone()),
                )
                .chain(module.functions.iter().filter_map(|(_, f)| f.name.clone()));
            for name in names {
                assert!(name.starts_with(WGSL_PREFIX), "{name} in\n{source}");
            }
            for public in [
                "fn manylights_lights_at(",
                "fn manylights_listed_light(",
                "struct manylights_Light {",
            ] {
                assert!(source.contains(public), "{public} in\n{source}");
            }
            if group == 1 {
                println!("{source}");
            }
        }
    }
}
