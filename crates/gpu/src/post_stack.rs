//! The post stack every pipeline shares, after shading: temporal anti-aliasing and bloom
//! (each written back into the HDR target), then exposure and the tonemap. One part, so
//! that a frame prepares and records it in one place, and a new post pass joins it here.

use crate::bloom::{Bloom, PreparedBloom};
use crate::context::GpuContext;
use crate::error::GpuResult;
use crate::post::{Exposure, PreparedTonemap, Tonemap, TonemapPass};
use crate::shaders::ShaderLibrary;
use crate::taa::{AntiAliasing, PreparedTaa, TemporalAntiAliasing};
use crate::targets::RenderTargets;
use crate::timer::GpuTimer;

/// What a frame asks of the post stack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostChoices {
    pub anti_aliasing: AntiAliasing,
    /// Bloom's strength (0: none).
    pub bloom: f32,
    pub exposure: Exposure,
    pub tonemap: Tonemap,
    /// Whether the last frame was of this image (the same pipeline, depth convention and
    /// BRDF): otherwise temporal anti-aliasing's history is dropped.
    pub follows_own_frame: bool,
}

/// The post passes and what they keep between frames.
#[derive(Debug)]
pub struct PostStack {
    taa: TemporalAntiAliasing,
    bloom: Bloom,
    tonemap: TonemapPass,
}

/// One frame's post passes, prepared.
#[derive(Debug)]
pub struct PreparedPost<'a> {
    taa: Option<PreparedTaa<'a>>,
    bloom: Option<PreparedBloom<'a>>,
    tonemap: PreparedTonemap<'a>,
}

impl PostStack {
    /// The passes, temporal anti-aliasing's on the view's layout (group 0).
    pub fn new(
        context: &GpuContext,
        library: &ShaderLibrary,
        view_layout: &wgpu::BindGroupLayout,
    ) -> GpuResult<Self> {
        Ok(Self {
            taa: TemporalAntiAliasing::new(context, library, view_layout)?,
            bloom: Bloom::new(context, library)?,
            tonemap: TonemapPass::new(context, library)?,
        })
    }

    /// Exposure and the tonemap (its exposure state, for tests and reports).
    pub fn tonemap(&self) -> &TonemapPass {
        &self.tonemap
    }

    /// Prepares a frame's post passes over `targets`.
    pub fn prepare<'a>(
        &'a mut self,
        context: &GpuContext,
        targets: &'a RenderTargets,
        choices: PostChoices,
    ) -> GpuResult<PreparedPost<'a>> {
        let Self {
            taa,
            bloom,
            tonemap,
        } = self;
        // The image's history is of this image only while the frame follows its own
        // pipeline's and keeps anti-aliasing on.
        if !choices.follows_own_frame || choices.anti_aliasing == AntiAliasing::Off {
            taa.forget_history();
        }
        // The fixed exposure is written first: the passes before the tonemap read it.
        let prepared_tonemap = tonemap.prepare(context, targets, choices.exposure, choices.tonemap);
        let exposure = prepared_tonemap.exposure_state();
        Ok(PreparedPost {
            taa: match choices.anti_aliasing {
                AntiAliasing::Taa => Some(taa.prepare(context, targets, exposure)?),
                AntiAliasing::Off => None,
            },
            bloom: match choices.bloom > 0.0 {
                true => bloom.prepare(context, targets, exposure, choices.bloom)?,
                false => None,
            },
            tonemap: prepared_tonemap,
        })
    }
}

impl PreparedPost<'_> {
    /// Records temporal anti-aliasing (with the view at group 0), bloom, then exposure and
    /// the tonemap into the output.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view_group: &wgpu::BindGroup,
        timer: &mut GpuTimer,
    ) {
        if let Some(taa) = &self.taa {
            taa.record(encoder, view_group, timer);
        }
        if let Some(bloom) = &self.bloom {
            bloom.record(encoder, timer);
        }
        self.tonemap.record(encoder, timer);
    }
}
