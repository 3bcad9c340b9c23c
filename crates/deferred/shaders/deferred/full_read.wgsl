// G-buffer layout `full` (reading).

#import manylights::common::view::view
#import manylights::deferred::codecs::GBufferSample

// Whether the scene has a specular channel (else a 1x1 placeholder is bound and unread).
// (Pipeline constant 0: naga_oil renames the items of imported modules, so the pipeline
// sets it by id, `deferred::GBUFFER_SPECULAR_ID`.)
@id(0) override GBUFFER_SPECULAR: bool = true;

// World position (xyz) and lobe (w: exponent or roughness).
@group(1) @binding(0) var gbuffer_position: texture_2d<f32>;
// Unit normal.
@group(1) @binding(1) var gbuffer_normal: texture_2d<f32>;
// Linear albedo.
@group(1) @binding(2) var gbuffer_albedo: texture_2d<f32>;
// Linear specular colour.
@group(1) @binding(3) var gbuffer_specular: texture_2d<f32>;
// Depth (coverage).
@group(1) @binding(4) var gbuffer_depth: texture_depth_2d;

fn read_gbuffer(pixel: vec2<i32>) -> GBufferSample {
    var sample: GBufferSample;
    let depth = textureLoad(gbuffer_depth, pixel, 0);
    sample.covered = depth != view.near_far.z;
    let position = textureLoad(gbuffer_position, pixel, 0);
    sample.surface.position = position.xyz;
    sample.surface.lobe = position.w;
    sample.surface.normal = textureLoad(gbuffer_normal, pixel, 0).xyz;
    sample.surface.albedo = textureLoad(gbuffer_albedo, pixel, 0).rgb;
    sample.surface.alpha = 1.0;
    sample.surface.specular = vec3<f32>(0.0);
    if GBUFFER_SPECULAR {
        sample.surface.specular = textureLoad(gbuffer_specular, pixel, 0).rgb;
    }
    sample.view_depth = -(view.view * vec4<f32>(position.xyz, 1.0)).z;
    return sample;
}
