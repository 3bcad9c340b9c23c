// The camera of the frame being drawn: matrices and the quantities shading needs.
// Bound at group 0 by every pass that draws the scene.

struct View {
    // World to clip space.
    view_proj: mat4x4<f32>,
    // World to view space (right-handed, camera looks down -Z).
    view: mat4x4<f32>,
    // View to clip space.
    proj: mat4x4<f32>,
    // Clip to view space, for reconstructing positions from depth.
    inverse_proj: mat4x4<f32>,
    // View to world space.
    inverse_view: mat4x4<f32>,
    // World-space camera position (w unused).
    camera_position: vec4<f32>,
    // Render target size in pixels (xy) and its reciprocal (zw).
    viewport: vec4<f32>,
    // Near and far plane distances (positive), the depth of empty pixels (1, or 0 with
    // reverse-Z), one unused slot.
    near_far: vec4<f32>,
}

// The frame's camera.
@group(0) @binding(0) var<uniform> view: View;
