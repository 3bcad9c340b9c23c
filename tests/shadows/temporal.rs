//! The ray budget's temporal accumulation (`Shadows::RaysTemporal`): a still view stops
//! flickering, a light switched off leaves the image at once where it mattered and within a
//! stated number of frames elsewhere, and the history follows surfaces as the camera moves.

use super::{SIZE, cornell, floor_and_wall, render, walled};
use glam::Vec3;
use manylights::visibility::SHADOW_HISTORY_FRAMES;
use manylights::{
    Camera, Exposure, FrameSettings, GBufferLayout, LightingPath, PipelineSettings, Renderer,
    Shadows,
};
use manylights_tests::{assert_lit, fixed_lights, gpu};

/// How far the history may stray from this frame's filtered share
/// (`HISTORY_MARGIN` in `shaders/visibility/shadow_filter.wgsl`).
const HISTORY_MARGIN: f64 = 0.15;

fn luminance(p: &[f32; 4]) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// Renders `frames` frames, each with its own seed from `first_seed`, and returns the last
/// two.
pub(super) fn last_frames(
    renderer: &mut Renderer,
    settings: &mut FrameSettings,
    first_seed: u32,
    frames: u32,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let mut images = Vec::new();
    for frame in 0..frames {
        settings.shadows.seed = first_seed + frame;
        images.push(render(renderer, settings));
    }
    let last = images.pop().expect("frames");
    (images.pop().expect("two frames"), last)
}

/// The exact and the unshadowed frame of `settings`, and the pixels in partial shadow
/// (at least 1,000 of them).
fn partly_shadowed(
    renderer: &mut Renderer,
    settings: &mut FrameSettings,
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>, Vec<usize>) {
    let mode = settings.shadows.mode;
    settings.shadows.mode = Shadows::Exact;
    let exact = render(renderer, settings);
    settings.shadows.mode = Shadows::Off;
    let unshadowed = render(renderer, settings);
    settings.shadows.mode = mode;
    let partial: Vec<usize> = (0..exact.len())
        .filter(|&i| {
            let (e, u) = (luminance(&exact[i]), luminance(&unshadowed[i]));
            u > 0.0 && e > 1e-3 * u && e < (1.0 - 1e-3) * u
        })
        .collect();
    assert!(
        partial.len() >= 1000,
        "only {} partially shadowed pixels",
        partial.len()
    );
    (exact, unshadowed, partial)
}

/// The warm-up fills the history with draws of their own (issue 80): the frame after it
/// is about a third as far from the converged filtered frame as the frame after sixteen
/// frames of one seed (the old warm-up's history: one frame's filtered noise sixteen
/// times, which stood still as blotches). Converged: the mean of 16 spatially filtered
/// frames of their own seeds (its noise 1/sqrt(16) of a frame's; the filter's blur, which
/// no history removes, is in it too). With independent draws the history's noise is
/// 1/sqrt(16) of a frame's, sqrt(1/16 + 1/16) = 0.35 of it from the converged frame;
/// with one seed 15/16 of the frame's is left after the next frame, sqrt(0.88 + 0.06) =
/// 0.97. The bound, 0.6, leaves room for the pixels the history is held at.
#[test]
fn the_warm_up_fills_the_history_with_independent_draws() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Full, LightingPath::Tiles);
    let (_, unshadowed, partial) = partly_shadowed(&mut renderer, &mut settings);
    settings.shadows.mode = Shadows::RaysSpatial(1);
    let draws = 16;
    let mut converged = vec![0.0; unshadowed.len()];
    for seed in 0..draws {
        settings.shadows.seed = 5000 + seed;
        let frame = render(&mut renderer, &settings);
        for (sum, pixel) in converged.iter_mut().zip(&frame) {
            *sum += luminance(pixel) / f64::from(draws);
        }
    }
    settings.shadows.seed = 0;
    settings.shadows.mode = Shadows::RaysTemporal(1);
    let distance = |image: &[[f32; 4]]| {
        partial
            .iter()
            .map(|&i| (luminance(&image[i]) - converged[i]).abs() / luminance(&unshadowed[i]))
            .sum::<f64>()
            / partial.len() as f64
    };
    let policy = manylights::WarmUpPolicy {
        min_frames: SHADOW_HISTORY_FRAMES,
        max_frames: SHADOW_HISTORY_FRAMES,
        max_seconds: f64::INFINITY,
        ..manylights::WarmUpPolicy::default()
    };
    manylights::warm_up(&mut renderer, &settings, &policy).expect("warm-up");
    let after_warm_up = distance(&render(&mut renderer, &settings));
    let (mut fresh, _) = cornell(64);
    let mut one_seed = settings.clone();
    one_seed.shadows.seed = 1000;
    for _ in 0..SHADOW_HISTORY_FRAMES {
        render(&mut fresh, &one_seed);
    }
    let after_one_seed = distance(&render(&mut fresh, &settings));
    eprintln!(
        "from the converged frame: after the warm-up {after_warm_up:.5}, after one seed {after_one_seed:.5}"
    );
    assert!(
        after_warm_up < 0.6 * after_one_seed,
        "after the warm-up {after_warm_up:.5}, after one seed {after_one_seed:.5}"
    );
}

/// A still view stops flickering once its history is full. On the cornell room's 64
/// lights, the frame-to-frame change over the partially shadowed pixels (as a share of
/// their unshadowed light) must fall to a quarter of the spatial filter's alone.
///
/// Why a quarter: with a full history each frame moves the share by a sixteenth of the
/// difference between this frame's filtered share and the history, which is about the
/// difference between two frames' filtered shares (the history's own noise is a fifth of
/// a frame's). So the change falls to about 1/16 of the filter's alone; the bound leaves
/// four times that for the pixels where the history is held to this frame's share.
#[test]
fn a_still_view_stops_flickering_once_its_history_is_full() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Full, LightingPath::Tiles);
    let (_, unshadowed, partial) = partly_shadowed(&mut renderer, &mut settings);
    let flicker = |(before, after): (Vec<[f32; 4]>, Vec<[f32; 4]>)| {
        partial
            .iter()
            .map(|&i| {
                (luminance(&after[i]) - luminance(&before[i])).abs() / luminance(&unshadowed[i])
            })
            .sum::<f64>()
            / partial.len() as f64
    };
    settings.shadows.mode = Shadows::RaysSpatial(1);
    let spatial = flicker(last_frames(&mut renderer, &mut settings, 0, 2));
    settings.shadows.mode = Shadows::RaysTemporal(1);
    let temporal = flicker(last_frames(
        &mut renderer,
        &mut settings,
        0,
        SHADOW_HISTORY_FRAMES + 2,
    ));
    eprintln!("flicker: spatial filter {spatial:.5}, with history {temporal:.5}");
    assert!(spatial > 1e-3, "one filtered ray must flicker: {spatial}");
    assert!(
        temporal < spatial / 4.0,
        "the history left flicker {temporal:.5}, against {spatial:.5} without it"
    );
}

/// A light switched off leaves the image at once wherever it gave more than 5% of a
/// pixel's unshadowed light (the history is dropped there), and within a stated number of
/// frames elsewhere. A wall across a floor; light A on the camera's side, light B behind
/// the wall, reaching the near floor only through it (unshadowed, it would light it).
/// Under both, the near floor's share is A's part of its light; once A is off, it is 0,
/// and the near floor must be black.
///
/// In deferred's compute lighting and in Forward+'s shadow pass alike:
/// - Where A gave more than 6% (5% and rounding room), the first frame is exactly black.
/// - Elsewhere the history is held within `HISTORY_MARGIN` (0.15) of the new share, 0, and
///   each frame keeps 15/16 of it: after k frames at most 0.15 (15/16)^k of B's light, under
///   1% within 42 frames. Checked after 1 and 16 frames.
#[test]
fn a_light_switched_off_leaves_the_image_within_the_stated_frames() {
    // Deferred's compute lighting, and Forward+'s shadow pass.
    for pipeline in [
        PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Compute),
        PipelineSettings::forward_plus(),
    ] {
        a_light_switched_off_leaves(pipeline);
    }
}

fn a_light_switched_off_leaves(pipeline: PipelineSettings) {
    let light_a = (Vec3::new(-3.0, 0.5, 0.0), 2.5, 3.0);
    let light_b = (Vec3::new(1.0, 0.5, 0.0), 6.0, 4.0);
    let (mut renderer, mut settings) = walled(&[light_a, light_b]);
    settings.pipeline = pipeline;
    let set_lights = |renderer: &mut Renderer, lights: &[(Vec3, f32, f32)]| {
        renderer
            .set_fixed_lights(&fixed_lights(lights))
            .expect("lights");
    };
    settings.shadows.mode = Shadows::Off;
    let both = render(&mut renderer, &settings);
    set_lights(&mut renderer, &[light_b]);
    let only_b = render(&mut renderer, &settings);
    let surface = renderer.capture_surface(&settings).expect("surface");
    // The near floor, where B's light arrives unshadowed.
    let near_floor: Vec<usize> = (0..both.len())
        .filter(|&i| {
            let position = surface.position[i];
            position[3] == 1.0
                && surface.normal_lobe[i][1] > 0.5
                && f64::from(position[0]) + surface.origin.x < -1e-3
                && luminance(&only_b[i]) > 0.0
        })
        .collect();
    let a_mattered = |i: usize| {
        let (all, b) = (luminance(&both[i]), luminance(&only_b[i]));
        all - b > 0.06 * all
    };
    let mattered = near_floor.iter().filter(|&&i| a_mattered(i)).count();
    eprintln!(
        "{} near-floor pixels, A gave more than 6% at {mattered}",
        near_floor.len()
    );
    assert!(
        mattered > 500 && near_floor.len() - mattered > 100,
        "the test needs pixels where A mattered and where it did not"
    );

    settings.shadows.mode = Shadows::RaysTemporal(1);
    set_lights(&mut renderer, &[light_a, light_b]);
    last_frames(&mut renderer, &mut settings, 0, SHADOW_HISTORY_FRAMES + 2);
    set_lights(&mut renderer, &[light_b]);
    let mut frames_since = 0;
    let mut seed = 100;
    for check_at in [1, 16] {
        let mut image = Vec::new();
        while frames_since < check_at {
            settings.shadows.seed = seed;
            seed += 1;
            image = render(&mut renderer, &settings);
            frames_since += 1;
        }
        let bound = HISTORY_MARGIN * (15.0f64 / 16.0).powi(check_at);
        for &i in &near_floor {
            let (left, light) = (luminance(&image[i]), luminance(&only_b[i]));
            if a_mattered(i) {
                assert_eq!(
                    image[i][..3],
                    [0.0; 3],
                    "{pipeline:?}: {check_at} frames after A went off, pixel {i} still shows light"
                );
            }
            assert!(
                left <= bound * light * 1.01 + 1e-6,
                "{pipeline:?}: {check_at} frames after A went off, pixel {i} shows {:.4} of its light, over {bound:.4}",
                left / light
            );
        }
    }
}

/// The history is held to this frame's neighbourhood: a light moving sideways sweeps a
/// wall's shadow across the floor while each floor pixel's unshadowed light changes by
/// under 4% (the light moves across its line of sight, 10 m away), so the history is kept
/// (`LIGHT_CHANGE` is 5%) and only the clamp stops it. After 18 frames lit (share 1),
/// one frame after the move a pixel now fully in shadow (its whole filter footprint
/// shadowed: the spatial filter alone gives exactly 0) may show at most `HISTORY_MARGIN`
/// x 15/16 of its light: the clamped history plus a sixteenth of the step to 0. An
/// unclamped history shows 15/16 of it.
#[test]
fn a_moving_shadow_clamps_the_history_to_the_new_frame() {
    use manylights::visibility::test_scenes::{closed_box, merged, plane};
    let floor = plane(6.0, glam::Mat4::IDENTITY);
    let wall = closed_box(Vec3::new(-0.05, 0.0, -6.0), Vec3::new(0.05, 3.0, 0.0));
    let light_at = |z: f32| [(Vec3::new(8.0, 2.0, z), 30.0, 50.0)];
    let (before, after) = (light_at(2.0), light_at(-2.0));
    let camera = Camera::look_at(
        Vec3::new(-2.0, 6.0, 1.0),
        Vec3::new(-2.0, 0.0, 0.0),
        40.0,
        0.05,
        100.0,
    );
    let (mut renderer, mut settings) =
        super::built_scene("wall end", merged([floor, wall]), SIZE, camera, &before);
    for pipeline in [
        PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Compute),
        PipelineSettings::forward_plus(),
    ] {
        settings.pipeline = pipeline;
        let mut frame = |renderer: &mut Renderer, light: &[(Vec3, f32, f32)], shadows| {
            renderer
                .set_fixed_lights(&fixed_lights(light))
                .expect("lights");
            settings.shadows.mode = shadows;
            render(renderer, &settings)
        };
        let unshadowed_before = frame(&mut renderer, &before, Shadows::Off);
        let unshadowed_after = frame(&mut renderer, &after, Shadows::Off);
        let lit_before = frame(&mut renderer, &before, Shadows::RaysSpatial(1));
        let shadowed_after = frame(&mut renderer, &after, Shadows::RaysSpatial(1));
        // Swept: lit before (filtered share 1), in shadow after (0), under about the same
        // unshadowed light.
        let swept: Vec<usize> = (0..unshadowed_after.len())
            .filter(|&i| {
                let (was, now) = (
                    luminance(&unshadowed_before[i]),
                    luminance(&unshadowed_after[i]),
                );
                now > 0.0
                    && (now - was).abs() <= 0.04 * was.max(now)
                    && lit_before[i] == unshadowed_before[i]
                    && shadowed_after[i][..3] == [0.0; 3]
            })
            .collect();
        eprintln!("{pipeline:?}: {} swept pixels", swept.len());
        assert!(
            swept.len() > 300,
            "the shadow must sweep floor pixels under a steady light"
        );
        renderer
            .set_fixed_lights(&fixed_lights(&before))
            .expect("lights");
        settings.shadows.mode = Shadows::RaysTemporal(1);
        last_frames(&mut renderer, &mut settings, 0, SHADOW_HISTORY_FRAMES + 2);
        renderer
            .set_fixed_lights(&fixed_lights(&after))
            .expect("lights");
        settings.shadows.seed = 100;
        let image = render(&mut renderer, &settings);
        let bound = HISTORY_MARGIN * 15.0 / 16.0;
        for &i in &swept {
            let (left, light) = (luminance(&image[i]), luminance(&unshadowed_after[i]));
            assert!(
                left <= bound * light * 1.01 + 1e-6,
                "{pipeline:?}: a frame after the shadow swept pixel {i}, it shows {:.4} of its light, over {bound:.4}",
                left / light
            );
        }
    }
}

/// The history is of the same surface: a camera move uncovers floor that a plate hid, and
/// the history read there is the plate's. A plate 2.5 m up over a floor, lit from 200 m
/// straight above: its top is lit (share 1) and the floor under it in its shadow (share
/// 0), under unshadowed light within 3% of the plate's (200^2 / 197.5^2), so the light
/// check keeps the plate's history and only the distance check drops it. After 18 frames
/// from one side, the camera moves 3 m to the other: every floor pixel that the plate hid
/// from the first camera, in shadow with its whole filter footprint (the spatial filter
/// alone gives exactly 0), must be exactly black at once. The plate's history would
/// leave up to `HISTORY_MARGIN` of its light there.
#[test]
fn a_surface_uncovered_by_a_camera_move_starts_without_history() {
    use manylights::visibility::test_scenes::{closed_box, merged, plane};
    let (plate_min, plate_max) = (Vec3::new(-1.0, 2.5, -3.0), Vec3::new(1.0, 2.55, 3.0));
    let floor = plane(8.0, glam::Mat4::IDENTITY);
    let camera_at = |x: f32| Camera::look_at(Vec3::new(x, 3.5, 0.2), Vec3::ZERO, 60.0, 0.05, 100.0);
    let (first, second) = (Vec3::new(-1.5, 3.5, 0.2), camera_at(1.5));
    let (mut renderer, mut settings) = super::built_scene(
        "plate",
        merged([floor, closed_box(plate_min, plate_max)]),
        (256, 192),
        second,
        &[(Vec3::new(0.0, 200.0, 0.0), 400.0, 4e4)],
    );
    // Whether the plate hides `point` on the floor from `eye`, 5 cm inside its edges (9
    // pixels there from the first camera): the history read for it is the plate's, not
    // the floor's beside the plate's silhouette.
    let hidden_from = |eye: Vec3, point: Vec3| {
        let t = (eye.y - plate_min.y) / (eye.y - point.y);
        let crossing = eye + t * (point - eye);
        (plate_min.x + 0.05..=plate_max.x - 0.05).contains(&crossing.x)
            && (plate_min.z + 0.05..=plate_max.z - 0.05).contains(&crossing.z)
    };
    for pipeline in [
        PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Compute),
        PipelineSettings::forward_plus(),
    ] {
        settings.pipeline = pipeline;
        settings.view.camera = second;
        settings.shadows.mode = Shadows::Off;
        let unshadowed = render(&mut renderer, &settings);
        settings.shadows.mode = Shadows::RaysSpatial(1);
        let spatial = render(&mut renderer, &settings);
        let surface = renderer.capture_surface(&settings).expect("surface");
        let uncovered: Vec<usize> = (0..spatial.len())
            .filter(|&i| {
                let point = (surface.origin
                    + Vec3::from_slice(&surface.position[i][..3]).as_dvec3())
                .as_vec3();
                surface.position[i][3] == 1.0
                    && point.y.abs() < 1e-3
                    && luminance(&unshadowed[i]) > 0.0
                    && spatial[i][..3] == [0.0; 3]
                    && hidden_from(first, point)
            })
            .collect();
        eprintln!("{pipeline:?}: {} uncovered pixels", uncovered.len());
        assert!(
            uncovered.len() > 300,
            "the move must uncover shadowed floor"
        );
        settings.view.camera = camera_at(first.x);
        settings.shadows.mode = Shadows::RaysTemporal(1);
        last_frames(&mut renderer, &mut settings, 0, SHADOW_HISTORY_FRAMES + 2);
        settings.view.camera = second;
        settings.shadows.seed = 100;
        let image = render(&mut renderer, &settings);
        for &i in &uncovered {
            assert_eq!(
                image[i][..3],
                [0.0; 3],
                "{pipeline:?}: pixel {i}, uncovered by the move, shows light from the plate's history"
            );
        }
    }
}

/// The history follows each surface as the camera moves (it is read where the surface was
/// last frame, through `view.previous_view_proj`), and so keeps averaging while the view
/// moves. A camera straight above a floor moves 3 pixels a frame (exactly, at the floor's
/// depth) across the shadows a short wall throws from 24 lights behind it, lit in Lambert
/// alone (light that does not change with the view, so nothing rejects a surface's
/// history). At each camera, the target is the spatial filter's mean over 32 seeds
/// there; one filtered frame misses it by its noise. With history the frame averages up
/// to 16 frames of the same surface points and must miss it by less than half as much
/// (averaging n frames divides the noise by the square root of n: a quarter at 16, and
/// the history reaches 16 frames before the camera moves). A history read where the pixel
/// is now, not where its surface was, is dropped where the light differs (or kept where
/// it does not, and blurs the shadows along the motion): no better than one frame.
/// Compared on the floor's partially shadowed pixels, away from the wall and from the
/// image's borders, where the filter's walk ends differently as the view moves.
#[test]
fn the_history_follows_surfaces_as_the_camera_moves() {
    let mut settings = FrameSettings::for_scene(&floor_and_wall(0.25));
    settings.shading = manylights::lights::Shading::BlinnPhong;
    settings.view.size = SIZE;
    settings.post.exposure = Exposure::Manual(1.0);
    // The full layout stores each pixel's position as rasterized, which moves only by
    // roundings with the camera (a position rebuilt from depth moves the shadow ray's start
    // by its error bound, which grows with the distance from the camera).
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Full, LightingPath::Compute);
    let height = 4.0f32;
    let fov_y = 60.0f32;
    let mut camera = Camera::look_at(
        Vec3::new(-1.0, height, 0.0),
        Vec3::new(-1.0, 0.0, -1.0),
        fov_y,
        0.05,
        100.0,
    );
    camera.yaw = 0.0;
    camera.pitch = -std::f32::consts::FRAC_PI_2;
    settings.view.camera = camera;
    let lights: Vec<(Vec3, f32, f32)> = (0..24)
        .map(|i| {
            let (column, row) = ((i % 4) as f32, (i / 4) as f32);
            let position = Vec3::new(0.3 + 0.5 * column, 0.2 + 0.15 * row, -2.0 + 0.8 * row);
            (position, 6.0, 0.5)
        })
        .collect();
    // The frames with history, and the same frames without it (a frame without history
    // drops it, so they are rendered apart).
    let mut renderer = Renderer::new(gpu(), floor_and_wall(0.25)).expect("renderer");
    let mut without_history = Renderer::new(gpu(), floor_and_wall(0.25)).expect("renderer");
    for renderer in [&mut renderer, &mut without_history] {
        renderer
            .set_fixed_lights(&fixed_lights(&lights))
            .expect("lights");
    }
    let pixel_at_floor = 2.0 * height * (fov_y.to_radians() / 2.0).tan() / SIZE.1 as f32;
    const STEP_PIXELS: u32 = 3;
    const MOVES: u32 = 3;
    const SEEDS: u32 = 32;
    // Pixels whose filter taps (6 a side) lay inside the image at every camera.
    let margin = 6 + 1;
    let interior = |i: usize| {
        let (x, y) = ((i as u32) % SIZE.0, (i as u32) / SIZE.0);
        x >= margin
            && x + margin + STEP_PIXELS * MOVES < SIZE.0
            && y >= margin
            && y + margin < SIZE.1
    };

    settings.shadows.mode = Shadows::RaysTemporal(1);
    let mut seed = 0;
    for _ in 0..SHADOW_HISTORY_FRAMES {
        settings.shadows.seed = seed;
        seed += 1;
        render(&mut renderer, &settings);
    }
    let (mut with_history, mut one_frame, mut compared) = (0.0, 0.0, 0);
    for step in 1..=MOVES {
        settings.view.camera.position.x = -1.0 + (step * STEP_PIXELS) as f32 * pixel_at_floor;
        settings.shadows.seed = seed;
        seed += 1;
        let temporal = render(&mut renderer, &settings);
        let mut alone = settings.clone();
        alone.shadows.mode = Shadows::Off;
        let unshadowed = render(&mut without_history, &alone);
        let surface = without_history.capture_surface(&alone).expect("surface");
        alone.shadows.mode = Shadows::RaysSpatial(1);
        let mut mean = vec![0.0f64; temporal.len()];
        let mut single = Vec::new();
        for k in 0..SEEDS {
            alone.shadows.seed = 1000 * step + k;
            let frame = render(&mut without_history, &alone);
            for (sum, pixel) in mean.iter_mut().zip(&frame) {
                *sum += luminance(pixel) / f64::from(SEEDS);
            }
            if k == 0 {
                single = frame;
            }
        }
        for i in (0..temporal.len()).filter(|&i| interior(i)) {
            let position = surface.position[i];
            let wall_distance = (f64::from(position[0]) + surface.origin.x).abs();
            let light = luminance(&unshadowed[i]);
            let share = mean[i] / light.max(1e-12);
            if position[3] != 1.0
                || surface.normal_lobe[i][1] < 0.99
                || wall_distance < 8.0 * f64::from(pixel_at_floor)
                || !(0.05..=0.95).contains(&share)
            {
                continue;
            }
            compared += 1;
            with_history += (luminance(&temporal[i]) - mean[i]).abs() / light;
            one_frame += (luminance(&single[i]) - mean[i]).abs() / light;
        }
    }
    let (with_history, one_frame) = (with_history / compared as f64, one_frame / compared as f64);
    eprintln!(
        "{compared} partially shadowed floor pixels: off the 32-seed mean by {one_frame:.4} in one frame, {with_history:.4} with history"
    );
    assert!(compared > 1000, "only {compared} partially shadowed pixels");
    assert!(
        one_frame > 0.01,
        "one filtered frame must be noisy: {one_frame}"
    );
    assert!(
        with_history < one_frame / 2.0,
        "with history {with_history:.4}, one frame {one_frame:.4}: the history did not follow the surfaces"
    );
}

/// A pipeline's history belongs to the frame before: after frames drawn by another
/// pipeline, it starts afresh. Forward+ fills its history over 17 frames, one deferred
/// frame follows, and the next Forward+ frame must be its first with history: the spatial
/// filter's frame for the same seed, bit for bit (a frame without history keeps the
/// filtered share exactly). A history kept across the switch would average it with 16
/// frames the lights and camera may no longer match.
#[test]
fn a_pipeline_switch_starts_the_history_afresh() {
    let (mut renderer, mut settings) = cornell(64);
    settings.pipeline = PipelineSettings::forward_plus();
    settings.shadows.mode = Shadows::RaysTemporal(1);
    last_frames(&mut renderer, &mut settings, 0, SHADOW_HISTORY_FRAMES + 1);
    settings.pipeline = PipelineSettings::deferred(GBufferLayout::Compact, LightingPath::Tiles);
    render(&mut renderer, &settings);
    settings.pipeline = PipelineSettings::forward_plus();
    settings.shadows.seed = 1000;
    let after_switch = render(&mut renderer, &settings);
    settings.shadows.mode = Shadows::RaysSpatial(1);
    let first_frame = render(&mut renderer, &settings);
    assert_lit("Forward+ after the switch", &after_switch, 0.3);
    assert!(
        after_switch == first_frame,
        "the history survived a frame of another pipeline"
    );
}
