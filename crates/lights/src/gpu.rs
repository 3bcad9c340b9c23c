//! Lights on the GPU: the storage buffer and the animation compute pass
//! (`shaders/lights/animate.wgsl`).

use manylights_gpu::{
    GpuContext, GpuResult, GpuTimer, MaterialVariant, PassName, Program, ShaderDef, ShaderLibrary,
    ShaderModules, shader_files, timed_compute_pass, wgpu,
};

use crate::Shading;
use crate::light::{LIGHT_POINT, LIGHT_SPOT, Light, LightSet, LightSettings, validate_lights};

/// The bind group index manylights' own lighting passes bind their inputs at: the
/// lights, the specular tables, and above this crate the lists (`cluster`) and the BVH
/// (`visibility`); an engine picks its own for each.
pub const MANYLIGHTS_GROUP: u32 = 3;

/// The light animation's timed pass.
pub const ANIMATE_PASS: PassName = PassName::new("animate lights");

/// This crate's WGSL: the GPU light (`light_set.wgsl`), the shading model every pipeline
/// evaluates a light with (`shading.wgsl`, its BRDFs in `brdf.wgsl`), the hashes (`hash.wgsl`) and the animation pass
/// (`animate.wgsl`).
pub static SHADERS: ShaderModules = ShaderModules {
    owner: "lights",
    files: shader_files![
        "lights/lighting_group.wgsl",
        "lights/light_set.wgsl",
        "lights/area.wgsl",
        "lights/brdf.wgsl",
        "lights/shading.wgsl",
        "lights/specular_albedo.wgsl",
        "lights/hash.wgsl",
        "lights/animate.wgsl",
        "lights/reference_terms.wgsl",
        "lights/reference.wgsl",
        "lights/pbr_for_engines.wgsl",
    ],
    uses: &[&manylights_gpu::shaders::SHADERS],
    constants: shader_constants,
};

/// The constants this crate's WGSL reads (`#NAME`): light kinds, falloff modes and the
/// animation's workgroup size.
fn shader_constants() -> Vec<(String, ShaderDef)> {
    use crate::Falloff;
    let constants = [
        ("LIGHT_POINT", ShaderDef::UInt(crate::light::LIGHT_POINT)),
        ("LIGHT_SPOT", ShaderDef::UInt(LIGHT_SPOT)),
        ("LIGHT_SPHERE", ShaderDef::UInt(crate::light::LIGHT_SPHERE)),
        ("LIGHT_RECT", ShaderDef::UInt(crate::light::LIGHT_RECT)),
        (
            "LIGHT_TRIANGLE",
            ShaderDef::UInt(crate::light::LIGHT_TRIANGLE),
        ),
        (
            "FALLOFF_WINDOWED_INVERSE_SQUARE",
            ShaderDef::UInt(Falloff::WindowedInverseSquare.shader_mode()),
        ),
        (
            "FALLOFF_REFERENCE_PROJECTS",
            ShaderDef::UInt(Falloff::ReferenceProjects.shader_mode()),
        ),
        (
            "FALLOFF_INVERSE_SQUARE",
            ShaderDef::UInt(Falloff::InverseSquare.shader_mode()),
        ),
        ("ANIMATE_WORKGROUP_SIZE", ShaderDef::UInt(WORKGROUP_SIZE)),
        (
            "SPECULAR_ALBEDO_ROUGHNESS_CELLS",
            ShaderDef::UInt(crate::specular_albedo::ROUGHNESS_NODES as u32 - 1),
        ),
        (
            "LTC_VIEW_CELLS",
            ShaderDef::UInt(crate::ltc::VIEW_NODES as u32 - 1),
        ),
        ("LTC_FIRST_TEXEL", ShaderDef::UInt(ALBEDO_TEXELS)),
        // Our lighting passes' group; an engine's BRDF program sets its own (`pbr_program`).
        (
            "SPECULAR_TABLES_GROUP",
            ShaderDef::UInt(crate::MANYLIGHTS_GROUP),
        ),
    ];
    constants
        .into_iter()
        .map(|(name, value)| (name.to_string(), value))
        .collect()
}

/// The animation pass's program.
pub fn animate_program() -> Program {
    Program::new("animate_lights", &SHADERS, "lights/animate.wgsl")
}

/// The prefix of every name in [`pbr_wgsl`]'s source (`manylights_pbr_surface`, ...).
pub const PBR_WGSL_PREFIX: &str = "manylights_";

/// Our BRDF as an engine's own light loop calls it (`lights/pbr_for_engines.wgsl`):
/// glTF's metallic-roughness for point and spot lights, as our pipelines shade them, with
/// its one binding ([`SpecularTables`]) at the engine's `group`.
pub fn pbr_program(group: u32) -> Program {
    Program::new("pbr_for_engines", &SHADERS, "lights/pbr_for_engines.wgsl")
        .with_shading(Shading::Pbr)
        .with_def("SPECULAR_TABLES_GROUP", ShaderDef::UInt(group))
        // The BRDF alone: the loop's light (its cone, an area's extent) is the engine's.
        .with_def("POINT_LIGHTS_ONLY", ShaderDef::Bool(true))
        .with_def("NO_AREA_LIGHTS", ShaderDef::Bool(true))
}

/// Our BRDF for an engine's own shader, as one self-contained WGSL source (no
/// `#import`s, no shader defs) with every name prefixed by [`PBR_WGSL_PREFIX`]; it goes
/// beside the lists' WGSL (`cluster::ListedLights::wgsl`) in the engine's module. Its one
/// binding is the specular fits' table the energy-conserving diffuse reads: a
/// [`SpecularTables`] at `group` (the engine's choice), binding
/// [`SpecularTables::BINDING`], in a bind group of the engine's own
/// ([`SpecularTables::layout_entry`], [`SpecularTables::binding`]). Once per pixel, `manylights_pbr_surface(position, normal,
/// view_dir, base_color, metallic, roughness)` (world space, unit vectors, `view_dir` from
/// the point to the eye); in the loop, `manylights_pbr_reflected(surface, view_dir, l)`,
/// the BRDF times n.l for light from the unit direction `l`, which the engine multiplies
/// by the light's colour, intensity, falloff and cone:
///
/// ```wgsl
/// let surface = manylights_pbr_surface(world, normal, view_dir, base_color, metallic, roughness);
/// radiance += light.color * light.intensity * falloff * manylights_pbr_reflected(surface, view_dir, l);
/// ```
pub fn pbr_wgsl(library: &ShaderLibrary, group: u32) -> GpuResult<String> {
    library
        .compose(&pbr_program(group), MaterialVariant::default())?
        .to_wgsl(PBR_WGSL_PREFIX)
}

/// Mirrors `AnimationParams` in `shaders/lights/animate.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct AnimationUniform {
    box_min: [f32; 4],
    box_max: [f32; 4],
    noise_time: f32,
    radius: f32,
    wander: f32,
    seed: u32,
    count: u32,
    _pad: [u32; 3],
}

/// Which kinds of light a buffer holds: a light loop leaves out the code of the kinds that
/// are absent (animation moves lights, never changes their kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct LightKinds {
    /// Any light is a spot or an area light: without, the cone's and the areas' code is
    /// left out.
    pub shaped: bool,
    /// Any light is an area light: without, the areas' code is left out.
    pub area: bool,
}

impl LightKinds {
    /// The kinds among `lights`.
    pub fn of(lights: &[Light]) -> Self {
        Self {
            shaped: lights.iter().any(|light| light.kind != LIGHT_POINT),
            area: lights.iter().any(Light::is_area),
        }
    }

    /// Every kind, for a buffer no loop is specialised by.
    pub const ANY: Self = Self {
        shaped: true,
        area: true,
    };

    /// The kinds of either.
    pub fn union(self, other: Self) -> Self {
        Self {
            shaped: self.shaped || other.shaped,
            area: self.area || other.area,
        }
    }
}

/// The light storage buffer (read by shading, written by animation).
#[derive(Debug)]
pub struct GpuLights {
    pub buffer: wgpu::Buffer,
    pub count: u32,
    /// The animation moves lights `0..animated` (the generated ones); any after them (a
    /// scene's own lights) stay where they were uploaded. All of them after `upload`.
    pub animated: u32,
    /// The kinds of light it holds: shading programs leave out the code of those absent.
    pub kinds: LightKinds,
}

impl GpuLights {
    /// Uploads a generated light set, all of whose lights the animation moves (at least
    /// one slot is allocated: wgpu refuses empty bindings).
    pub fn upload(context: &GpuContext, lights: &LightSet) -> GpuResult<Self> {
        let mut uploaded = Self::new(context, &lights.lights)?;
        uploaded.animated = uploaded.count;
        Ok(uploaded)
    }

    /// Uploads an engine's own lights (any mix of [`Light::point`], [`Light::spot`] and the
    /// area shapes), which no animation of ours moves: the engine changes them with
    /// [`GpuLights::write`]. Lights with a non-finite field, a radius that is not positive
    /// or a malformed shape are refused with the light's index ([`validate_lights`]).
    pub fn new(context: &GpuContext, lights: &[Light]) -> GpuResult<Self> {
        validate_lights(lights, 0).map_err(refused_lights)?;
        let size = (lights.len().max(1) * std::mem::size_of::<Light>()) as u64;
        context.check_buffer_size(
            &format!("light buffer ({} lights)", lights.len()),
            size,
            true,
        )?;
        let buffer = context.scoped("creating the light buffer", || {
            context.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lights"),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        })?;
        context
            .queue
            .write_buffer(&buffer, 0, bytemuck::cast_slice(lights));
        Ok(Self {
            buffer,
            count: lights.len() as u32,
            animated: 0,
            kinds: LightKinds::of(lights),
        })
    }

    /// Replaces lights `first..first + lights.len()` (an engine's per-frame update: only
    /// the range that changed is written, through the queue, before the frame's
    /// submission). The count stays; a range past it, or a light that [`validate_lights`]
    /// refuses (named by its index in the whole buffer), is refused and nothing is written.
    /// A light that becomes a spot or an area light turns its kind on in
    /// [`GpuLights::kinds`], so the next frame's programs include its
    /// code (they are never turned off here: the code they add shades points exactly).
    pub fn write(&mut self, context: &GpuContext, first: u32, lights: &[Light]) -> GpuResult<()> {
        let end = first as u64 + lights.len() as u64;
        if end > self.count as u64 {
            return Err(manylights_gpu::GpuError::InvalidInput {
                what: "lights".into(),
                problem: format!(
                    "writing lights {first}..{end} past the {} lights uploaded (upload a new \
                     GpuLights to change the count)",
                    self.count
                ),
            });
        }
        validate_lights(lights, first as usize).map_err(refused_lights)?;
        let offset = first as u64 * std::mem::size_of::<Light>() as u64;
        context
            .queue
            .write_buffer(&self.buffer, offset, bytemuck::cast_slice(lights));
        self.kinds = self.kinds.union(LightKinds::of(lights));
        Ok(())
    }

    /// Reads the lights back (tests, the accuracy lab).
    pub fn read(&self, context: &GpuContext) -> GpuResult<Vec<Light>> {
        manylights_gpu::block_on(self.read_async(context))
    }

    /// [`GpuLights::read`] without blocking.
    pub async fn read_async(&self, context: &GpuContext) -> GpuResult<Vec<Light>> {
        let mut lights: Vec<Light> =
            manylights_gpu::targets::read_buffer_async(context, &self.buffer).await?;
        lights.truncate(self.count as usize);
        Ok(lights)
    }
}

/// A light refused by [`validate_lights`], as the GPU side's error.
fn refused_lights(error: crate::LightError) -> manylights_gpu::GpuError {
    manylights_gpu::GpuError::InvalidInput {
        what: "lights".into(),
        problem: error.to_string(),
    }
}

/// The animation compute pass.
#[derive(Debug)]
pub struct LightAnimator {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    bind_group: manylights_gpu::binding::CachedBindGroup,
}

/// One frame's animation, prepared: its parameters written, the lights' group built.
#[derive(Debug)]
pub struct PreparedAnimation<'a> {
    animator: &'a LightAnimator,
    bind_group: wgpu::BindGroup,
    /// How many lights move (the rest were placed by hand).
    animated: u32,
}

/// Threads per workgroup in `animate.wgsl`.
const WORKGROUP_SIZE: u32 = 64;

/// Texels of the albedo fit per row of [`SpecularTables`] (A's six coefficients and B's).
const ALBEDO_TEXELS: u32 = 3;

impl LightAnimator {
    pub fn new(context: &GpuContext, library: &ShaderLibrary) -> GpuResult<Self> {
        let device = &context.device;
        let module =
            library.create_module(context, &animate_program(), MaterialVariant::default())?;
        let manylights_gpu::binding::ComputePasses {
            layout,
            pipelines: [pipeline],
        } = manylights_gpu::binding::ComputePasses::new(
            context,
            &module,
            "light animation",
            &[],
            &[
                manylights_gpu::binding::uniform_entry(0, wgpu::ShaderStages::COMPUTE),
                manylights_gpu::binding::storage_entry(1, wgpu::ShaderStages::COMPUTE, false),
            ],
            ["animate"],
        )?;
        let uniform = manylights_gpu::binding::uniform_buffer(
            device,
            "light animation params",
            std::mem::size_of::<AnimationUniform>(),
        );
        Ok(Self {
            pipeline,
            layout,
            uniform,
            bind_group: Default::default(),
        })
    }

    /// Prepares the pass that moves every light of `settings` to its position at `time`.
    pub fn prepare(
        &mut self,
        context: &GpuContext,
        lights: &GpuLights,
        settings: &LightSettings,
        time: f32,
    ) -> PreparedAnimation<'_> {
        let params = &settings.animation;
        let uniform = AnimationUniform {
            box_min: params.bounds.min.extend(0.0).to_array(),
            box_max: params.bounds.max.extend(0.0).to_array(),
            noise_time: params.noise_time(time),
            radius: settings.radius.radius(settings.intensity),
            wander: params.wander,
            seed: settings.seed,
            count: lights.animated.min(lights.count),
            _pad: [0; 3],
        };
        context
            .queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let bind_group = self.bind_group.get(
            context,
            "light animation",
            &self.layout,
            manylights_gpu::binding::buffers_in_order([&self.uniform, &lights.buffer]),
        );
        PreparedAnimation {
            animator: self,
            bind_group,
            animated: lights.animated.min(lights.count),
        }
    }
}

impl PreparedAnimation<'_> {
    /// Records the animation pass.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, timer: Option<&mut GpuTimer>) {
        let mut pass = timed_compute_pass(encoder, timer, ANIMATE_PASS);
        pass.set_pipeline(&self.animator.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        // `GpuLights::upload` checked that this fits one dispatch dimension.
        let groups = self.animated.div_ceil(WORKGROUP_SIZE);
        if groups > 0 {
            pass.dispatch_workgroups(groups, 1, 1);
        }
    }
}

#[cfg(test)]
mod layout_tests {
    use super::{AnimationUniform, animate_program};
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn animation_uniform_matches_wgsl() {
        assert_wgsl_layout!(
            animate_program(),
            "lights/animate.wgsl",
            AnimationParams
                == AnimationUniform {
                    box_min: box_min,
                    box_max: box_max,
                    noise_time: noise_time,
                    radius: radius,
                    wander: wander,
                    seed: seed,
                    count: count,
                    _pad0: _pad,
                    _pad1: _pad + 4,
                    _pad2: _pad + 8,
                }
        );
    }
}

/// PBR's specular fits on the GPU: a sampled `Rgba32Uint` texture of f32 values every
/// lighting pass binds at group 3 (an engine's shader with our BRDF, [`pbr_wgsl`], at
/// its own), binding [`SpecularTables::BINDING`]
/// (`shaders/lights/specular_albedo.wgsl`). Each row is one roughness node of both fits:
/// the albedo's coefficients ([`crate::specular_albedo`], three texels), then the
/// linearly transformed cosines' inverse matrices ([`crate::ltc`], one texel per view
/// node). 18 KiB, made once per device.
#[derive(Debug)]
pub struct SpecularTables {
    view: wgpu::TextureView,
}

impl SpecularTables {
    /// The binding in the lighting passes' group 3 (after the BVH's), and in the engine's
    /// group for our BRDF ([`pbr_wgsl`]).
    pub const BINDING: u32 = crate::lighting_group::SPECULAR_TABLES;

    /// Texels per row: the albedo fit's three, then the matrices'.
    pub const SIZE: (u32, u32) = (
        ALBEDO_TEXELS + crate::ltc::VIEW_NODES as u32,
        crate::specular_albedo::ROUGHNESS_NODES as u32,
    );

    /// The tables on `context`'s device, made once per device.
    pub fn new(context: &GpuContext) -> GpuResult<Self> {
        let albedo = crate::specular_albedo::SpecularAlbedoFit::committed().texels();
        let matrices = crate::ltc::LtcTable::committed().texels();
        let texels: Vec<[u32; 4]> = albedo
            .chunks_exact(ALBEDO_TEXELS as usize)
            .zip(matrices.chunks_exact(crate::ltc::VIEW_NODES))
            .flat_map(|(albedo, matrices)| albedo.iter().chain(matrices).copied())
            .collect();
        let target = manylights_gpu::Target::sampled_with_data(
            context,
            "specular fits",
            Self::SIZE,
            wgpu::TextureFormat::Rgba32Uint,
            bytemuck::cast_slice(&texels),
        )?;
        Ok(Self { view: target.view })
    }

    /// The layout entry of [`SpecularTables::BINDING`].
    pub fn layout_entry(visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
        wgpu::BindGroupLayoutEntry {
            binding: Self::BINDING,
            visibility,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        }
    }

    /// The resource of [`SpecularTables::layout_entry`], by binding.
    pub fn binding(&self) -> (u32, wgpu::BindingResource<'_>) {
        (
            Self::BINDING,
            wgpu::BindingResource::TextureView(&self.view),
        )
    }
}

#[cfg(test)]
mod pbr_for_engines_tests {
    /// The BRDF an engine gets is one source that declares only the specular tables, at
    /// the engine's group (none of our camera's or materials' bindings), and names each item with the prefix.
    #[test]
    fn the_engines_brdf_binds_only_its_table_at_the_engines_group_and_is_prefixed() {
        let wgsl = super::pbr_wgsl(&manylights_gpu::ShaderLibrary::Embedded, 5).expect("wgsl");
        let module = naga::front::wgsl::parse_str(&wgsl).expect("the source parses back");
        let bindings: Vec<_> = module
            .global_variables
            .iter()
            .map(|(_, global)| (global.name.clone().unwrap_or_default(), global.binding))
            .collect();
        let table = naga::ResourceBinding {
            group: 5,
            binding: super::SpecularTables::BINDING,
        };
        assert_eq!(
            bindings,
            [("manylights_specular_tables".to_string(), Some(table))],
            "{wgsl}"
        );
        for name in ["fn manylights_pbr_surface(", "fn manylights_pbr_reflected("] {
            assert!(wgsl.contains(name), "{name} missing:\n{wgsl}");
        }
        assert!(!wgsl.contains("X_naga_oil"), "{wgsl}");
    }

    /// An engine that composes with naga_oil imports the BRDF unprefixed from its own
    /// composer (`ShaderLibrary::add_to_composer`): its module validates and binds the
    /// engine's camera and our table at the engine's group, nothing else.
    #[test]
    fn an_engine_imports_our_brdf_into_its_own_naga_oil_composer() {
        use manylights_gpu::naga_oil::compose::{Composer, NagaModuleDescriptor};
        let mut composer = Composer::default();
        let defs = manylights_gpu::ShaderLibrary::Embedded
            .add_to_composer(&mut composer, &super::pbr_program(2))
            .expect("our BRDF in the engine's composer");
        let engine_shader = r#"
#import manylights::lights::pbr_for_engines::{pbr_surface, pbr_reflected}

@group(0) @binding(0) var<uniform> engine_eye: vec4<f32>;

@fragment
fn fs_main(@location(0) world: vec3<f32>, @location(1) normal: vec3<f32>) -> @location(0) vec4<f32> {
    let view_dir = normalize(engine_eye.xyz - world);
    let surface = pbr_surface(world, normal, view_dir, vec3<f32>(0.8), 0.0, 0.5);
    return vec4<f32>(pbr_reflected(surface, view_dir, vec3<f32>(0.0, 1.0, 0.0)), 1.0);
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
        let mut bindings: Vec<(u32, u32)> = (module.global_variables.iter())
            .filter_map(|(_, global)| global.binding.as_ref())
            .map(|binding| (binding.group, binding.binding))
            .collect();
        bindings.sort_unstable();
        assert_eq!(bindings, [(0, 0), (2, super::SpecularTables::BINDING)]);
    }
}
