//! Full-precision surface readback (`shaders/gpu/surface.wgsl`): world position, normal,
//! diffuse albedo, specular colour (or F0) and lobe of the fragment each pixel shows, as f32, for the f64
//! reference shading. Two passes of two Rgba32Float targets each.

use crate::context::GpuContext;
use crate::depth::DepthConvention;
use crate::error::GpuResult;
use crate::shaders::{Program, SHADERS, ShaderLibrary};
use manylights_scene::Shading;

/// The surface capture's program (`shaders/gpu/surface.wgsl`) building surfaces for
/// `shading`.
pub fn program(shading: Shading) -> Program {
    Program::shading_materials("surface_dump", &SHADERS, "gpu/surface.wgsl").with_shading(shading)
}
use crate::targets::{Target, read_f32_rgba_async};
use crate::upload::{GpuScene, PipelineKey, ScenePipelineDesc};
use crate::view::ViewBinding;

const SURFACE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// What each pixel shows, in full precision. `position[3]` is 1 where a surface was drawn
/// and 0 over the background.
#[derive(Debug, Clone)]
pub struct SurfaceImage {
    pub size: (u32, u32),
    /// World position the positions below are relative to (camera-relative rendering):
    /// the world position of a pixel is `origin + position`.
    pub origin: glam::DVec3,
    pub position: Vec<[f32; 4]>,
    /// Normal (xyz) and lobe (w: Blinn-Phong's exponent or PBR's perceptual roughness).
    pub normal_lobe: Vec<[f32; 4]>,
    /// Diffuse albedo (rgb) and alpha.
    pub albedo: Vec<[f32; 4]>,
    /// Specular colour (Blinn-Phong) or F0 (PBR).
    pub specular: Vec<[f32; 4]>,
    /// The reflectance model the surfaces were built for, and are shaded with.
    pub shading: Shading,
    /// Emitted radiance (rgb); zeros when no material of the scene emits.
    pub emission: Vec<[f32; 4]>,
}

#[derive(Debug)]
pub struct SurfacePass {
    geometry: Vec<(PipelineKey, wgpu::RenderPipeline)>,
    material: Vec<(PipelineKey, wgpu::RenderPipeline)>,
    /// Only for scenes with emissive materials.
    emission: Option<Vec<(PipelineKey, wgpu::RenderPipeline)>>,
    depth: DepthConvention,
    shading: Shading,
}

impl SurfacePass {
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        scene: &GpuScene,
        view: &ViewBinding,
        depth: DepthConvention,
        shading: Shading,
    ) -> GpuResult<Self> {
        let two_targets = [Some(SURFACE_FORMAT.into()), Some(SURFACE_FORMAT.into())];
        let program = program(shading);
        let build = |entry: &str,
                     targets: &[Option<wgpu::ColorTargetState>]|
         -> GpuResult<Vec<(PipelineKey, wgpu::RenderPipeline)>> {
            scene
                .pipeline_keys()
                .into_iter()
                .map(|key| {
                    let desc = ScenePipelineDesc {
                        label: entry,
                        program: &program,
                        key,
                        view_layout: &view.layout,
                        extra_layouts: &[],
                        vertex_entry: "vs_main",
                        fragment_entry: Some(entry),
                        color_targets: targets,
                        depth_write: true,
                        depth_compare: depth.nearer(),
                        pulls_vertices: false,
                        samples: 1,
                    };
                    Ok((key, scene.create_pipeline(context, library, &desc)?))
                })
                .collect()
        };
        Ok(Self {
            geometry: build("fs_geometry", &two_targets)?,
            material: build("fs_material", &two_targets)?,
            emission: if scene.features.emissive {
                Some(build("fs_emission", &two_targets[..1])?)
            } else {
                None
            },
            depth,
            shading,
        })
    }

    /// Draws the scene twice (geometry, material; three times with emission) at `size`
    /// and reads everything back (blocking).
    pub fn capture(
        &self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        size: (u32, u32),
        origin: glam::DVec3,
    ) -> GpuResult<SurfaceImage> {
        crate::block_on(self.capture_async(context, scene, view, size, origin))
    }

    /// One capture pass: `pipelines` draw the scene into `outputs` over a cleared `depth`.
    fn draw_pass(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipelines: &[(PipelineKey, wgpu::RenderPipeline)],
        outputs: &[&Target],
        depth: &Target,
        scene: &GpuScene,
        view: &ViewBinding,
    ) {
        let attachments: Vec<_> = outputs
            .iter()
            .map(|t| crate::binding::cleared_color(&t.view, wgpu::Color::TRANSPARENT))
            .collect();
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("surface capture"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(crate::binding::depth_attachment(
                &depth.view,
                wgpu::LoadOp::Clear(self.depth.clear_value()),
            )),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &view.bind_group, &[]);
        for (key, pipeline) in pipelines {
            pass.set_pipeline(pipeline);
            scene.draw(&mut pass, *key);
        }
    }

    /// [`SurfacePass::capture`] without blocking.
    pub async fn capture_async(
        &self,
        context: &GpuContext,
        scene: &GpuScene,
        view: &ViewBinding,
        size: (u32, u32),
        origin: glam::DVec3,
    ) -> GpuResult<SurfaceImage> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let target = |label: &str| Target::new(context, label, size, SURFACE_FORMAT, usage);
        let (position, normal, albedo, specular) = (
            target("surface position")?,
            target("surface normal")?,
            target("surface albedo")?,
            target("surface specular")?,
        );
        let emission = match &self.emission {
            Some(_) => Some(target("surface emission")?),
            None => None,
        };
        let depth = Target::new(
            context,
            "surface depth",
            size,
            crate::targets::DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )?;
        context.scoped("capturing surface attributes", || {
            let mut encoder =
                context
                    .device
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("surface capture"),
                    });
            let passes = [
                (&self.geometry, vec![&position, &normal]),
                (&self.material, vec![&albedo, &specular]),
            ]
            .into_iter()
            .chain(
                self.emission
                    .as_ref()
                    .zip(emission.as_ref())
                    .map(|(pipelines, target)| (pipelines, vec![target])),
            );
            for (pipelines, outputs) in passes {
                self.draw_pass(&mut encoder, pipelines, &outputs, &depth, scene, view);
            }
            context.queue.submit([encoder.finish()]);
        })?;
        Ok(SurfaceImage {
            size,
            origin,
            position: read_f32_rgba_async(context, &position.texture).await?,
            shading: self.shading,
            normal_lobe: read_f32_rgba_async(context, &normal.texture).await?,
            albedo: read_f32_rgba_async(context, &albedo.texture).await?,
            specular: read_f32_rgba_async(context, &specular.texture).await?,
            emission: match &emission {
                Some(emission) => read_f32_rgba_async(context, &emission.texture).await?,
                None => vec![[0.0; 4]; (size.0 * size.1) as usize],
            },
        })
    }
}
