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
    // The world position all scene coordinates are relative to (the camera's):
    // camera-relative rendering keeps f32 precision far from the world origin. Instance
    // transforms and this view are relative to it; light positions are stored in world
    // space and made relative with `relative_to_origin`.
    origin: vec4<f32>,
    // The frame's seeds: x, the stochastic shadow rays' (`FrameSettings::shadow_seed`);
    // the rest unused.
    seeds: vec4<u32>,
    // The previous frame's world to clip space, taking this frame's scene coordinates:
    // where a surface was on the screen a frame ago (`view_proj` on a first frame).
    previous_view_proj: mat4x4<f32>,
    // The previous frame's camera position in this frame's scene coordinates (w unused).
    previous_camera_position: vec4<f32>,
    // The sub-pixel offsets temporal anti-aliasing moved the projection by, in NDC: xy
    // this frame's (already in `proj` and `view_proj`), zw the previous frame's (already
    // in `previous_view_proj`). Zero without it.
    jitter: vec4<f32>,
    // x: the mip bias of material textures (negative under temporal anti-aliasing, which
    // averages several samples a pixel over frames); the rest unused.
    texture_lod_bias: vec4<f32>,
}

// A world-space position made relative to the view's origin (exact for nearby points:
// the difference of two close f32 values is exact).
fn relative_to_origin(world: vec3<f32>) -> vec3<f32> {
    return world - view.origin.xyz;
}

// The frame's camera.
@group(0) @binding(0) var<uniform> view: View;
