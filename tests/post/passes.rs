//! The post passes driven directly, on frames the test writes (no scene, no pipeline), so
//! that their f64 twins (`taa_twin.rs`, `bloom_twin.rs`) can be given exactly the same
//! input and every pixel compared.

use manylights_gpu::targets::{RenderTargets, read_f32_rgba};
use manylights_gpu::timer::GpuTimer;
use manylights_gpu::view::{ViewBinding, ViewUniform};
use manylights_gpu::{Bloom, GpuContext, ShaderLibrary, TemporalAntiAliasing, wgpu};
use manylights_tests::synthetic::{Image, Plane, clear_depth, draw_depth_plane, write_rgba16};

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

    /// Writes `image` into the HDR target (as half floats) and clears the depth target to
    /// `depth` (a plane facing the camera).
    pub fn write_frame(&self, image: &Image, depth: f32) {
        let texels: Vec<[f64; 4]> = image.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect();
        write_rgba16(
            &self.context,
            &self.targets.hdr.texture,
            self.targets.size,
            &texels,
        );
        clear_depth(&self.context, &self.targets.depth.view, depth);
    }

    /// Writes `image` into the HDR target and draws `plane` into the depth target, seen
    /// through `view`; the depth the rasterizer wrote.
    pub fn write_frame_on(&self, image: &Image, view: &ViewUniform, plane: Plane) -> Vec<f64> {
        self.write_frame(image, 1.0);
        draw_depth_plane(&self.context, &self.targets.depth.texture, view, plane)
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
