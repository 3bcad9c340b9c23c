//! The post passes driven directly, on frames the test writes (no scene, no pipeline), so
//! that their f64 twins (`taa_twin.rs`, `bloom_twin.rs`) can be given exactly the same
//! input and every pixel compared.

use glam::{Mat4, Vec3};
use manylights_gpu::targets::{RenderTargets, read_f32_rgba};
use manylights_gpu::timer::GpuTimer;
use manylights_gpu::view::{ViewBinding, ViewUniform};
use manylights_gpu::{Bloom, GpuContext, ShaderLibrary, TemporalAntiAliasing, wgpu};

/// An RGB image, row-major, in f64 (the twins' and the tests' working type).
pub type Image = Vec<[f64; 3]>;

/// One device's post passes over targets of one size.
pub struct PostBench {
    pub context: GpuContext,
    pub targets: RenderTargets,
    pub view: ViewBinding,
    /// Exposure state all zeros: the passes read an exposure of 1.
    exposure: wgpu::Buffer,
    pub taa: TemporalAntiAliasing,
    pub bloom: Bloom,
}

impl PostBench {
    pub fn new(size: (u32, u32)) -> PostBench {
        let context = manylights_tests::gpu();
        // The shaders a mutant run points at (`MANYLIGHTS_SHADER_DIR`), else the embedded.
        let library = ShaderLibrary::from_env();
        let targets = RenderTargets::new(&context, size).expect("targets");
        let view = ViewBinding::new(&context);
        let exposure = context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("test exposure state"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let taa = TemporalAntiAliasing::new(&context, &library, &view.layout).expect("taa");
        let bloom = Bloom::new(&context, &library).expect("bloom");
        PostBench {
            context,
            targets,
            view,
            exposure,
            taa,
            bloom,
        }
    }

    pub fn size(&self) -> (u32, u32) {
        self.targets.size
    }

    /// Writes `image` into the HDR target (as half floats) and clears the depth target to
    /// `depth` (a plane facing the camera).
    pub fn write_frame(&self, image: &Image, depth: f32) {
        let (width, height) = self.size();
        let texels: Vec<half::f16> = image
            .iter()
            .flat_map(|p| [p[0], p[1], p[2], 1.0])
            .map(half::f16::from_f64)
            .collect();
        self.context.queue.write_texture(
            self.targets.hdr.texture.as_image_copy(),
            &texels
                .iter()
                .flat_map(|t| t.to_le_bytes())
                .collect::<Vec<u8>>(),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(width * 8),
                rows_per_image: Some(height),
            },
            wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
        );
        let mut encoder = self
            .context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("test depth plane"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.targets.depth.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(depth),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        self.context.queue.submit([encoder.finish()]);
    }

    /// The HDR target as f64 RGB.
    pub fn read_hdr(&self) -> Image {
        read_f32_rgba(&self.context, &self.targets.hdr.texture)
            .expect("hdr")
            .into_iter()
            .map(|p| [f64::from(p[0]), f64::from(p[1]), f64::from(p[2])])
            .collect()
    }

    /// One frame of temporal anti-aliasing over what [`PostBench::write_frame`] wrote, seen
    /// through `view`; its result.
    pub fn taa_frame(&mut self, view: &ViewUniform) -> Image {
        self.view.update(&self.context, view);
        let mut timer = GpuTimer::new(&self.context);
        let mut encoder = self
            .context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let errors = self.context.scoped("a test's taa frame", || {
            let prepared = self
                .taa
                .prepare(&self.context, &self.targets, &self.exposure)
                .expect("taa prepared");
            prepared.record(&mut encoder, &self.view.bind_group, &mut timer);
        });
        errors.expect("the taa pass is valid");
        self.context.queue.submit([encoder.finish()]);
        self.read_hdr()
    }

    /// Bloom of `strength` over what [`PostBench::write_frame`] wrote; its result.
    pub fn bloom_frame(&mut self, strength: f32) -> Image {
        let mut timer = GpuTimer::new(&self.context);
        let mut encoder = self
            .context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let errors = self.context.scoped("a test's bloom frame", || {
            let prepared = self
                .bloom
                .prepare(&self.context, &self.targets, &self.exposure, strength)
                .expect("bloom prepared")
                .expect("the frame is large enough for bloom");
            prepared.record(&mut encoder, &mut timer);
        });
        errors.expect("the bloom passes are valid");
        self.context.queue.submit([encoder.finish()]);
        self.read_hdr()
    }
}

/// The camera every post test looks through: at the origin looking down -z, 60 degrees
/// vertically, depth 0..1 (forward), near 0.1, far 100.
pub fn test_view(size: (u32, u32)) -> ViewUniform {
    let aspect = size.0 as f32 / size.1 as f32;
    let proj = glam::camera::rh::proj::directx::perspective(60f32.to_radians(), aspect, 0.1, 100.0);
    ViewUniform::new(Mat4::IDENTITY, proj, Vec3::ZERO, size, 0.1, 100.0)
}

/// The NDC depth of the plane facing [`test_view`]'s camera at `distance` along its axis.
pub fn plane_depth(view: &ViewUniform, distance: f32) -> f32 {
    let clip = Mat4::from_cols_array_2d(&view.proj) * glam::Vec4::new(0.0, 0.0, -distance, 1.0);
    clip.z / clip.w
}

/// Where `got` differs from `want` by more than `tolerance(pixel)` (pixel and channel
/// index, values), at most `limit` of them, and how many in all.
pub fn differing(
    got: &Image,
    want: &Image,
    tolerance: impl Fn(usize) -> f64,
    limit: usize,
) -> (usize, Vec<String>) {
    let mut count = 0;
    let mut examples = Vec::new();
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        let bound = tolerance(i);
        for c in 0..3 {
            if (g[c] - w[c]).abs() > bound || !g[c].is_finite() {
                count += 1;
                if examples.len() < limit {
                    examples.push(format!(
                        "pixel {i} channel {c}: {:.6} against {:.6} (allowed {bound:.2e})",
                        g[c], w[c]
                    ));
                }
            }
        }
    }
    (count, examples)
}
