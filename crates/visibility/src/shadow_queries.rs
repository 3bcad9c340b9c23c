//! Shadow rays as a service: the scene's BVH ([`GpuSceneBvh`], built from an engine's own
//! triangles with [`crate::SceneBvh::from_triangles`]) queried from an engine's own shader.
//! [`ShadowQueries`] gives the WGSL (`shaders/visibility/bvh.wgsl`, written back as one
//! source), the layout of the group it declares and the group itself.

use manylights_gpu::binding::{bind_group, bind_group_layout};
use manylights_gpu::{GpuContext, GpuResult, Program, ShaderDef, ShaderLibrary, wgpu};

use crate::GpuSceneBvh;

/// The bind group index manylights' own lighting passes bind the BVH at (beside the
/// lists, bindings [`crate::FIRST_BINDING`] to +3).
pub const MANYLIGHTS_GROUP: u32 = manylights_lights::MANYLIGHTS_GROUP;

/// The prefix of every name in [`ShadowQueries::wgsl`]'s source:
/// `manylights_shadows_unless_shadowed`, `manylights_shadows_light_visible`, ... It differs
/// from the lists' (`manylights_`), so both sources go into one module: each declares
/// the `Light` struct under its own name.
pub const WGSL_PREFIX: &str = "manylights_shadows_";

/// Shadow rays through the scene's BVH from an engine's shader, at the bind group index it
/// chose. The traversal is software (no ray-tracing hardware or extension), in fragment
/// and compute stages alike:
///
/// ```wgsl
/// // `radiance` from a light at `light_position`, or nothing where the scene blocks the
/// // ray from `world` (its surface normal `normal`; 0: an interpolated position).
/// radiance = manylights_shadows_unless_shadowed(radiance, world, normal, 0.0, light_position);
/// // or only the answer:
/// let lit = manylights_shadows_light_visible(world, normal, 0.0, light_position);
/// ```
#[derive(Debug)]
pub struct ShadowQueries {
    group: u32,
    layout: wgpu::BindGroupLayout,
}

impl ShadowQueries {
    /// The shadow queries at bind group `group` of the engine's shader, for its fragment
    /// and compute stages (bindings [`crate::FIRST_BINDING`] to +3:
    /// [`GpuSceneBvh::layout_entries`]).
    pub fn new(context: &GpuContext, group: u32) -> Self {
        let stages = wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let entries = GpuSceneBvh::layout_entries(stages);
        Self {
            group,
            layout: bind_group_layout(context, "shadow queries", &entries),
        }
    }

    /// The bind group index the WGSL declares.
    pub fn group(&self) -> u32 {
        self.group
    }

    /// The layout of the group, for the engine's pipeline layout at [`ShadowQueries::group`].
    pub fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The program of `visibility/bvh.wgsl` at this group, for a caller composing with
    /// manylights' [`ShaderLibrary`].
    pub fn program(&self) -> Program {
        Program::new("shadow_queries", &crate::SHADERS, "visibility/bvh.wgsl")
            .with_def("BVH_GROUP", ShaderDef::UInt(self.group))
    }

    /// The WGSL, self-contained, every name prefixed with [`WGSL_PREFIX`]: put it in the
    /// engine's module beside its own WGSL (and the lists', if it uses them). `library`:
    /// where the WGSL is read from ([`ShaderLibrary::Embedded`] unless the engine reads it
    /// from a folder).
    pub fn wgsl(&self, library: &ShaderLibrary) -> GpuResult<String> {
        library
            .compose(&self.program(), Default::default())?
            .to_wgsl(WGSL_PREFIX)
    }

    /// The group binding `bvh` (in an error scope: a validation error comes back here).
    pub fn bind_group(
        &self,
        context: &GpuContext,
        bvh: &GpuSceneBvh,
    ) -> GpuResult<wgpu::BindGroup> {
        context.scoped("creating the shadow queries' bind group", || {
            bind_group(context, "shadow queries", &self.layout, bvh.bindings())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The source an engine gets, parsed back by a plain WGSL front end: the BVH's four
    /// bindings at the engine's group and nothing else (no camera, no lists), every name
    /// prefixed.
    #[test]
    fn the_wgsl_declares_the_bvh_at_the_engines_group_with_every_name_prefixed() {
        for group in [0, 2] {
            let program = Program::new("shadow_queries", &crate::SHADERS, "visibility/bvh.wgsl")
                .with_def("BVH_GROUP", ShaderDef::UInt(group));
            let source = ShaderLibrary::Embedded
                .compose(&program, Default::default())
                .and_then(|composed| composed.to_wgsl(WGSL_PREFIX))
                .expect("the shadow queries' WGSL");
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}\n{source}", e.emit_to_string(&source)));
            let mut bindings: Vec<(u32, u32)> = (module.global_variables.iter())
                .filter_map(|(_, global)| global.binding.as_ref())
                .map(|binding| (binding.group, binding.binding))
                .collect();
            bindings.sort_unstable();
            let expected: Vec<(u32, u32)> =
                (0..4).map(|k| (group, crate::FIRST_BINDING + k)).collect();
            assert_eq!(bindings, expected, "{source}");
            let names = (module.types.iter().filter_map(|(_, ty)| ty.name.clone()))
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
            for item in [
                "fn manylights_shadows_unless_shadowed(",
                "fn manylights_shadows_light_visible(",
            ] {
                assert!(source.contains(item), "{item} in\n{source}");
            }
        }
    }
}
