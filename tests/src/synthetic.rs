//! Frames a test writes itself, for driving one pass directly (no scene, no pipeline) and
//! comparing it with an f64 twin given exactly the same input: half-float images, a depth
//! plane facing the camera, the camera, and a pixel-by-pixel comparison.

use glam::{Mat4, Vec3, Vec4};
use manylights_gpu::view::ViewUniform;
use manylights_gpu::{GpuContext, wgpu};

/// An RGB image, row-major, in f64 (the twins' working type).
pub type Image = Vec<[f64; 3]>;

/// `image` rounded to half floats, as a pass is given it.
pub fn in_half_floats(image: &[[f64; 4]]) -> Vec<[f64; 4]> {
    image
        .iter()
        .map(|p| p.map(|c| half::f16::from_f64(c).to_f64()))
        .collect()
}

/// Writes `texels` (row-major RGBA) into `texture`, an `Rgba16Float` texture of `size`
/// with `COPY_DST`.
pub fn write_rgba16(
    context: &GpuContext,
    texture: &wgpu::Texture,
    size: (u32, u32),
    texels: &[[f64; 4]],
) {
    assert_eq!(
        texels.len(),
        (size.0 * size.1) as usize,
        "texels for {size:?}"
    );
    let bytes: Vec<u8> = texels
        .iter()
        .flatten()
        .flat_map(|&c| half::f16::from_f64(c).to_le_bytes())
        .collect();
    context.queue.write_texture(
        texture.as_image_copy(),
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.0 * 8),
            rows_per_image: Some(size.1),
        },
        wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
    );
}

/// Clears the depth target `view` to `depth`: a plane facing the camera.
pub fn clear_depth(context: &GpuContext, view: &wgpu::TextureView, depth: f32) {
    let mut encoder = context
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("test depth plane"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(depth),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    context.queue.submit([encoder.finish()]);
}

/// The camera the synthetic tests look through: at the origin looking down -z, 60 degrees
/// vertically, depth 0..1 (forward), near 0.1, far 100.
pub fn test_view(size: (u32, u32)) -> ViewUniform {
    let aspect = size.0 as f32 / size.1 as f32;
    let proj = glam::camera::rh::proj::directx::perspective(60f32.to_radians(), aspect, 0.1, 100.0);
    ViewUniform::new(Mat4::IDENTITY, proj, Vec3::ZERO, size, 0.1, 100.0)
}

/// `view` with last frame's camera seeing each point `moved` pixels back (x right, y
/// down): the reprojection of content that moved by `moved` since the frame before.
pub fn moved_since_last_frame(view: &ViewUniform, moved: (f64, f64)) -> ViewUniform {
    let (w, h) = (f64::from(view.viewport[0]), f64::from(view.viewport[1]));
    let shift = Mat4::from_translation(Vec3::new(
        (-2.0 * moved.0 / w) as f32,
        (2.0 * moved.1 / h) as f32,
        0.0,
    ));
    let mut out = *view;
    out.previous_view_proj = (shift * Mat4::from_cols_array_2d(&view.view_proj)).to_cols_array_2d();
    out
}

/// The NDC depth of the plane facing [`test_view`]'s camera at `distance` along its axis.
pub fn plane_depth(view: &ViewUniform, distance: f32) -> f32 {
    let clip = Mat4::from_cols_array_2d(&view.proj) * Vec4::new(0.0, 0.0, -distance, 1.0);
    clip.z / clip.w
}

/// Where `got` differs from `want` by more than `tolerance(pixel, channel)` (or is not
/// finite): how many channels, and the first `limit` of them described.
pub fn differing(
    got: &Image,
    want: &Image,
    tolerance: impl Fn(usize, usize) -> f64,
    limit: usize,
) -> (usize, Vec<String>) {
    let mut count = 0;
    let mut examples = Vec::new();
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        for c in 0..3 {
            let bound = tolerance(i, c);
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

/// A plane seen by [`test_view`]'s camera: through the point `distance` straight ahead,
/// turned `tilt_degrees` about the vertical axis (0: facing the camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub distance: f32,
    pub tilt_degrees: f32,
}

impl Plane {
    /// The plane's NDC depth at NDC position `(x, y)` through `view`'s projection.
    fn depth_at(&self, view: &ViewUniform, x: f64, y: f64) -> f64 {
        let proj = glam::DMat4::from_cols_array_2d(&view.proj.map(|c| c.map(f64::from)));
        let inverse = proj.inverse();
        let far = inverse * glam::DVec4::new(x, y, 1.0, 1.0);
        let ray = (far.truncate() / far.w).normalize();
        let (sin, cos) = f64::from(self.tilt_degrees).to_radians().sin_cos();
        let normal = glam::DVec3::new(sin, 0.0, cos);
        let on_plane = glam::DVec3::new(0.0, 0.0, -f64::from(self.distance));
        let point = ray * (normal.dot(on_plane) / normal.dot(ray));
        let clip = proj * point.extend(1.0);
        clip.z / clip.w
    }
}

/// Draws `plane` into the depth target `target` (cleared to 1, the sky, first) and reads
/// back what the rasterizer wrote: a plane's NDC depth is affine in screen position, so one
/// triangle over the frame with the plane's depths at its corners draws it.
pub fn draw_depth_plane(
    context: &GpuContext,
    target: &wgpu::Texture,
    view: &ViewUniform,
    plane: Plane,
) -> Vec<f64> {
    // The affine map from NDC (x, y) to depth, from three points inside the frame.
    let d0 = plane.depth_at(view, 0.0, 0.0);
    let dx = plane.depth_at(view, 0.5, 0.0) - d0;
    let dy = plane.depth_at(view, 0.0, 0.5) - d0;
    let corners = [(-1.0, -1.0), (3.0, -1.0), (-1.0, 3.0)];
    let depths: Vec<f32> = corners
        .iter()
        .map(|&(x, y)| (d0 + 2.0 * (dx * x + dy * y)) as f32)
        .collect();
    let source = format!(
        "@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {{
            var xy = array<vec2<f32>, 3>(vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
            var z = array<f32, 3>({:?}, {:?}, {:?});
            return vec4<f32>(xy[i], z[i], 1.0);
        }}",
        depths[0], depths[1], depths[2]
    );
    let module = context
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("test depth plane"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
    let pipeline = context
        .device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("test depth plane"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: manylights_gpu::targets::DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
    let depth_view = target.create_view(&wgpu::TextureViewDescriptor::default());
    let mut encoder = context
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("test depth plane"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.draw(0..3, 0..1);
    }
    context.queue.submit([encoder.finish()]);
    manylights_gpu::targets::read_f32_rgba(context, target)
        .expect("the depth plane read back")
        .into_iter()
        .map(|p| f64::from(p[0]))
        .collect()
}
