//! The full-frame reference on the GPU (`shaders/lights/reference.wgsl`): every light at
//! every pixel of a surface capture, with the scene's BRDF and the unbounded (or a windowed)
//! falloff, in f32 with Neumaier's compensated summation. It reads what the f64 reference
//! ([`crate::reference`]) reads (a [`SurfaceImage`], the animated lights), so the two agree
//! wherever both run (`tests/naive/gpu_reference.rs` holds them to it); the f64 one decides where
//! they do not. Unlike the f64 reference it shades every pixel at any light count: the image
//! metrics (FLIP, error maps, seams) need whole frames.

use glam::DVec3;
use manylights_gpu::{
    GpuContext, GpuError, GpuResult, MaterialVariant, Program, ShaderLibrary, SurfaceImage, wgpu,
};

use crate::gpu::{GpuLights, SHADERS, SpecularTables};
use crate::reference::{Falloff, Shading};

/// The reference pass's program for `shading`'s BRDF.
pub fn reference_program(shading: Shading) -> Program {
    Program::new("gpu_reference", &SHADERS, "lights/reference.wgsl").with_shading(shading)
}

/// Threads per workgroup in `reference.wgsl` (one pixel each).
const WORKGROUP_SIZE: u32 = 64;

/// The most lights a dispatch over `pixels` pixels should loop over: a few milliseconds of
/// work on a fast GPU, and never past llvmpipe's loop limit.
pub fn lights_per_dispatch(pixels: u64) -> u32 {
    (EVALUATIONS_PER_DISPATCH / pixels.max(1)).clamp(1, MAX_LIGHTS_PER_DISPATCH) as u32
}

/// Light evaluations per dispatch, about: a million lights over a 1080p frame are 2e12, so
/// the work is cut into dispatches of a few milliseconds each on a fast GPU (and short
/// enough that no driver's watchdog sees one long kernel).
const EVALUATIONS_PER_DISPATCH: u64 = 1 << 28;

/// The most lights one dispatch loops over: llvmpipe (lavapipe's compiler) leaves any loop
/// after 65,535 iterations, silently (gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`, its guard
/// against endless loops); found by this pass's test, which saw 65,536 of 100,001 lights.
const MAX_LIGHTS_PER_DISPATCH: u64 = 65_535;

/// Mirrors `ReferenceParams` in `shaders/lights/reference.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ReferenceParams {
    origin: [f32; 4],
    camera: [f32; 4],
    width: u32,
    pixels: u32,
    first_light: u32,
    light_count: u32,
    falloff: u32,
    opaque_zero: u32,
    _pad: [u32; 2],
}

/// The reference's radiance for every pixel of a capture, in f64 (sum plus compensation,
/// plus the surface's emission); zero where the capture drew no surface.
#[derive(Debug, Clone)]
pub struct GpuReferenceImage {
    pub size: (u32, u32),
    pub radiance: Vec<DVec3>,
    /// Lights evaluated at each covered pixel.
    pub lights: u32,
}

impl GpuReferenceImage {
    /// The image as the HDR target's RGBA f32 (alpha 1), for the image metrics.
    pub fn to_rgba_f32(&self) -> Vec<[f32; 4]> {
        self.radiance
            .iter()
            .map(|c| [c.x as f32, c.y as f32, c.z as f32, 1.0])
            .collect()
    }
}

/// The compute pass of the full-frame reference, for one BRDF.
#[derive(Debug)]
pub struct GpuReference {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    shading: Shading,
}

impl GpuReference {
    pub fn new(context: &GpuContext, library: &ShaderLibrary, shading: Shading) -> GpuResult<Self> {
        let module = library.create_module(
            context,
            &reference_program(shading),
            MaterialVariant::default(),
        )?;
        let compute = wgpu::ShaderStages::COMPUTE;
        let storage = |binding, read_only| {
            manylights_gpu::binding::storage_entry(binding, compute, read_only)
        };
        let entries = [
            manylights_gpu::binding::uniform_entry(0, compute),
            storage(1, true),
            storage(2, true),
            storage(3, true),
            storage(4, true),
            storage(5, true),
            storage(6, false),
            storage(7, false),
            SpecularTables::layout_entry(compute),
        ];
        context.scoped("creating the GPU reference's pipeline", || {
            let layout =
                context
                    .device
                    .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                        label: Some("gpu reference"),
                        entries: &entries,
                    });
            // Group 3, as in every lighting pass (the specular-albedo table's binding is
            // declared there); groups 0 to 2 are not used.
            let pipeline_layout =
                context
                    .device
                    .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                        label: Some("gpu reference"),
                        bind_group_layouts: &[None, None, None, Some(&layout)],
                        immediate_size: 0,
                    });
            let pipeline = context.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("gpu reference"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("reference"),
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

    /// Shades every pixel of `surface` with every light of `lights`, seen from `camera`
    /// (world space), with `falloff`.
    pub async fn render_async(
        &self,
        context: &GpuContext,
        surface: &SurfaceImage,
        camera: DVec3,
        lights: &GpuLights,
        table: &SpecularTables,
        falloff: Falloff,
    ) -> GpuResult<GpuReferenceImage> {
        if surface.shading != self.shading {
            return Err(GpuError::Unsupported(format!(
                "the GPU reference was built for {} and the surface captured for {}",
                self.shading, surface.shading
            )));
        }
        let buffers = ReferenceBuffers::new(context, surface)?;
        let bind_group = context.scoped("binding the GPU reference", || {
            manylights_gpu::binding::bind_group(
                context,
                "gpu reference",
                &self.layout,
                manylights_gpu::binding::buffers_in_order(
                    std::iter::once(&buffers.params)
                        .chain(buffers.capture.in_order())
                        .chain([&lights.buffer, &buffers.sums, &buffers.compensations]),
                )
                .chain([table.binding()]),
            )
        })?;
        let mut params = ReferenceParams {
            origin: surface.origin.as_vec3().extend(0.0).to_array(),
            camera: (camera - surface.origin).as_vec3().extend(0.0).to_array(),
            width: surface.size.0,
            pixels: surface.position.len() as u32,
            first_light: 0,
            light_count: 0,
            falloff: falloff.shader_mode(),
            opaque_zero: 0,
            _pad: [0; 2],
        };
        context.scoped("running the GPU reference", || {
            self.dispatch_every_light(
                context,
                &buffers.params,
                &bind_group,
                &mut params,
                lights.count,
            );
        })?;
        let sums = manylights_gpu::targets::read_buffer_async(context, &buffers.sums).await?;
        let compensations =
            manylights_gpu::targets::read_buffer_async(context, &buffers.compensations).await?;
        Ok(GpuReferenceImage {
            size: surface.size,
            radiance: radiance(surface, &sums, &compensations),
            lights: lights.count,
        })
    }

    /// Submits one dispatch per batch of lights, each adding its lights to every pixel's
    /// running sum (`params` gets each batch's range).
    fn dispatch_every_light(
        &self,
        context: &GpuContext,
        params_buffer: &wgpu::Buffer,
        bind_group: &wgpu::BindGroup,
        params: &mut ReferenceParams,
        light_count: u32,
    ) {
        let pixels = u64::from(params.pixels);
        if pixels == 0 {
            return;
        }
        let per_dispatch = lights_per_dispatch(pixels);
        let height = params.pixels / params.width;
        while params.first_light < light_count {
            params.light_count = per_dispatch.min(light_count - params.first_light);
            context
                .queue
                .write_buffer(params_buffer, 0, bytemuck::bytes_of(params));
            let mut encoder =
                context
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("gpu reference"),
                    });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("gpu reference"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(3, bind_group, &[]);
                pass.dispatch_workgroups(params.width.div_ceil(WORKGROUP_SIZE), height, 1);
            }
            context.queue.submit([encoder.finish()]);
            params.first_light += params.light_count;
        }
    }
}

/// A surface capture's attributes as the GPU references read them: four storage buffers
/// of one RGBA32F value a pixel (position, normal and lobe, albedo, specular), at
/// group 3 bindings 1 to 4.
#[derive(Debug)]
pub struct CaptureBuffers {
    pub positions: wgpu::Buffer,
    pub normals: wgpu::Buffer,
    pub albedos: wgpu::Buffer,
    pub speculars: wgpu::Buffer,
}

impl CaptureBuffers {
    pub fn upload(context: &GpuContext, surface: &SurfaceImage) -> GpuResult<Self> {
        let input = |label: &str, data: &[[f32; 4]]| {
            let uploaded = pixel_buffer(context, label, data.len(), wgpu::BufferUsages::COPY_DST)?;
            context
                .queue
                .write_buffer(&uploaded, 0, bytemuck::cast_slice(data));
            Ok::<_, GpuError>(uploaded)
        };
        context.scoped("uploading the surface capture", || {
            Ok(Self {
                positions: input("reference positions", &surface.position)?,
                normals: input("reference normals", &surface.normal_lobe)?,
                albedos: input("reference albedos", &surface.albedo)?,
                speculars: input("reference speculars", &surface.specular)?,
            })
        })?
    }

    /// The four buffers in binding order.
    pub fn in_order(&self) -> [&wgpu::Buffer; 4] {
        [
            &self.positions,
            &self.normals,
            &self.albedos,
            &self.speculars,
        ]
    }
}

/// A storage buffer of one RGBA32F value for each of `pixels`, checked against the
/// device's limits.
pub fn pixel_buffer(
    context: &GpuContext,
    label: &str,
    pixels: usize,
    usage: wgpu::BufferUsages,
) -> GpuResult<wgpu::Buffer> {
    let bytes = (pixels * 16) as u64;
    context.check_buffer_size(label, bytes, true)?;
    Ok(context.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | usage,
        mapped_at_creation: false,
    }))
}

/// The pass's buffers: the surface capture's attributes uploaded, the running sums and
/// compensations, the parameters.
struct ReferenceBuffers {
    capture: CaptureBuffers,
    sums: wgpu::Buffer,
    compensations: wgpu::Buffer,
    params: wgpu::Buffer,
}

impl ReferenceBuffers {
    fn new(context: &GpuContext, surface: &SurfaceImage) -> GpuResult<Self> {
        let pixels = surface.position.len();
        let output = |label| pixel_buffer(context, label, pixels, wgpu::BufferUsages::COPY_SRC);
        let capture = CaptureBuffers::upload(context, surface)?;
        let sums = output("reference sums")?;
        let compensations = output("reference compensations")?;
        context.scoped("creating the GPU reference's buffers", || Self {
            capture,
            sums,
            compensations,
            params: manylights_gpu::binding::uniform_buffer(
                &context.device,
                "reference params",
                std::mem::size_of::<ReferenceParams>(),
            ),
        })
    }
}

/// Each pixel's radiance in f64: its sum plus its compensation, plus the surface's
/// emission; zero where the capture drew no surface.
fn radiance(surface: &SurfaceImage, sums: &[[f32; 4]], compensations: &[[f32; 4]]) -> Vec<DVec3> {
    let to_f64 = |v: [f32; 4]| DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]));
    (0..surface.position.len())
        .map(|i| {
            if surface.position[i][3] != 1.0 {
                return DVec3::ZERO;
            }
            let emission = surface.emission.get(i).copied().map_or(DVec3::ZERO, to_f64);
            to_f64(sums[i]) + to_f64(compensations[i]) + emission
        })
        .collect()
}

#[cfg(test)]
mod layout_tests {
    use super::{ReferenceParams, reference_program};
    use manylights_gpu::assert_wgsl_layout;

    #[test]
    fn reference_params_match_wgsl() {
        assert_wgsl_layout!(
            reference_program(crate::Shading::Pbr),
            "lights/reference.wgsl",
            ReferenceParams
                == ReferenceParams {
                    origin: origin,
                    camera: camera,
                    width: width,
                    pixels: pixels,
                    first_light: first_light,
                    light_count: light_count,
                    falloff: falloff,
                    opaque_zero: opaque_zero,
                    _pad: _pad,
                }
        );
    }
}
