//! The G-buffer codecs tested where they run: `shaders/deferred/codecs.wgsl` on the GPU
//! (through `codec_probe.wgsl`, which calls the very functions the G-buffer passes use),
//! against exact values and derived bounds. There is no Rust copy of the codecs to drift
//! from the shader.

use glam::Vec3;
use manylights_deferred::codec_probe_program;
use manylights_gpu::wgpu::util::DeviceExt as _;
use manylights_gpu::{GpuContext, MaterialVariant, ShaderLibrary, wgpu};
use manylights_scene::color::{linear_to_srgb, srgb_to_linear};

/// Mirrors `ProbeInput` in `codec_probe.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeInput {
    normal_shininess: [f32; 4],
    color: [f32; 4],
}

/// Mirrors `ProbeOutput` in `codec_probe.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ProbeOutput {
    octahedral: [f32; 2],
    quantized: [u32; 2],
    decoded_normal_shininess: [f32; 4],
    srgb_shininess_code: [f32; 4],
    linear: [f32; 4],
}

/// Runs every input through the codecs on the GPU.
fn probe(inputs: &[ProbeInput]) -> Vec<ProbeOutput> {
    let context = GpuContext::new_headless().unwrap_or_else(|error| {
        // Without an adapter the error (GpuError::NoAdapter) says how to install lavapipe.
        panic!("these tests need a GPU: {error}")
    });
    let module = ShaderLibrary::from_env()
        .create_module(&context, &codec_probe_program(), MaterialVariant::default())
        .expect("the probe composes");
    let device = &context.device;
    let input_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("codec probe inputs"),
        contents: bytemuck::cast_slice(inputs),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let output_buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("codec probe outputs"),
        size: (inputs.len() * std::mem::size_of::<ProbeOutput>()) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let compute = wgpu::ShaderStages::COMPUTE;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("codec probe"),
        entries: &[
            manylights_gpu::binding::storage_entry(0, compute, true),
            manylights_gpu::binding::storage_entry(1, compute, false),
        ],
    });
    let [pipeline] = manylights_gpu::binding::compute_pipelines(
        &context,
        "codec probe",
        &[&layout],
        &module,
        ["probe"],
    );
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("codec probe"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output_buffer.as_entire_binding(),
            },
        ],
    });
    context
        .scoped("running the codec probe", || {
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups((inputs.len() as u32).div_ceil(64), 1, 1);
            }
            context.queue.submit([encoder.finish()]);
        })
        .expect("the probe passes wgpu's validation");
    manylights_gpu::targets::read_buffer(&context, &output_buffer).expect("readback")
}

fn input(normal: Vec3) -> ProbeInput {
    ProbeInput {
        normal_shininess: normal.extend(16.0).to_array(),
        color: [0.5; 4],
    }
}

/// Directions that stress the map: a dense sphere, the equator (the fold's seam) and just
/// either side of it, the great circles along the axes.
fn directions() -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..90 {
        for j in 0..180 {
            let theta = (i as f32 + 0.5) / 90.0 * std::f32::consts::PI;
            let phi = j as f32 / 180.0 * std::f32::consts::TAU;
            out.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ));
        }
    }
    for i in 0..3600 {
        let a = (i as f32 / 10.0).to_radians();
        for z in [0.0f32, 1e-6, -1e-6, 1e-3, -1e-3] {
            out.push(Vec3::new(a.cos(), a.sin(), z).normalize());
        }
        out.push(Vec3::new(0.0, a.cos(), a.sin()));
        out.push(Vec3::new(a.cos(), 0.0, a.sin()));
    }
    out
}

/// The axes encode to the square's corners, edges and centre, quantise to exact codes
/// (0, 32767, 65534) and decode to themselves exactly.
#[test]
fn axes_encode_and_decode_exactly() {
    let axes = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    let outputs = probe(&axes.map(input));
    let expected_octahedral = [
        [1.0, 0.0],
        [-1.0, 0.0],
        [0.0, 1.0],
        [0.0, -1.0],
        [0.0, 0.0],
        // The lower pole folds out to a corner of the square.
        [1.0, 1.0],
    ];
    for ((axis, out), octahedral) in axes.iter().zip(&outputs).zip(expected_octahedral) {
        assert_eq!(out.octahedral, octahedral, "{axis}");
        let code = |v: f32| (v * 32767.0 + 32767.0) as u32;
        assert_eq!(out.quantized, octahedral.map(code), "{axis}");
        let decoded = Vec3::from_slice(&out.decoded_normal_shininess[..3]);
        assert_eq!(decoded, *axis, "{axis} decodes exactly");
    }
}

/// The 16-bit round trip's angular error, bounded by derivation: quantisation moves each
/// coordinate of the square by at most d = 0.5/32767, so the unnormalised decode
/// p = (x, y, 1 - |x| - |y|) moves by at most sqrt(d^2 + d^2 + (2d)^2) = sqrt(6) d, and
/// since |p|_1 = 1 gives |p|_2 >= 1/sqrt(3), the direction turns by at most
/// sqrt(6) sqrt(3) d = 3 sqrt(2) d = 6.47e-5 rad = 0.00371 degrees; plus 1e-6 rad for f32.
#[test]
fn normal_round_trip_error_stays_within_its_derived_bound() {
    let directions = directions();
    let outputs = probe(&directions.iter().map(|n| input(*n)).collect::<Vec<_>>());
    let bound = 3.0 * 2f64.sqrt() * (0.5 / 32767.0) + 1e-6;
    let mut worst = (0.0f64, Vec3::ZERO);
    for (n, out) in directions.iter().zip(&outputs) {
        let decoded = Vec3::from_slice(&out.decoded_normal_shininess[..3]).as_dvec3();
        let angle = n.as_dvec3().angle_between(decoded);
        if angle > worst.0 {
            worst = (angle, *n);
        }
    }
    println!(
        "largest 16-bit octahedral round-trip error on the GPU: {:.5} degrees at {} (bound {:.5})",
        worst.0.to_degrees(),
        worst.1,
        bound.to_degrees()
    );
    assert!(worst.0 <= bound, "{worst:?} beyond {bound} rad");
}

/// The shininess code is log2(s)/11 (clamped to 1..2048) and decodes back to s within f32
/// rounding of exp2 and log2 (1e-5 relative, 50 times the f32 epsilon); sRGB encodes as
/// the CPU's transfer function within 1e-4 (a fortieth of an 8-bit step, far above f32
/// rounding of pow) and round-trips within 1e-4.
#[test]
fn shininess_and_srgb_match_the_cpu() {
    let shininess = [1.0f32, 1.05, 2.0, 10.0, 16.0, 64.0, 500.0, 2048.0];
    let colours = [0.0f32, 0.001, 0.003_130_8, 0.01, 0.2, 0.5, 0.9, 1.0];
    let inputs: Vec<ProbeInput> = shininess
        .iter()
        .zip(colours)
        .map(|(s, c)| ProbeInput {
            normal_shininess: [0.0, 0.0, 1.0, *s],
            color: [c, c, c, 1.0],
        })
        .collect();
    for ((s, c), out) in shininess.iter().zip(colours).zip(probe(&inputs)) {
        let code = out.srgb_shininess_code[3];
        assert!((code - s.log2() / 11.0).abs() <= 1e-6, "{s}: code {code}");
        let back = out.decoded_normal_shininess[3];
        assert!((back / s - 1.0).abs() <= 1e-5, "{s} -> {back}");
        let srgb = out.srgb_shininess_code[0];
        assert!((srgb - linear_to_srgb(c)).abs() <= 1e-4, "{c}: sRGB {srgb}");
        assert!((out.linear[0] - srgb_to_linear(srgb)).abs() <= 1e-4, "{c}");
        assert!(
            (out.linear[0] - c).abs() <= 1e-4,
            "{c} -> {}",
            out.linear[0]
        );
    }
}

/// The probe's input and output structs against the shader's (no GPU needed).
#[test]
fn probe_structs_match_wgsl() {
    use manylights_gpu::assert_wgsl_layout;
    assert_wgsl_layout!(
        codec_probe_program(),
        "deferred/codec_probe.wgsl",
        ProbeInput
            == ProbeInput {
                normal_shininess: normal_shininess,
                color: color,
            }
    );
    assert_wgsl_layout!(
        codec_probe_program(),
        "deferred/codec_probe.wgsl",
        ProbeOutput
            == ProbeOutput {
                octahedral: octahedral,
                quantized: quantized,
                decoded_normal_shininess: decoded_normal_shininess,
                srgb_shininess_code: srgb_shininess_code,
                linear: linear,
            }
    );
}
