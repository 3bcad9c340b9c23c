// Full-precision surface attributes for the accuracy reference: the CPU f64 shading reads
// back exactly what the GPU shaded (interpolated position, normal, material). Two entry
// points, each writing two Rgba32Float targets (32 bytes per pixel, WebGPU's default
// attachment budget): geometry, then material; a third, emission, for scenes whose
// materials emit light.

#import manylights::common::scene::{VertexInput, VertexOutput, scene_vertex}
#import manylights::common::material::fragment_surface

@vertex
fn vs_main(vertex: VertexInput, @builtin(instance_index) instance_index: u32) -> VertexOutput {
    return scene_vertex(vertex, instance_index);
}

struct GeometryOutput {
    // World position (xyz), 1 in w where a surface was drawn.
    @location(0) position: vec4<f32>,
    // Unit shading normal (xyz), lobe (w: Blinn-Phong exponent or PBR roughness).
    @location(1) normal_shininess: vec4<f32>,
}

@fragment
fn fs_geometry(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> GeometryOutput {
    let surface = fragment_surface(in, front_facing);
    var out: GeometryOutput;
    out.position = vec4<f32>(surface.position, 1.0);
    out.normal_shininess = vec4<f32>(surface.normal, surface.lobe);
    return out;
}

struct MaterialOutput {
    // Linear diffuse albedo (rgb), alpha (a).
    @location(0) albedo: vec4<f32>,
    // Specular colour or F0 (rgb).
    @location(1) specular: vec4<f32>,
}

@fragment
fn fs_material(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> MaterialOutput {
    let surface = fragment_surface(in, front_facing);
    var out: MaterialOutput;
    out.albedo = vec4<f32>(surface.albedo, surface.alpha);
    out.specular = vec4<f32>(surface.specular, 1.0);
    return out;
}

struct EmissionOutput {
    // Emitted radiance (rgb).
    @location(0) emission: vec4<f32>,
}

@fragment
fn fs_emission(in: VertexOutput, @builtin(front_facing) front_facing: bool) -> EmissionOutput {
    let surface = fragment_surface(in, front_facing);
    var out: EmissionOutput;
    out.emission = vec4<f32>(surface.emission, 1.0);
    return out;
}
