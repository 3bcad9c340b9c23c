//! Offscreen render targets of any size, and readback of textures and buffers to the CPU.

use crate::context::GpuContext;
use crate::error::{GpuError, GpuResult};

/// Linear HDR colour: every shading pipeline writes here.
pub const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Tonemapped 8-bit output (what PNGs and the window show), as it is drawn into and sampled:
/// the output's default view.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// The output texture's own format: sRGB formats cannot be storage textures, so the output
/// is stored as plain 8-bit UNORM holding sRGB-encoded values, written by the compute
/// tonemap through [`RenderTargets::output_storage`] and viewed as [`OUTPUT_FORMAT`]
/// everywhere else (the same bytes).
pub const OUTPUT_STORAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth buffer format. 32-bit float: needed for the large near/far ratios the lab uses.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// One texture with its default view.
#[derive(Debug)]
pub struct Target {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl Target {
    /// A sampled texture of `format` and `size` holding `bytes` (tightly packed rows):
    /// lookup tables and data textures that shaders read and nothing writes again.
    pub fn sampled_with_data(
        context: &GpuContext,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        bytes: &[u8],
    ) -> GpuResult<Self> {
        let target = Self::new(
            context,
            label,
            size,
            format,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        )?;
        let texel_bytes = format.block_copy_size(None).unwrap_or(1);
        context.queue.write_texture(
            target.texture.as_image_copy(),
            bytes,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(texel_bytes * size.0),
                rows_per_image: Some(size.1),
            },
            target.texture.size(),
        );
        Ok(target)
    }

    pub fn new(
        context: &GpuContext,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> GpuResult<Self> {
        Self::viewed_as(context, label, size, format, format, usage)
    }

    /// A texture of `format` whose default view has `view_format` (e.g. the sRGB view of a
    /// UNORM texture).
    pub fn viewed_as(
        context: &GpuContext,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        view_format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> GpuResult<Self> {
        context.check_texture_size(label, size.0, size.1)?;
        let view_formats: &[wgpu::TextureFormat] = if view_format == format {
            &[]
        } else {
            &[view_format]
        };
        let texture = create_texture(context, label, size, format, 1, usage, view_formats)?;
        // A view in another format keeps only the usages that format allows (an sRGB view
        // cannot be a storage binding).
        let view_usage = if view_format == format {
            usage
        } else {
            usage
                & view_format
                    .guaranteed_format_features(context.device.features())
                    .allowed_usages
        };
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(view_format),
            usage: Some(view_usage),
            ..Default::default()
        });
        Ok(Self { texture, view })
    }
}

/// A 2D texture of `format` and `samples` samples a pixel, created in an error scope that
/// names it (every texture of this module).
fn create_texture(
    context: &GpuContext,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    samples: u32,
    usage: wgpu::TextureUsages,
    view_formats: &[wgpu::TextureFormat],
) -> GpuResult<wgpu::Texture> {
    let sampled = match samples {
        1 => String::new(),
        n => format!(", {n} samples"),
    };
    context.scoped(
        &format!("creating {label} ({}x{}{sampled})", size.0, size.1),
        || {
            context.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: size.0,
                    height: size.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats,
            })
        },
    )
}

/// A view of a depth texture's depth alone, as a pass binds it to read it
/// (`texture_depth_2d`).
pub fn depth_only_view(depth: &wgpu::Texture) -> wgpu::TextureView {
    depth.create_view(&wgpu::TextureViewDescriptor {
        aspect: wgpu::TextureAspect::DepthOnly,
        ..Default::default()
    })
}

/// Records a copy of the whole of `from` into `to` (of the same size and format): what a
/// pass that cannot write what it reads does with its result.
pub fn copy_whole_texture(
    encoder: &mut wgpu::CommandEncoder,
    from: &wgpu::Texture,
    to: &wgpu::Texture,
) {
    encoder.copy_texture_to_texture(from.as_image_copy(), to.as_image_copy(), from.size());
}

/// A multisampled render target's view (MSAA: drawn, read by `textureLoad` per sample,
/// resolved into a single-sampled target).
pub fn multisampled_view(
    context: &GpuContext,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    samples: u32,
) -> GpuResult<wgpu::TextureView> {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
    let texture = create_texture(context, label, size, format, samples, usage, &[])?;
    Ok(texture.create_view(&wgpu::TextureViewDescriptor::default()))
}

/// The targets of one frame: HDR colour, depth, and the tonemapped output; with MSAA, the
/// multisampled colour and depth the forward pipelines draw into, resolved into `hdr`.
#[derive(Debug)]
pub struct RenderTargets {
    pub size: (u32, u32),
    pub hdr: Target,
    /// Single-sampled depth (what the frame's compute passes read); under MSAA the depth
    /// the passes test is [`RenderTargets::depth_view`], and this one is not written.
    pub depth: Target,
    /// MSAA's colour and depth targets (`None` at one sample a pixel).
    pub multisampled: Option<MultisampledTargets>,
    /// Viewed as [`OUTPUT_FORMAT`]; stored as [`OUTPUT_STORAGE_FORMAT`].
    pub output: Target,
    /// The output as a storage texture (UNORM, written sRGB-encoded by the tonemap).
    pub output_storage: wgpu::TextureView,
}

/// The targets of MSAA: HDR colour (resolved into [`RenderTargets::hdr`] by each pass
/// that draws it) and depth, both of `samples` samples a pixel.
#[derive(Debug)]
pub struct MultisampledTargets {
    pub samples: u32,
    pub hdr: wgpu::TextureView,
    pub depth: wgpu::TextureView,
}

impl RenderTargets {
    /// Targets of `size` with `samples` samples a pixel (1: no MSAA); counts the device
    /// lacks are refused ([`GpuContext::msaa_sample_counts`]).
    pub fn with_samples(context: &GpuContext, size: (u32, u32), samples: u32) -> GpuResult<Self> {
        let mut targets = Self::new(context, size)?;
        if samples == 1 {
            return Ok(targets);
        }
        let counts = context.msaa_sample_counts();
        if !counts.contains(&samples) {
            return Err(GpuError::Unsupported(format!(
                "{samples}x MSAA: this device offers {counts:?} samples a pixel for the HDR and depth targets"
            )));
        }
        targets.multisampled = Some(MultisampledTargets {
            samples,
            hdr: multisampled_view(
                context,
                "multisampled hdr target",
                size,
                HDR_FORMAT,
                samples,
            )?,
            depth: multisampled_view(
                context,
                "multisampled depth target",
                size,
                DEPTH_FORMAT,
                samples,
            )?,
        });
        Ok(targets)
    }

    /// Samples a pixel of the colour and depth the forward passes draw.
    pub fn samples(&self) -> u32 {
        self.multisampled.as_ref().map_or(1, |m| m.samples)
    }

    /// The depth the forward passes test and write: the multisampled one under MSAA.
    pub fn depth_view(&self) -> &wgpu::TextureView {
        self.multisampled
            .as_ref()
            .map_or(&self.depth.view, |m| &m.depth)
    }

    /// The HDR colour a forward pass draws, `load`ed and stored: under MSAA the
    /// multisampled target, resolved into [`RenderTargets::hdr`] at the end of the pass.
    pub fn hdr_attachment(
        &self,
        load: wgpu::LoadOp<wgpu::Color>,
    ) -> Option<wgpu::RenderPassColorAttachment<'_>> {
        let (view, resolve_target) = match &self.multisampled {
            Some(multisampled) => (&multisampled.hdr, Some(&self.hdr.view)),
            None => (&self.hdr.view, None),
        };
        Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })
    }

    pub fn new(context: &GpuContext, size: (u32, u32)) -> GpuResult<Self> {
        let readable = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        let output = Target::viewed_as(
            context,
            "output target",
            size,
            OUTPUT_STORAGE_FORMAT,
            OUTPUT_FORMAT,
            readable | wgpu::TextureUsages::STORAGE_BINDING,
        )?;
        let output_storage = output
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        Ok(Self {
            size,
            output_storage,
            output,
            hdr: Target::new(
                context,
                "hdr target",
                size,
                HDR_FORMAT,
                // Copied into by the post passes that cannot write what they read
                // (temporal anti-aliasing, bloom).
                readable | wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::COPY_DST,
            )?,
            depth: Target::new(context, "depth target", size, DEPTH_FORMAT, readable)?,
            multisampled: None,
        })
    }
}

/// Bytes per texel of the formats we read back.
fn texel_bytes(format: wgpu::TextureFormat) -> GpuResult<u32> {
    use wgpu::TextureFormat as F;
    match format {
        F::Rgba8Unorm
        | F::Rgba8UnormSrgb
        | F::Bgra8Unorm
        | F::Bgra8UnormSrgb
        | F::R32Float
        | F::Depth32Float
        | F::R32Uint => Ok(4),
        F::Rgba16Float | F::Rg32Float | F::Rg32Uint => Ok(8),
        F::Rgba32Float | F::Rgba32Uint => Ok(16),
        other => Err(GpuError::Unsupported(format!("readback of {other:?}"))),
    }
}

/// Copies a whole 2D texture (mip 0) to the CPU as tightly packed rows (blocking).
pub fn read_texture_bytes(context: &GpuContext, texture: &wgpu::Texture) -> GpuResult<Vec<u8>> {
    crate::block_on(read_texture_bytes_async(context, texture))
}

/// [`read_texture_bytes`] without blocking: the page awaits it.
pub async fn read_texture_bytes_async(
    context: &GpuContext,
    texture: &wgpu::Texture,
) -> GpuResult<Vec<u8>> {
    let (width, height) = (texture.width(), texture.height());
    let texel = texel_bytes(texture.format())?;
    let unpadded_row = width * texel;
    let padded_row = unpadded_row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
        * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let size = padded_row as u64 * height as u64;
    context.check_buffer_size("texture readback", size, false)?;
    let staging = context.scoped("creating readback buffer", || {
        context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        })
    })?;
    context.scoped("copying texture for readback", || {
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("texture readback"),
            });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(height),
                },
            },
            texture.size(),
        );
        context.queue.submit([encoder.finish()]);
    })?;
    let padded = map_read_async(context, &staging, "reading back a texture").await?;
    let mut out = Vec::with_capacity((unpadded_row * height) as usize);
    for row in padded.chunks_exact(padded_row as usize) {
        out.extend_from_slice(&row[..unpadded_row as usize]);
    }
    Ok(out)
}

/// Maps a MAP_READ buffer and copies its contents out (blocking).
pub fn map_read(context: &GpuContext, buffer: &wgpu::Buffer, what: &str) -> GpuResult<Vec<u8>> {
    crate::block_on(map_read_async(context, buffer, what))
}

/// [`map_read`] without blocking: natively it waits for the device (which runs the map's
/// callback), in the page it yields to the browser until the callback has run.
#[cfg_attr(target_arch = "wasm32", allow(unused_variables))]
pub async fn map_read_async(
    context: &GpuContext,
    buffer: &wgpu::Buffer,
    what: &str,
) -> GpuResult<Vec<u8>> {
    let receiver = crate::readback::request_read_map(buffer);
    #[cfg(not(target_arch = "wasm32"))]
    context.wait_idle(what)?;
    let map_error = |message: String| GpuError::Map {
        context: what.into(),
        message,
    };
    receiver
        .await
        .map_err(|e| map_error(e.to_string()))?
        .map_err(|e| map_error(e.to_string()))?;
    let bytes = buffer
        .slice(..)
        .get_mapped_range()
        .map_err(|e| map_error(e.to_string()))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// Reads an RGBA8 texture (UNORM or sRGB: the stored bytes, no conversion).
pub fn read_rgba8(context: &GpuContext, texture: &wgpu::Texture) -> GpuResult<image::RgbaImage> {
    crate::block_on(read_rgba8_async(context, texture))
}

/// [`read_rgba8`] without blocking.
pub async fn read_rgba8_async(
    context: &GpuContext,
    texture: &wgpu::Texture,
) -> GpuResult<image::RgbaImage> {
    use wgpu::TextureFormat as F;
    if !matches!(texture.format(), F::Rgba8Unorm | F::Rgba8UnormSrgb) {
        return Err(GpuError::Unsupported(format!(
            "read_rgba8 of {:?}",
            texture.format()
        )));
    }
    let bytes = read_texture_bytes_async(context, texture).await?;
    image::RgbaImage::from_raw(texture.width(), texture.height(), bytes)
        .ok_or_else(|| GpuError::Unsupported("readback size mismatch".into()))
}

/// Reads a float colour texture (Rgba16Float, Rgba32Float, R32Float, Depth32Float) as
/// f32 RGBA texels, row-major (single-channel formats fill red, alpha 1).
pub fn read_f32_rgba(context: &GpuContext, texture: &wgpu::Texture) -> GpuResult<Vec<[f32; 4]>> {
    crate::block_on(read_f32_rgba_async(context, texture))
}

/// [`read_f32_rgba`] without blocking.
pub async fn read_f32_rgba_async(
    context: &GpuContext,
    texture: &wgpu::Texture,
) -> GpuResult<Vec<[f32; 4]>> {
    use wgpu::TextureFormat as F;
    let bytes = read_texture_bytes_async(context, texture).await?;
    match texture.format() {
        F::Rgba16Float => Ok(bytes
            .chunks_exact(8)
            .map(|t| {
                let h = |i: usize| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32();
                [h(0), h(1), h(2), h(3)]
            })
            .collect()),
        F::Rgba32Float => Ok(bytemuck::pod_collect_to_vec::<u8, [f32; 4]>(&bytes)),
        F::R32Float | F::Depth32Float => Ok(bytemuck::pod_collect_to_vec::<u8, f32>(&bytes)
            .into_iter()
            .map(|v| [v, 0.0, 0.0, 1.0])
            .collect()),
        other => Err(GpuError::Unsupported(format!("read_f32_rgba of {other:?}"))),
    }
}

/// Copies `buffer` (which needs COPY_SRC) to the CPU as a vector of `T`.
pub fn read_buffer<T: bytemuck::Pod>(
    context: &GpuContext,
    buffer: &wgpu::Buffer,
) -> GpuResult<Vec<T>> {
    crate::block_on(read_buffer_async(context, buffer))
}

/// [`read_buffer`] without blocking.
pub async fn read_buffer_async<T: bytemuck::Pod>(
    context: &GpuContext,
    buffer: &wgpu::Buffer,
) -> GpuResult<Vec<T>> {
    let size = buffer.size();
    let staging = context.scoped("creating buffer readback", || {
        context.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("buffer readback"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        })
    })?;
    context.scoped("copying buffer for readback", || {
        let mut encoder = context
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("buffer readback"),
            });
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        context.queue.submit([encoder.finish()]);
    })?;
    let bytes = map_read_async(context, &staging, "reading back a buffer").await?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}
