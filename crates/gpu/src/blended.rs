//! Blended surfaces (glTF's `BLEND`) drawn over the opaque frame: the "over" operator and
//! the render pass every pipeline's blended draws record into (Forward+ and deferred through
//! `cluster::BlendedPass`, naive with its own loop).

use crate::{GpuTimer, PassName, RenderTargets, ViewBinding, wgpu};

/// The blended pass's timed name.
pub const BLENDED_PASS: PassName = PassName::new("blended surfaces");

/// The "over" operator on the HDR target: colour by the surface's alpha over what is
/// behind it; the target's alpha kept.
pub const OVER: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::SrcAlpha,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::Zero,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};

/// A render pass over the HDR target and the depth buffer, both loaded (the opaque frame),
/// with `draw` recording the blended draws (group 0 set).
pub fn record_blended(
    encoder: &mut wgpu::CommandEncoder,
    timer: &mut GpuTimer,
    (view, targets): (&ViewBinding, &RenderTargets),
    draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(BLENDED_PASS.as_str()),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &targets.hdr.view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(crate::binding::depth_attachment(
            &targets.depth.view,
            wgpu::LoadOp::Load,
        )),
        timestamp_writes: timer.render_pass(BLENDED_PASS),
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_bind_group(0, &view.bind_group, &[]);
    draw(&mut pass);
}
