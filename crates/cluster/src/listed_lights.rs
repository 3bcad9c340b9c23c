//! The light lists in an engine's own shader (`shaders/cluster/listed_lights.wgsl`): the
//! WGSL that walks the lights reaching a point, as one source to put before the engine's
//! own, the bind group layout that source declares, and the bind group of this frame's
//! lists ([`GpuClusters`]) and lights ([`GpuLights`]). manylights' own loops walk the lists
//! through the same WGSL functions (`cluster_lights.wgsl`, `tile_lights.wgsl`), bound at
//! [`MANYLIGHTS_GROUP`].

use manylights_gpu::binding::{bind_group, bind_group_layout, storage_entry, uniform_entry};
use manylights_gpu::{GpuContext, GpuResult, Program, ShaderDef, ShaderLibrary, wgpu};
use manylights_lights::{GpuLights, lighting_group};

use crate::GpuClusters;

/// The bind group index manylights' own lighting passes bind the lists at (the pipeline
/// crate's `LIGHTING_GROUP`, which shares it with their other lighting inputs).
pub const MANYLIGHTS_GROUP: u32 = manylights_lights::MANYLIGHTS_GROUP;

/// The prefix of every name in [`ListedLights::wgsl`]'s source: `manylights_lights_at`,
/// `manylights_listed_light`, `manylights_lights`, `manylights_NOT_LISTED`, ...
pub const WGSL_PREFIX: &str = "manylights_";

/// The programs of the lists' WGSL at `group`, with the far field's or not.
fn programs(group: u32, far_field: bool) -> Vec<Program> {
    let program = |name, entry| {
        Program::new(name, &crate::SHADERS, entry)
            .with_def("LISTED_LIGHTS_GROUP", ShaderDef::UInt(group))
    };
    let mut programs = vec![program("listed_lights", "cluster/listed_lights.wgsl")];
    if far_field {
        programs.push(program("far_terms", "cluster/far_terms.wgsl"));
    }
    programs
}

/// The program of `cluster/clustered_radiance.wgsl`: the lists at `group` (with the far
/// field's cut or not), our BRDF's table at `tables_group`, positions in world space.
pub(crate) fn clustered_radiance_program(
    group: u32,
    far_field: bool,
    tables_group: u32,
) -> Program {
    let program = Program::new(
        "clustered_radiance",
        &crate::SHADERS,
        "cluster/clustered_radiance.wgsl",
    )
    .with_shading(manylights_lights::Shading::Pbr)
    .with_def("LISTED_LIGHTS_GROUP", ShaderDef::UInt(group))
    .with_def("SPECULAR_TABLES_GROUP", ShaderDef::UInt(tables_group))
    .with_def("LIGHTS_IN_WORLD_SPACE", ShaderDef::Bool(true));
    if far_field {
        program.with_def("CLUSTERED_RADIANCE_FAR_FIELD", ShaderDef::Bool(true))
    } else {
        program
    }
}

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
///
/// With the far field ([`ListedLights::with_far_field`], for frames whose
/// [`crate::ClusterFrame::far_field`] is a light tree), the WGSL also walks the cluster's
/// cut of the tree (`far_terms.wgsl`: `manylights_far_cut`, `manylights_far_entry`,
/// `manylights_aggregate_term`, `manylights_far_light`, `manylights_far_falloff`): what the
/// lights add beyond their radius, so a million lights shade at the cost of the few that
/// reach each cluster plus a cut of aggregates.
#[derive(Debug)]
pub struct ListedLights {
    group: u32,
    far_field: bool,
    layout: wgpu::BindGroupLayout,
}

impl ListedLights {
    /// The bindings the WGSL declares, in its group, numbered as in manylights' lighting
    /// group ([`lighting_group`]): 0 the grid, 1 the list offsets, 2 the lists' light
    /// indices, 3 the lights, 5 the lights in view space, 6 the clusters' boxes (4 and 7
    /// and above are manylights' own lighting inputs).
    pub const BINDINGS: [u32; 6] = [
        lighting_group::GRID,
        lighting_group::LIST_OFFSETS,
        lighting_group::LIST_INDICES,
        lighting_group::LIGHTS,
        lighting_group::VIEW_LIGHTS,
        lighting_group::CLUSTER_BOUNDS,
    ];

    /// The far field's bindings, in the same group: 7 its parameters, 8 the tree's nodes,
    /// 9 each cluster's cut, 10 the lights in the tree's order.
    pub const FAR_FIELD_BINDINGS: [u32; 4] = lighting_group::FAR_FIELD_BINDINGS;

    /// The layout entries of [`ListedLights::BINDINGS`], visible to `stages`: what an
    /// engine puts in a layout of its own (alone, or beside bindings of its own that take
    /// other numbers).
    pub fn layout_entries(stages: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 6] {
        let [grid, offsets, indices, lights, view_lights, bounds] = Self::BINDINGS;
        [
            uniform_entry(grid, stages),
            storage_entry(offsets, stages, true),
            storage_entry(indices, stages, true),
            storage_entry(lights, stages, true),
            storage_entry(view_lights, stages, true),
            storage_entry(bounds, stages, true),
        ]
    }

    /// The lists at bind group `group` of the engine's shader, for its fragment and
    /// compute stages.
    pub fn new(context: &GpuContext, group: u32) -> Self {
        Self::with_layout(context, group, false)
    }

    /// The lists and the far field's cut at bind group `group`.
    pub fn with_far_field(context: &GpuContext, group: u32) -> Self {
        Self::with_layout(context, group, true)
    }

    fn with_layout(context: &GpuContext, group: u32, far_field: bool) -> Self {
        let stages = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let mut entries = Self::layout_entries(stages).to_vec();
        if far_field {
            entries.extend(Self::far_field_layout_entries(stages));
        }
        Self {
            group,
            far_field,
            layout: bind_group_layout(context, "listed lights", &entries),
        }
    }

    /// The layout entries of [`ListedLights::FAR_FIELD_BINDINGS`], visible to `stages`.
    pub fn far_field_layout_entries(stages: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 4] {
        let [params, nodes, lists, order] = Self::FAR_FIELD_BINDINGS;
        [
            uniform_entry(params, stages),
            storage_entry(nodes, stages, true),
            storage_entry(lists, stages, true),
            storage_entry(order, stages, true),
        ]
    }

    /// The bind group index the WGSL declares.
    pub fn group(&self) -> u32 {
        self.group
    }

    /// The layout of the group, for the engine's pipeline layout at [`ListedLights::group`].
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The programs of `cluster/listed_lights.wgsl` (and with the far field
    /// `cluster/far_terms.wgsl`) at this group: the composable form. An engine that
    /// composes with naga_oil adds each to its own composer
    /// ([`ShaderLibrary::add_to_composer`], which returns the shader defs to compose with)
    /// and `#import`s from `manylights::cluster::listed_lights` (`lights_at`,
    /// `listed_light`, `lights`, ...) and `manylights::cluster::far_terms`, unprefixed.
    pub fn programs(&self) -> Vec<Program> {
        programs(self.group, self.far_field)
    }

    /// The WGSL, self-contained (no `#import`s, no shader defs), with every name
    /// prefixed by [`WGSL_PREFIX`]: put it before the engine's own WGSL in one module.
    /// It declares [`ListedLights::BINDINGS`] (and with the far field
    /// [`ListedLights::FAR_FIELD_BINDINGS`]) at [`ListedLights::group`] and nothing else
    /// (no entry point, no other binding), and the `Light` struct as `manylights_Light`
    /// (the layout of [`manylights_lights::Light`]). `library` is where the WGSL is read
    /// from: [`ShaderLibrary::Embedded`], or the one the engine gave [`GpuClusters::new`].
    pub fn wgsl(&self, library: &ShaderLibrary) -> GpuResult<String> {
        let sources = self
            .programs()
            .iter()
            .map(|program| {
                library
                    .compose(program, Default::default())?
                    .to_wgsl(WGSL_PREFIX)
            })
            .collect::<GpuResult<Vec<String>>>()?;
        Ok(sources.join("\n"))
    }

    /// The clustered radiance of a surface in one call, as a self-contained WGSL source
    /// (every name prefixed by [`WGSL_PREFIX`]) to use instead of [`ListedLights::wgsl`]:
    ///
    /// ```wgsl
    /// let radiance = manylights_clustered_radiance(frag_coord.xy, view_depth, world,
    ///     normal, view_dir, base_color, metallic, roughness);
    /// ```
    /// the radiance towards the eye from every light of the point's cluster list, each by
    /// its shape (points, spots, spheres, rectangles, triangles) and, with the far field,
    /// the cluster's cut of the light tree, through our BRDF (glTF's metallic-roughness,
    /// as our pipelines shade it; no shadows). Positions are world space, `view_dir` the
    /// unit direction from the point to the eye, `view_depth` as in the lists' walk.
    ///
    /// It declares the lists' bindings at [`ListedLights::group`] (those the function
    /// reads: [`ListedLights::BINDINGS`], and with the far field 7 to 10) and our BRDF's
    /// one table at `tables_group`, binding
    /// [`manylights_lights::SpecularTables::BINDING`] (in a group of the engine's own, or
    /// beside the lists in a layout the engine makes from [`ListedLights::layout_entries`]
    /// and [`manylights_lights::SpecularTables::layout_entry`]).
    pub fn clustered_radiance_wgsl(
        &self,
        library: &ShaderLibrary,
        tables_group: u32,
    ) -> GpuResult<String> {
        library
            .compose(
                &self.clustered_radiance_program(tables_group),
                Default::default(),
            )?
            .to_wgsl(WGSL_PREFIX)
    }

    /// The program of [`ListedLights::clustered_radiance_wgsl`], the composable form: an
    /// engine that composes with naga_oil adds it to its composer
    /// ([`ShaderLibrary::add_to_composer`]) and `#import`s `clustered_radiance` from
    /// `manylights::cluster::clustered_radiance`.
    pub fn clustered_radiance_program(&self, tables_group: u32) -> Program {
        clustered_radiance_program(self.group, self.far_field, tables_group)
    }

    /// This frame's group: `clusters`' lists (after its `prepare` for the frame; make the
    /// group again after each `prepare`: the buffers it binds change when the lists grow
    /// or the tree is rebuilt) and `lights`, the lights they were assigned from.
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
        let lists = Self::BINDINGS.into_iter().zip(buffers);
        let far_field = (Self::FAR_FIELD_BINDINGS.into_iter())
            .zip(clusters.far_field().shading_buffers())
            .filter(|_| self.far_field);
        let resources = lists
            .chain(far_field)
            .map(|(binding, buffer)| (binding, buffer.as_entire_binding()));
        // In an error scope: on an engine's device a mistake of ours comes back here, not
        // through the engine's uncaptured-error callback.
        context.scoped("creating the listed lights' bind group", || {
            bind_group(context, "listed lights", &self.layout, resources)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The (group, binding) pairs `module` declares, sorted.
    fn declared_bindings(module: &naga::Module) -> Vec<(u32, u32)> {
        let mut bindings: Vec<(u32, u32)> = (module.global_variables.iter())
            .filter_map(|(_, global)| global.binding.as_ref())
            .map(|binding| (binding.group, binding.binding))
            .collect();
        bindings.sort_unstable();
        bindings
    }

    /// The lists' (group, binding) pairs at `group`, with the far field's or not.
    fn lists_bindings(group: u32, far_field: bool) -> Vec<(u32, u32)> {
        let far = far_field
            .then_some(ListedLights::FAR_FIELD_BINDINGS)
            .into_iter()
            .flatten();
        (ListedLights::BINDINGS.into_iter())
            .chain(far)
            .map(|b| (group, b))
            .collect()
    }

    /// The source an engine gets, parsed back as a plain WGSL front end would: it declares
    /// the six bindings at the engine's group and nothing else, and every name it adds to
    /// the engine's module has the prefix.
    #[test]
    fn the_wgsl_declares_its_bindings_at_the_engines_group_with_every_name_prefixed() {
        for (group, far_field) in [(0, false), (1, true), (3, false)] {
            let sources = (programs(group, far_field).iter())
                .map(|program| {
                    ShaderLibrary::Embedded
                        .compose(program, Default::default())?
                        .to_wgsl(WGSL_PREFIX)
                })
                .collect::<GpuResult<Vec<String>>>()
                .expect("the listed lights' WGSL");
            let source = sources.join("\n");
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}\n{source}", e.emit_to_string(&source)));
            let expected = lists_bindings(group, far_field);
            assert_eq!(declared_bindings(&module), expected, "{source}");
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
            let mut public = vec![
                "fn manylights_lights_at(",
                "fn manylights_listed_light(",
                "struct manylights_Light {",
            ];
            if far_field {
                public.extend([
                    "fn manylights_far_cut(",
                    "fn manylights_far_entry(",
                    "fn manylights_aggregate_term(",
                ]);
            }
            for item in public {
                assert!(source.contains(item), "{item} in\n{source}");
            }
        }
    }

    /// The one-call clustered radiance, as an engine gets it: a module that validates,
    /// with the lists' bindings at the engine's group, the BRDF's table at the group it
    /// chose and nothing else (no camera of ours at group 0), every name prefixed.
    #[test]
    fn the_clustered_radiance_binds_only_the_lists_and_the_brdfs_table() {
        use manylights_lights::SpecularTables;
        for (group, far_field, tables_group) in [(1, false, 2), (2, true, 0), (1, true, 1)] {
            let program = clustered_radiance_program(group, far_field, tables_group);
            let source = ShaderLibrary::Embedded
                .compose(&program, Default::default())
                .and_then(|module| module.to_wgsl(WGSL_PREFIX))
                .expect("the clustered radiance's WGSL");
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}\n{source}", e.emit_to_string(&source)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{e:?}\n{source}"));
            let mut expected = lists_bindings(group, far_field);
            expected.push((tables_group, SpecularTables::BINDING));
            expected.sort_unstable();
            assert_eq!(declared_bindings(&module), expected, "{source}");
            assert!(
                source.contains("fn manylights_clustered_radiance("),
                "{source}"
            );
            let functions = module.functions.iter().filter_map(|(_, f)| f.name.clone());
            for name in functions {
                assert!(name.starts_with(WGSL_PREFIX), "{name} in\n{source}");
            }
        }
    }

    /// An engine that composes its own WGSL with naga_oil imports the lists (and the far
    /// field's cut) into its shader from its own composer: the module validates, with the
    /// engine's binding beside ours and nothing else.
    #[test]
    fn an_engine_imports_the_lists_into_its_own_naga_oil_composer() {
        use manylights_gpu::naga_oil::compose::{Composer, NagaModuleDescriptor, ShaderDefValue};
        let mut composer = Composer::default();
        let mut defs: std::collections::HashMap<String, ShaderDefValue> = Default::default();
        for program in programs(1, true) {
            let added = ShaderLibrary::Embedded
                .add_to_composer(&mut composer, &program)
                .expect("our modules in the engine's composer");
            defs.extend(added);
        }
        let engine_shader = r#"
#import manylights::cluster::listed_lights::{lights_at, listed_light, lights, NOT_LISTED, windowed_falloff}
#import manylights::cluster::far_terms::{far_cut, far_entry}

@group(0) @binding(0) var<uniform> engine_camera: vec4<f32>;

@fragment
fn fs_main(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let list = lights_at(position.xy, engine_camera.x);
    var radiance = vec3<f32>(0.0);
    for (var i = 0u; i < list.candidates; i++) {
        let index = listed_light(list, i);
        if index == NOT_LISTED {
            continue;
        }
        radiance += lights[index].color * windowed_falloff(1.0, lights[index].radius);
    }
    let cut = far_cut(list.cluster);
    for (var k = 0u; k < cut.entries; k++) {
        radiance += far_entry(cut, k).node.power;
    }
    return vec4<f32>(radiance, 1.0);
}
"#;
        let module = composer
            .make_naga_module(NagaModuleDescriptor {
                source: engine_shader,
                file_path: "engine.wgsl",
                shader_defs: defs,
                ..Default::default()
            })
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .expect("the engine's module validates");
        // What the shader reads and nothing else: it never reads the far lights' order
        // (binding 10, `far_light`), and naga_oil leaves out what is not used.
        let ours = ListedLights::BINDINGS.into_iter().chain([7, 8, 9]);
        let expected: Vec<(u32, u32)> = std::iter::once((0, 0))
            .chain(ours.map(|b| (1, b)))
            .collect();
        assert_eq!(declared_bindings(&module), expected);
    }
}
