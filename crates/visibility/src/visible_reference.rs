//! The full-frame reference with visibility on the GPU (`shaders/visibility/
//! visible_reference.wgsl`): every pixel of a surface capture lit by the lights its f64
//! shadow rays ([`crate::shadow_ray`]) reach, traced through the scene's BVH in compute.
//! Up to a ray budget every light gets its ray and the image is exact (the f64 reference's
//! [`shade_visible`](manylights_lights::reference::shade_visible) in compensated f32);
//! beyond it, independent samplers draw lights in proportion to their unshadowed term and
//! estimate the visible sum without bias, and each pixel gets its standard error from the
//! samplers' spread (the f64 samples' [`shade_visible_estimate`](
//! manylights_lights::reference::shade_visible_estimate) does the same at 256 pixels).
//! The estimate weighs lights by the unshadowed reference ([`GpuReferenceImage`]), so a
//! frame beyond the budget costs the unshadowed reference's light loop twice, plus rays.

use glam::DVec3;
use manylights_gpu::{
    GpuContext, GpuError, GpuResult, MaterialVariant, Program, ShaderDef, ShaderLibrary,
    SurfaceImage, wgpu,
};
use manylights_lights::gpu_reference::{CaptureBuffers, lights_per_dispatch, pixel_buffer};
use manylights_lights::{Falloff, GpuLights, GpuReferenceImage, Shading, SpecularTables};

use crate::GpuSceneBvh;

/// Independent samplers of the estimate: their spread is each pixel's standard error, with
/// 7 degrees of freedom.
pub const VISIBLE_REFERENCE_SAMPLERS: u32 = 8;

/// Threads per workgroup in `visible_reference.wgsl` (one pixel each).
const WORKGROUP_SIZE: u32 = 64;

/// Pixels a band: the samplers' running sums take 128 bytes a pixel, so a 1080p frame is
/// done in bands of 32 MB rather than one buffer of 265 MB.
const BAND_PIXELS: usize = 1 << 18;

/// The constants `visible_reference.wgsl` reads.
pub(crate) fn shader_defs() -> Vec<(String, ShaderDef)> {
    vec![(
        "VISIBLE_REFERENCE_SAMPLERS".to_string(),
        ShaderDef::UInt(VISIBLE_REFERENCE_SAMPLERS),
    )]
}

/// The pass's program for `shading`'s BRDF.
pub fn visible_reference_program(shading: Shading) -> Program {
    Program::new(
        "gpu_visible_reference",
        &crate::SHADERS,
        "visibility/visible_reference.wgsl",
    )
    .with_shading(shading)
}

/// The shadow rays the reference with visibility may spend at a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct VisibleReferenceRays {
    /// With at most this many lights every light that adds to a pixel gets its ray (the
    /// image is exact); with more, the samplers draw about this many between them.
    pub per_pixel: u32,
    /// Seeds the samplers' draws (the same seed, the same image).
    pub seed: u32,
}

impl VisibleReferenceRays {
    /// Whether `lights` are few enough to trace every ray.
    pub fn exact_for(&self, lights: u32) -> bool {
        lights <= self.per_pixel
    }
}

/// Mirrors `VisibleReferenceParams` in `visible_reference.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct VisibleReferenceParams {
    origin: [f32; 4],
    camera: [f32; 4],
    first_pixel: u32,
    band_pixels: u32,
    first_light: u32,
    light_count: u32,
    falloff: u32,
    opaque_zero: u32,
    rays_per_sampler: f32,
    seed: u32,
}

impl VisibleReferenceParams {
    /// The parameters of `inputs`' render, before its first band and batch of lights.
    fn new(inputs: &VisibleReferenceInputs<'_>, rays: VisibleReferenceRays, exact: bool) -> Self {
        let origin = inputs.surface.origin;
        Self {
            origin: origin.as_vec3().extend(0.0).to_array(),
            camera: (inputs.camera - origin).as_vec3().extend(0.0).to_array(),
            first_pixel: 0,
            band_pixels: 0,
            first_light: 0,
            light_count: 0,
            falloff: inputs.falloff.shader_mode(),
            opaque_zero: 0,
            rays_per_sampler: if exact {
                0.0
            } else {
                rays.per_pixel as f32 / VISIBLE_REFERENCE_SAMPLERS as f32
            },
            seed: rays.seed,
        }
    }
}

/// The reference with visibility for every pixel of a capture, in f64 (emission
/// included); zero where the capture drew no surface.
#[derive(Debug, Clone)]
pub struct GpuVisibleReferenceImage {
    pub size: (u32, u32),
    pub radiance: Vec<DVec3>,
    /// Each pixel's standard error per channel: zero where every ray was traced.
    pub standard_error: Vec<DVec3>,
    /// Whether every light's ray was traced at every pixel.
    pub exact: bool,
    /// Shadow rays traced in all.
    pub rays: u64,
}

impl GpuVisibleReferenceImage {
    /// Adds a band's pixels from its samplers' `estimates` and its `states` (the rays).
    fn add_band(
        &mut self,
        surface: &SurfaceImage,
        first_pixel: usize,
        states: &[[u32; 4]],
        estimates: &[[f32; 4]],
    ) {
        let samplers = VISIBLE_REFERENCE_SAMPLERS as usize;
        for (local, state) in states.iter().enumerate() {
            let pixel = first_pixel + local;
            if pixel >= surface.position.len() {
                break;
            }
            self.rays += u64::from(state[3]);
            let (radiance, error) = combine(
                &estimates[local * samplers..(local + 1) * samplers],
                self.exact,
            );
            let emission = surface
                .emission
                .get(pixel)
                .copied()
                .map_or(DVec3::ZERO, to_f64);
            let drawn = surface.position[pixel][3] == 1.0;
            self.radiance.push(if drawn {
                radiance + emission
            } else {
                DVec3::ZERO
            });
            self.standard_error
                .push(if drawn { error } else { DVec3::ZERO });
        }
    }

    /// The image as the HDR target's RGBA f32 (alpha 1), for the image metrics.
    pub fn to_rgba_f32(&self) -> Vec<[f32; 4]> {
        self.radiance
            .iter()
            .map(|c| [c.x as f32, c.y as f32, c.z as f32, 1.0])
            .collect()
    }
}

/// The compute pass of the reference with visibility, for one BRDF.
#[derive(Debug)]
pub struct GpuVisibleReference {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    shading: Shading,
}

/// What one render reads: the capture, the lights, the tree, the table.
#[derive(Debug)]
pub struct VisibleReferenceInputs<'a> {
    pub surface: &'a SurfaceImage,
    /// The eye, in world space.
    pub camera: DVec3,
    pub lights: &'a GpuLights,
    pub table: &'a SpecularTables,
    pub bvh: &'a GpuSceneBvh,
    pub falloff: Falloff,
    /// The same frame's unshadowed reference, which weighs the lights where the image is
    /// estimated (`None` where every ray is traced).
    pub unshadowed: Option<&'a GpuReferenceImage>,
}

impl GpuVisibleReference {
    pub fn new(context: &GpuContext, library: &ShaderLibrary, shading: Shading) -> GpuResult<Self> {
        let module = library.create_module(
            context,
            &visible_reference_program(shading),
            MaterialVariant::default(),
        )?;
        let compute = wgpu::ShaderStages::COMPUTE;
        let storage = |binding, read_only| {
            manylights_gpu::binding::storage_entry(binding, compute, read_only)
        };
        let entries: Vec<wgpu::BindGroupLayoutEntry> = [
            manylights_gpu::binding::uniform_entry(0, compute),
            storage(1, true),
            storage(2, true),
            storage(3, true),
            storage(4, true),
            storage(5, true),
            storage(6, false),
            storage(7, false),
        ]
        .into_iter()
        .chain(GpuSceneBvh::layout_entries(compute))
        .chain([SpecularTables::layout_entry(compute)])
        .collect();
        context.scoped("creating the GPU reference with visibility", || {
            let layout =
                context
                    .device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some("gpu visible reference"),
                        entries: &entries,
                    });
            // Group 3, where the BVH's and the table's bindings are declared.
            let pipeline_layout =
                context
                    .device
                    .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some("gpu visible reference"),
                        bind_group_layouts: &[None, None, None, Some(&layout)],
                        immediate_size: 0,
                    });
            let pipeline = context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("gpu visible reference"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("visible_reference"),
                compilation_options: Default::default(),
                cache: None,
            });
            Self {
                pipeline,
                layout,
                shading,
            }
        })
    }

    /// The reference with visibility of every pixel of `inputs.surface`, spending `rays`.
    pub async fn render_async(
        &self,
        context: &GpuContext,
        inputs: &VisibleReferenceInputs<'_>,
        rays: VisibleReferenceRays,
    ) -> GpuResult<GpuVisibleReferenceImage> {
        let surface = inputs.surface;
        if surface.shading != self.shading {
            return Err(GpuError::Unsupported(format!(
                "the GPU reference with visibility was built for {} and the surface captured for {}",
                self.shading, surface.shading
            )));
        }
        let exact = rays.exact_for(inputs.lights.count);
        let weights = estimate_weights(inputs, rays, exact)?;
        let pixels = surface.position.len();
        let band_pixels = pixels.clamp(1, BAND_PIXELS);
        let buffers = BandBuffers::new(context, surface, band_pixels)?;
        let bind_group = self.bind(context, &buffers, inputs)?;
        let mut params = VisibleReferenceParams::new(inputs, rays, exact);
        let mut image = GpuVisibleReferenceImage {
            size: surface.size,
            radiance: Vec::with_capacity(pixels),
            standard_error: Vec::with_capacity(pixels),
            exact,
            rays: 0,
        };
        for first_pixel in (0..pixels).step_by(band_pixels) {
            let band = band_pixels.min(pixels - first_pixel);
            buffers.start_band(context, weights.as_deref(), first_pixel, band);
            params.first_pixel = first_pixel as u32;
            params.band_pixels = band as u32;
            context.scoped("running the GPU reference with visibility", || {
                self.dispatch_every_light(context, &buffers, &bind_group, &mut params, inputs);
            })?;
            let (states, estimates) = buffers.read_band(context, first_pixel).await?;
            image.add_band(surface, first_pixel, &states, &estimates);
        }
        Ok(image)
    }

    fn bind(
        &self,
        context: &GpuContext,
        buffers: &BandBuffers,
        inputs: &VisibleReferenceInputs<'_>,
    ) -> GpuResult<wgpu::BindGroup> {
        context.scoped("binding the GPU reference with visibility", || {
            manylights_gpu::binding::bind_group(
                context,
                "gpu visible reference",
                &self.layout,
                manylights_gpu::binding::buffers_in_order(
                    std::iter::once(&buffers.params)
                        .chain(buffers.capture.in_order())
                        .chain([&inputs.lights.buffer, &buffers.states, &buffers.estimates]),
                )
                .chain(inputs.bvh.bindings())
                .chain([inputs.table.binding()]),
            )
        })
    }

    /// One band's dispatches: every light, a batch at a time (llvmpipe's loop limit, a
    /// few milliseconds each on a fast GPU), after its running sums are cleared.
    fn dispatch_every_light(
        &self,
        context: &GpuContext,
        buffers: &BandBuffers,
        bind_group: &wgpu::BindGroup,
        params: &mut VisibleReferenceParams,
        inputs: &VisibleReferenceInputs<'_>,
    ) {
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("clear visible reference"),
            });
        encoder.clear_buffer(&buffers.estimates, 0, None);
        context.queue.submit([encoder.finish()]);
        let per_dispatch = lights_per_dispatch(u64::from(params.band_pixels))
            .min(loop_limited_lights(context, inputs.bvh));
        let light_count = inputs.lights.count;
        params.first_light = 0;
        while params.first_light < light_count {
            params.light_count = per_dispatch.min(light_count - params.first_light);
            context
                .queue
                .write_buffer(&buffers.params, 0, bytemuck::bytes_of(params));
            let mut encoder =
                context
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("gpu visible reference"),
                    });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("gpu visible reference"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(3, bind_group, &[]);
                pass.dispatch_workgroups(params.band_pixels.div_ceil(WORKGROUP_SIZE), 1, 1);
            }
            context.queue.submit([encoder.finish()]);
            params.first_light += params.light_count;
        }
    }
}

/// The rays count's top bit in `visible_reference.wgsl`: the light loop stopped short.
const STOPPED_SHORT: u32 = 0x8000_0000;

/// llvmpipe (lavapipe's compiler) leaves a loop after 65,535 iterations, counting those of
/// the loops nested in it together with its own: measured here, where 1,500 lights with
/// rays through the cornell room's tree lost half their light, while the same dispatch
/// without rays (`lights::GpuReference`) keeps 65,535 lights.
const LLVMPIPE_LOOP_LIMIT: u32 = 65_535;

/// The most lights a dispatch may loop over on a CPU adapter: each light costs one
/// iteration, the samplers' two loops, and a traversal, which pops each of the tree's
/// nodes and tests each of its triangles at most once. Elsewhere, no limit.
fn loop_limited_lights(context: &GpuContext, bvh: &GpuSceneBvh) -> u32 {
    if context.adapter.get_info().device_type != wgpu::DeviceType::Cpu {
        return u32::MAX;
    }
    let per_light = 1 + 2 * VISIBLE_REFERENCE_SAMPLERS + bvh.node_count + bvh.triangle_count;
    (LLVMPIPE_LOOP_LIMIT / per_light).max(1)
}

/// The estimate's weights ([`light_weights`]), `None` where every ray is traced; refuses a
/// budget of no rays, and an estimate without the unshadowed reference of the capture.
fn estimate_weights(
    inputs: &VisibleReferenceInputs<'_>,
    rays: VisibleReferenceRays,
    exact: bool,
) -> GpuResult<Option<Vec<f32>>> {
    if rays.per_pixel == 0 {
        return Err(GpuError::Unsupported(
            "the reference with visibility needs at least one shadow ray a pixel".into(),
        ));
    }
    let surface = inputs.surface;
    match (exact, inputs.unshadowed) {
        (true, _) => Ok(None),
        (false, Some(unshadowed)) if unshadowed.radiance.len() == surface.position.len() => {
            Ok(Some(light_weights(surface, unshadowed)))
        }
        (false, _) => Err(GpuError::Unsupported(format!(
            "{} lights are more than {} rays a pixel: the estimate needs the frame's unshadowed reference, of the capture's size",
            inputs.lights.count, rays.per_pixel
        ))),
    }
}

/// W at each pixel, the estimate's scale: the brightest channel of the unshadowed
/// reflected light (emission left out). Any positive W keeps the estimate unbiased; this
/// one is within a factor 3 of the sum of each light's brightest channel, so the samplers
/// draw about the rays asked for, at most three times as many.
fn light_weights(surface: &SurfaceImage, unshadowed: &GpuReferenceImage) -> Vec<f32> {
    unshadowed
        .radiance
        .iter()
        .enumerate()
        .map(|(pixel, radiance)| {
            let emission = surface
                .emission
                .get(pixel)
                .copied()
                .map_or(DVec3::ZERO, to_f64);
            (*radiance - emission).max_element().max(0.0) as f32
        })
        .collect()
}

/// A pixel's radiance and standard error from its samplers' sums: exact, the first sum
/// plus its compensation; estimated, the samplers' mean and the standard error of it.
fn combine(sums: &[[f32; 4]], exact: bool) -> (DVec3, DVec3) {
    if exact {
        return (to_f64(sums[0]) + to_f64(sums[1]), DVec3::ZERO);
    }
    let count = sums.len() as f64;
    let mean = sums.iter().map(|s| to_f64(*s)).sum::<DVec3>() / count;
    let spread = sums
        .iter()
        .map(|s| (to_f64(*s) - mean) * (to_f64(*s) - mean))
        .sum::<DVec3>();
    (mean, (spread / (count * (count - 1.0))).map(f64::sqrt))
}

fn to_f64(v: [f32; 4]) -> DVec3 {
    DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
}

/// The pass's buffers: the capture, a band's states and running sums, the parameters.
struct BandBuffers {
    capture: CaptureBuffers,
    states: wgpu::Buffer,
    estimates: wgpu::Buffer,
    params: wgpu::Buffer,
}

impl BandBuffers {
    fn new(context: &GpuContext, surface: &SurfaceImage, band_pixels: usize) -> GpuResult<Self> {
        let output = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let samplers = VISIBLE_REFERENCE_SAMPLERS as usize;
        Ok(Self {
            capture: CaptureBuffers::upload(context, surface)?,
            states: pixel_buffer(context, "visible reference states", band_pixels, output)?,
            estimates: pixel_buffer(
                context,
                "visible reference estimates",
                band_pixels * samplers,
                output,
            )?,
            params: manylights_gpu::binding::uniform_buffer(
                &context.device,
                "visible reference params",
                std::mem::size_of::<VisibleReferenceParams>(),
            ),
        })
    }
}

impl BandBuffers {
    /// Starts the band of `band` pixels from `first_pixel`: x at 0, W from `weights`.
    fn start_band(
        &self,
        context: &GpuContext,
        weights: Option<&[f32]>,
        first_pixel: usize,
        band: usize,
    ) {
        let states: Vec<[u32; 4]> = (first_pixel..first_pixel + band)
            .map(|pixel| [0, 0, weights.map_or(0.0, |w| w[pixel]).to_bits(), 0])
            .collect();
        context
            .queue
            .write_buffer(&self.states, 0, bytemuck::cast_slice(&states));
    }

    /// The band's states and samplers' sums, once its dispatches are done; an error where
    /// a pixel's light loop stopped short.
    async fn read_band(
        &self,
        context: &GpuContext,
        first_pixel: usize,
    ) -> GpuResult<(Vec<[u32; 4]>, Vec<[f32; 4]>)> {
        let states: Vec<[u32; 4]> =
            manylights_gpu::targets::read_buffer_async(context, &self.states).await?;
        if let Some(local) = states.iter().position(|s| s[3] & STOPPED_SHORT != 0) {
            return Err(GpuError::Unsupported(format!(
                "the reference with visibility stopped short of its lights at pixel {} (a driver's loop limit: llvmpipe's is 65,535 iterations); use a smaller scene or fewer lights there",
                first_pixel + local
            )));
        }
        let estimates =
            manylights_gpu::targets::read_buffer_async(context, &self.estimates).await?;
        Ok((states, estimates))
    }
}

#[cfg(test)]
mod layout_tests {
    use super::{VisibleReferenceParams, visible_reference_program};
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn visible_reference_params_match_wgsl() {
        assert_wgsl_layout!(
            visible_reference_program(manylights_lights::Shading::Pbr),
            "visibility/visible_reference.wgsl",
            VisibleReferenceParams
                == VisibleReferenceParams {
                    origin: origin,
                    camera: camera,
                    first_pixel: first_pixel,
                    band_pixels: band_pixels,
                    first_light: first_light,
                    light_count: light_count,
                    falloff: falloff,
                    opaque_zero: opaque_zero,
                    rays_per_sampler: rays_per_sampler,
                    seed: seed,
                }
        );
    }
}
