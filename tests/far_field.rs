//! The far field (issue 16) on the GPU (lavapipe in CI): with tolerance 0 the light tree
//! renders naive's unbounded inverse-square image in every clustered shading loop; a tree
//! frame is bit-reproducible; a looser tolerance costs accuracy but stays far closer to the
//! unbounded image than the radius alone; the stochastic estimator's mean over seeds
//! converges to the reference (a statistical test with a stated false-failure rate); and
//! the extremes (all lights in one spot, lights far outside the scene, a light inside a
//! surface, an empty far field, 1,000,000 lights) render finite images in bounded memory;
//! the tree sorts its lights stably by leaf cell over a box that is the lights' own; an
//! aggregate straddling a surface lights it as its lights do; an aggregate of flat lights
//! facing one way lights what they face.

use glam::{Vec2, Vec3};
use manylights::cluster::{FarField, FarFieldMethod};
use manylights::lights::{Falloff, Light, LightSet, RadiusMode};
use manylights::{Camera, FrameSettings, GBufferLayout, LoadedScene, PipelineSettings, Renderer};
use manylights_tests::{assert_hdr_close, assert_lit, clustered_variants, fixed_lights, gpu};

fn renderer(scene: &str, size: (u32, u32)) -> (Renderer, FrameSettings) {
    let loaded = LoadedScene::load(scene).expect("scene");
    let mut settings = FrameSettings::for_scene(&loaded);
    settings.view.size = size;
    settings.lights.time = 0.75;
    settings.lights.count = 200;
    // A radius of 1 m leaves most of the light to the far field.
    settings.lights.radius = RadiusMode::Fixed(1.0);
    (Renderer::new(gpu(), loaded).expect("renderer"), settings)
}

fn far(method: FarFieldMethod, tolerance: f32, seed: u32) -> FarField {
    FarField {
        seed,
        ..FarField::with_tolerance(method, tolerance)
    }
}

fn render(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f32; 4]> {
    renderer.render_frame(settings).expect("frame");
    let image = renderer.read_hdr().expect("hdr");
    assert!(
        image.iter().all(|p| p.iter().all(|v| v.is_finite())),
        "a far-field frame has a NaN or infinite pixel"
    );
    image
}

/// The naive pipeline's unbounded inverse-square image: the ground truth.
fn naive_inverse_square(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<[f32; 4]> {
    let mut naive = settings.clone();
    naive.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    render(renderer, &naive)
}

fn with_far_field(
    settings: &FrameSettings,
    pipeline: PipelineSettings,
    far_field: Option<FarField>,
) -> FrameSettings {
    let mut settings = settings.clone();
    settings.pipeline = pipeline;
    let falloff = if far_field.is_some() {
        Falloff::InverseSquare
    } else {
        Falloff::WindowedInverseSquare
    };
    settings.set_falloff(falloff, far_field).expect("settings");
    settings
}

fn mean_relative_error(reference: &[[f32; 4]], image: &[[f32; 4]]) -> f64 {
    let errors = manylights_tests::relative_errors(reference, image);
    errors.iter().sum::<f64>() / errors.len().max(1) as f64
}

#[test]
fn the_tree_at_tolerance_zero_renders_the_unbounded_image_in_every_clustered_loop() {
    for scene in ["cornell", "sponza"] {
        let (mut renderer, settings) = renderer(scene, (96, 64));
        let reference = naive_inverse_square(&mut renderer, &settings);
        assert_lit(scene, &reference, 0.3);
        // The lossless layout: the comparison is the shading loops', not the G-buffer's.
        for pipeline in clustered_variants(GBufferLayout::Full) {
            let exact =
                with_far_field(&settings, pipeline, Some(far(FarFieldMethod::Tree, 0.0, 0)));
            let image = render(&mut renderer, &exact);
            // The same tolerance as Forward+ against naive: one half-float ulp plus 1e-4
            // (two sums of the same terms, near and far, instead of one).
            let worst = assert_hdr_close(
                &format!("{scene} {} tree:0", pipeline.describe()),
                &reference,
                &image,
                1e-4,
            );
            println!(
                "{scene} {}: tree at tolerance 0, worst relative {worst:.2e}",
                pipeline.describe()
            );
            // The comparison can fail: the radius alone is visibly darker.
            let radius_only = render(&mut renderer, &with_far_field(&settings, pipeline, None));
            assert!(
                mean_relative_error(&reference, &radius_only) > 0.1,
                "{scene}: the radius-only image is as close as the far field's: the test proves nothing"
            );
        }
    }
}

#[test]
fn the_stochastic_method_at_tolerance_zero_is_exact_too() {
    let (mut renderer, settings) = renderer("cornell", (64, 48));
    let reference = naive_inverse_square(&mut renderer, &settings);
    for pipeline in clustered_variants(GBufferLayout::Full) {
        let exact = with_far_field(
            &settings,
            pipeline,
            Some(far(FarFieldMethod::Stochastic, 0.0, 3)),
        );
        let image = render(&mut renderer, &exact);
        assert_hdr_close(
            &format!("{} stochastic:0", pipeline.describe()),
            &reference,
            &image,
            1e-4,
        );
    }
}

#[test]
fn a_far_field_frame_is_reproducible_and_the_seed_moves_only_the_noise() {
    let (mut renderer, settings) = renderer("sponza", (96, 64));
    let pipeline = PipelineSettings::default();
    let tree = with_far_field(&settings, pipeline, Some(far(FarFieldMethod::Tree, 0.3, 0)));
    let first = render(&mut renderer, &tree);
    let again = render(&mut renderer, &tree);
    assert!(
        first.iter().zip(&again).all(|(a, b)| a == b),
        "two tree frames of the same settings differ"
    );
    let stochastic = |seed| {
        with_far_field(
            &settings,
            pipeline,
            Some(far(FarFieldMethod::Stochastic, 1.0, seed)),
        )
    };
    let seed_1 = render(&mut renderer, &stochastic(1));
    assert_eq!(
        seed_1,
        render(&mut renderer, &stochastic(1)),
        "one seed, two images"
    );
    assert_ne!(
        seed_1,
        render(&mut renderer, &stochastic(2)),
        "two seeds, one image"
    );
}

#[test]
fn a_looser_tree_costs_accuracy_but_beats_the_radius_alone() {
    let (mut renderer, settings) = renderer("sponza", (96, 64));
    let reference = naive_inverse_square(&mut renderer, &settings);
    let pipeline = PipelineSettings::forward_plus();
    let error = |renderer: &mut Renderer, far_field| {
        let image = render(renderer, &with_far_field(&settings, pipeline, far_field));
        mean_relative_error(&reference, &image)
    };
    let radius_only = error(&mut renderer, None);
    let tight = error(&mut renderer, Some(far(FarFieldMethod::Tree, 0.01, 0)));
    let loose = error(&mut renderer, Some(far(FarFieldMethod::Tree, 3.0, 0)));
    println!(
        "mean relative error: radius only {radius_only:.4}, tree:3 {loose:.4}, tree:0.01 {tight:.4}"
    );
    assert!(
        tight <= loose,
        "a tighter tolerance was less accurate ({tight} > {loose})"
    );
    assert!(
        loose < radius_only / 4.0,
        "the loose tree ({loose}) is not far closer than the radius alone ({radius_only})"
    );
}

/// The mean over seeds of the stochastic estimate converges to the unbounded image.
///
/// Statistic: the sum of the HDR image over a region (the whole image and its four
/// quadrants), per seed. Each is a sum of many independent per-light terms, so over `SEEDS`
/// seeds its mean is close to normal with standard error s / sqrt(SEEDS) (s: the sample
/// standard deviation over seeds). The test fails when |mean - reference| exceeds
/// `Z` standard errors plus the half-float storage's rounding (at most 2^-11 of each
/// pixel). With Z = 5 a correct estimator fails a region with probability about 6e-7
/// (normal tails; Student's t with 63 degrees of freedom: about 5e-6), so the five regions
/// together fail in fewer than 3 of 100,000 runs. A biased estimator (one that drops the
/// reweighting, say) is off by far more than that (checked below against the radius alone,
/// whose bias it would share).
#[test]
fn the_stochastic_mean_over_seeds_converges_to_the_reference() {
    const SEEDS: u32 = 64;
    const Z: f64 = 5.0;
    let (mut renderer, mut settings) = renderer("cornell", (48, 32));
    settings.pipeline =
        PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Compute);
    let reference = naive_inverse_square(&mut renderer, &settings);
    let (width, height) = (settings.view.size.0 as usize, settings.view.size.1 as usize);
    // (name, columns, rows): the image and its quadrants.
    let (half_w, half_h) = (width / 2, height / 2);
    let regions = [
        ("image", 0..width, 0..height),
        ("top left", 0..half_w, 0..half_h),
        ("top right", half_w..width, 0..half_h),
        ("bottom left", 0..half_w, half_h..height),
        ("bottom right", half_w..width, half_h..height),
    ];
    let sum = |image: &[[f32; 4]],
               columns: &std::ops::Range<usize>,
               rows: &std::ops::Range<usize>|
     -> f64 {
        image
            .iter()
            .enumerate()
            .filter(|(i, _)| columns.contains(&(i % width)) && rows.contains(&(i / width)))
            .map(|(_, p)| p[..3].iter().map(|&v| f64::from(v)).sum::<f64>())
            .sum()
    };
    let mut sums = vec![Vec::new(); regions.len()];
    for seed in 0..SEEDS {
        let image = render(
            &mut renderer,
            &with_far_field(
                &settings,
                settings.pipeline,
                Some(far(FarFieldMethod::Stochastic, 4.0, seed)),
            ),
        );
        for (k, (_, columns, rows)) in regions.iter().enumerate() {
            sums[k].push(sum(&image, columns, rows));
        }
    }
    let radius_only = render(
        &mut renderer,
        &with_far_field(&settings, settings.pipeline, None),
    );
    for (k, (name, columns, rows)) in regions.iter().enumerate() {
        let want = sum(&reference, columns, rows);
        let n = f64::from(SEEDS);
        let mean = sums[k].iter().sum::<f64>() / n;
        let variance = sums[k].iter().map(|s| (s - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let standard_error = (variance / n).sqrt();
        let rounding = want * 2f64.powi(-11);
        println!(
            "{name}: reference {want:.4}, mean of {SEEDS} seeds {mean:.4}, standard error {standard_error:.4}"
        );
        assert!(
            variance > 0.0,
            "{name}: every seed gave the same image: no noise, no test"
        );
        assert!(
            (mean - want).abs() <= Z * standard_error + rounding,
            "{name}: the mean over {SEEDS} seeds, {mean}, is {:.1} standard errors from the reference {want}",
            (mean - want).abs() / standard_error
        );
        // The test can fail: the radius alone (the far field dropped) is well outside
        // its tolerance.
        let dropped = sum(&radius_only, columns, rows);
        assert!(
            (dropped - want).abs() > 3.0 * (Z * standard_error + rounding),
            "{name}: the radius-only image ({dropped}) is within the test's tolerance of {want}"
        );
    }
}

/// Every far field, tree (tolerance 0 and loose) and stochastic, in Forward+ and deferred:
/// finite, and the exact tree equals naive.
fn check_extreme(label: &str, renderer: &mut Renderer, settings: &FrameSettings) {
    let reference = naive_inverse_square(renderer, settings);
    for pipeline in [
        PipelineSettings::forward_plus(),
        PipelineSettings::deferred(GBufferLayout::Full, manylights::LightingPath::Compute),
    ] {
        for far_field in [
            far(FarFieldMethod::Tree, 0.0, 0),
            far(FarFieldMethod::Tree, 1.0, 0),
            far(FarFieldMethod::Stochastic, 1.0, 7),
        ] {
            let image = render(
                renderer,
                &with_far_field(settings, pipeline, Some(far_field)),
            );
            if far_field.tolerance == 0.0 {
                assert_hdr_close(&format!("{label} {far_field}"), &reference, &image, 1e-4);
            }
        }
    }
}

#[test]
fn extremes_all_lights_in_one_spot_far_outside_inside_a_surface_and_an_empty_far_field() {
    let (mut renderer, settings) = renderer("cornell", (48, 32));
    let spot = Vec3::new(0.3, 1.5, 0.2);
    let cases: Vec<(&str, LightSet)> = vec![
        (
            "1,000 lights in one spot",
            fixed_lights(&vec![(spot, 0.5, 0.05); 1000]),
        ),
        (
            "lights far outside the scene (1e5 m) beside lights inside",
            fixed_lights(&[
                (Vec3::new(1e5, 2e5, -1e5), 0.5, 1e9),
                (Vec3::new(-3e5, 0.0, 1e5), 0.5, 1e9),
                (spot, 0.5, 0.2),
                (Vec3::new(-1.0, 1.0, -1.0), 0.5, 0.2),
            ]),
        ),
        (
            // The cornell room's floor is at y = 0: a light 1 mm below it, one on it.
            "a light inside a surface",
            fixed_lights(&[
                (Vec3::new(0.0, -0.001, 0.0), 0.5, 0.2),
                (Vec3::new(0.5, 0.0, 0.5), 0.5, 0.2),
                (spot, 0.5, 0.2),
            ]),
        ),
        (
            // Radii wider than the room: every light is exact, the far field adds nothing.
            "an empty far field",
            fixed_lights(&[(spot, 50.0, 0.2), (Vec3::new(-1.0, 2.0, 1.0), 50.0, 0.2)]),
        ),
    ];
    for (label, lights) in cases {
        renderer.set_fixed_lights(&lights).expect("lights");
        check_extreme(label, &mut renderer, &settings);
    }
}

/// Checks the light tree's sort (`far_field.wgsl`'s keys, histogram, scan and scatter over
/// blocks of 4,096 lights): every light once, keys in order, equal keys in light order
/// (stable), and the leaf cells spanning the lights' box from its first cell to its last
/// along every axis (the box, a workgroup reduction of the lights' positions, is the
/// lights' own: a box too large would leave the last cells empty).
fn assert_tree_order(label: &str, order: &[(u32, u32)], lights: u32) {
    assert_eq!(order.len(), lights as usize, "{label}: sorted lights");
    let mut seen = vec![false; lights as usize];
    for &(_, light) in order {
        assert!(
            !std::mem::replace(&mut seen[light as usize], true),
            "{label}: light {light} sorted twice"
        );
    }
    for (at, pair) in order.windows(2).enumerate() {
        assert!(
            pair[0] < pair[1],
            "{label}: at {at}, (key, light) {:?} before {:?}",
            pair[0],
            pair[1]
        );
    }
    // The Morton code's cells along each axis (x in the lowest of each 3 bits).
    let cell =
        |key: u32, axis: u32| (0..10).fold(0, |c, bit| c | ((key >> (3 * bit + axis)) & 1) << bit);
    let last = (1u32 << manylights::cluster::tree_levels(lights)) - 1;
    for axis in 0..3 {
        let cells = order.iter().map(|&(key, _)| cell(key, axis));
        let (low, high) = cells.fold((u32::MAX, 0), |(l, h), c| (l.min(c), h.max(c)));
        if lights > 1 {
            assert_eq!((low, high), (0, last), "{label}: axis {axis}'s cells");
        }
    }
}

/// Renders a frame with the tree at tolerance 1 and reads its sorted (key, light) pairs.
fn tree_order(renderer: &mut Renderer, settings: &FrameSettings) -> Vec<(u32, u32)> {
    let settings = with_far_field(
        settings,
        PipelineSettings::default(),
        Some(far(FarFieldMethod::Tree, 1.0, 0)),
    );
    renderer.render_frame(&settings).expect("frame");
    renderer.read_far_field_order().expect("order")
}

#[test]
fn the_trees_sort_is_stable_and_spans_the_lights_box() {
    // One light, exactly one block, and three blocks with a partial last one (about one
    // light per leaf cell in the second, so many keys are equal).
    let (mut renderer, mut settings) = renderer("cornell", (32, 24));
    for lights in [1, 4096, 10_000] {
        settings.lights.count = lights;
        let order = tree_order(&mut renderer, &settings);
        assert_tree_order(&format!("{lights} lights"), &order, lights);
    }
}

/// The tree's leaf keys and sort against the CPU, exactly: lights at the centres of the
/// leaf cells of a box from (0, 0, 0) to (cells, cells, cells) (two lights at its corners
/// set it), so every light's cell is exact in f32 on any device (a power-of-two extent
/// divides exactly). 9,000 lights: three sort blocks, the last partial, and about 1,200
/// lights sharing a cell with an earlier one (the sort must keep them in light order).
#[test]
fn the_trees_keys_and_sort_equal_the_cpus_on_a_lattice() {
    let count = 9_000u32;
    let cells = 1u32 << manylights::cluster::tree_levels(count);
    let mut state = 0x9e37_79b9u32;
    let mut next_cell = || {
        // xorshift32: a fixed sequence of cells.
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state % cells
    };
    let mut positions = Vec::new();
    while positions.len() < count as usize - 2 {
        let cell = [next_cell(), next_cell(), next_cell()];
        positions.push(Vec3::from(cell.map(|c| c as f32 + 0.5)));
    }
    // The corners last: the box is every workgroup's, not the first's.
    positions.extend([Vec3::ZERO, Vec3::splat(cells as f32)]);
    let morton = |cell: [u32; 3]| {
        (0..10).fold(0u32, |code, bit| {
            (0..3).fold(code, |code, axis| {
                code | ((cell[axis] >> bit) & 1) << (3 * bit + axis as u32)
            })
        })
    };
    let mut expected: Vec<(u32, u32)> = positions
        .iter()
        .zip(0..)
        .map(|(p, light)| {
            (
                morton(p.to_array().map(|v| (v as u32).min(cells - 1))),
                light,
            )
        })
        .collect();
    expected.sort_unstable();

    let (mut renderer, mut settings) = renderer("cornell", (32, 24));
    // World-space positions: relative to the camera they would not be whole numbers.
    settings.view.camera_relative = false;
    let lights: Vec<(Vec3, f32, f32)> = positions.iter().map(|&p| (p, 0.5, 1.0)).collect();
    renderer
        .set_fixed_lights(&fixed_lights(&lights))
        .expect("lights");
    let order = tree_order(&mut renderer, &settings);
    assert_tree_order("lattice", &order, count);
    let first_wrong = order.iter().zip(&expected).position(|(a, b)| a != b);
    assert_eq!(
        first_wrong, None,
        "the GPU's (key, light) differ from the CPU's from position {first_wrong:?}"
    );
}

#[test]
fn a_million_lights_with_either_far_field() {
    let (mut renderer, mut settings) = renderer("cornell", (32, 24));
    settings.lights.count = 1_000_000;
    settings.lights.radius = RadiusMode::Fixed(0.05);
    for far_field in [
        far(FarFieldMethod::Tree, 1.0, 0),
        far(FarFieldMethod::Stochastic, 64.0, 0),
    ] {
        let settings = with_far_field(&settings, PipelineSettings::default(), Some(far_field));
        renderer
            .render_frame(&settings)
            .unwrap_or_else(|e| panic!("{far_field}: {e}"));
        let image = renderer.read_hdr().expect("hdr");
        assert!(
            image.iter().all(|p| p.iter().all(|v| v.is_finite())),
            "{far_field}: not finite"
        );
        assert_lit(&format!("1,000,000 lights, {far_field}"), &image, 0.5);
        if far_field.method == FarFieldMethod::Tree {
            let order = renderer.read_far_field_order().expect("order");
            assert_tree_order("1,000,000 lights", &order, 1_000_000);
        }
    }
}

/// An aggregate whose box straddles a surface lights it as its lights do (issue 58: convex
/// stone beside the lights was dark, in blocks). An even 6 x 6 x 6 lattice of lights
/// straddles the cornell floor, and one slot makes the whole tree one aggregate. Its power
/// centroid lies on the floor, so a centroid evaluation lights the floor not at all, while
/// the lattice's upper half does. The four-point average over the node's box
/// (`shade_aggregate`) must give each floor pixel at least 4 half-widths from the lattice
/// what the lights give, within `TOLERANCE`.
///
/// The tolerance, derived: seen from the floor the upper half's lights count by their
/// height (n.l times the distance is the height), and the design's two points above the
/// floor sit at half / sqrt(3) of the box, against the upper half's mean height of half / 2
/// in the continuum (0.96 of it for this lattice, whose box ends at its outer lights):
/// within 16%. What the design leaves out is third order in half / distance, at most
/// (1/4)^2 = 6% more from 4 half-widths. So within 25% (the centroid is 100% off).
#[test]
fn an_aggregate_straddling_a_surface_lights_it() {
    const TOLERANCE: f64 = 0.25;
    let (mut renderer, mut settings) = renderer("cornell", (64, 48));
    settings.lights.radius = RadiusMode::Fixed(0.05);
    let centre = Vec3::new(0.9, 0.0, -1.2);
    settings.view.camera = looking_down_at_the_floor();
    let half = 0.25;
    let steps = 6;
    let lattice: Vec<(Vec3, f32, f32)> = lattice(centre, half, steps)
        .map(|at| (at, 0.05, 0.02))
        .collect();
    renderer
        .set_fixed_lights(&fixed_lights(&lattice))
        .expect("lights");
    let reference = naive_inverse_square(&mut renderer, &settings);
    let one_aggregate = one_aggregate();
    let settings = with_far_field(&settings, PipelineSettings::default(), Some(one_aggregate));
    let image = render(&mut renderer, &settings);
    let cuts = renderer.read_far_field_cuts().expect("cuts");
    assert!(
        cuts.iter().all(|cut| cut.len() <= 1),
        "one slot: a cut of more than one entry"
    );
    let surface = renderer.capture_surface(&settings).expect("surface");
    let mut judged = 0;
    let mut worst: f64 = 0.0;
    for (i, position) in surface.position.iter().enumerate() {
        let world = surface.origin.as_vec3() + Vec3::from_slice(&position[..3]);
        let on_floor =
            position[3] == 1.0 && surface.normal_lobe[i][1] > 0.99 && world.y.abs() < 1e-3;
        if !on_floor || (world - centre).length() < 4.0 * half {
            continue;
        }
        let want = f64::from(reference[i][1]);
        assert!(want > 0.0, "floor pixel {i} is black in the reference");
        let error = (f64::from(image[i][1]) - want).abs() / want;
        worst = worst.max(error);
        assert!(
            error <= TOLERANCE,
            "floor pixel ({}, {}) at {world}: the aggregate gives {}, the lights {want} ({:.0}% off)",
            i as u32 % surface.size.0,
            i as u32 / surface.size.0,
            image[i][1],
            100.0 * error
        );
        judged += 1;
    }
    println!("{judged} floor pixels, worst relative error {worst:.3}");
    assert!(judged >= 200, "only {judged} floor pixels judged");
}

/// Flat lights that all face one way light what they face, and the tree's aggregate of them
/// says so (`light_emission_dipole`): 216 small squares in a lattice 1 m over the cornell
/// room's floor, reach 5 cm (the floor is lit by the far field alone), one aggregate.
/// - Facing up, they light none of the floor: the aggregate sends a flat light's mean
///   intensity I/4 plus its first band I n.w / 2, nothing where n.w <= -1/2, and the floor
///   pixels judged see the lattice at least 33 degrees below its horizontal (n.w <= -0.55:
///   0 exactly). Without the dipole every one of them would get I/4.
/// - Facing down, the floor gets I n.w: the two bands give between 0.85 and 0.95 of it at
///   n.w from 0.55 to 0.71 (up to 45 degrees), and the aggregate's four points err by up to
///   25% more (`an_aggregate_straddling_a_surface_lights_it`): within 40%, where I/4 alone
///   would be 45% to 65% low.
#[test]
fn an_aggregate_of_flat_lights_lights_what_they_face() {
    let (mut renderer, mut settings) = renderer("cornell", (64, 48));
    settings.view.camera = looking_down_at_the_floor();
    let centre = Vec3::new(0.0, 1.0, -1.0);
    let (half, steps, side) = (0.25, 6, 0.01);
    let lattice = |facing: f32| -> LightSet {
        // first x second = +Y for facing 1, -Y for -1.
        let edges = (Vec3::Z * side / 2.0, Vec3::X * (facing * side / 2.0));
        let lights = lattice(centre, half, steps)
            .map(|at| Light::rect(at, 0.05, Vec3::ONE, 0.05, edges))
            .collect();
        LightSet { lights }
    };
    let one_aggregate = one_aggregate();
    let far_settings = with_far_field(&settings, PipelineSettings::default(), Some(one_aggregate));
    for (facing, tolerance) in [(1.0f32, None), (-1.0, Some(0.4))] {
        renderer.set_fixed_lights(&lattice(facing)).expect("lights");
        let reference = naive_inverse_square(&mut renderer, &settings);
        let image = render(&mut renderer, &far_settings);
        let surface = renderer.capture_surface(&far_settings).expect("surface");
        let (mut judged, mut worst) = (0, 0.0f64);
        for (i, position) in surface.position.iter().enumerate() {
            let world = surface.origin.as_vec3() + Vec3::from_slice(&position[..3]);
            let on_floor =
                position[3] == 1.0 && surface.normal_lobe[i][1] > 0.99 && world.y.abs() < 1e-3;
            let across = Vec2::new(world.x - centre.x, world.z - centre.z).length();
            // 1.0 m below the lattice's centre: from 0.6 m to 1.0 m aside, the lattice is
            // 45 to 33 degrees below the horizontal (its own extent shifts that by 14%).
            if !on_floor || !(0.6..1.0).contains(&across) {
                continue;
            }
            let (got, want) = (f64::from(image[i][1]), f64::from(reference[i][1]));
            match tolerance {
                None => assert!(
                    got == 0.0 && want == 0.0,
                    "facing up, floor pixel {i} at {world}: the aggregate gives {got}, the lights {want}"
                ),
                Some(tolerance) => {
                    assert!(want > 0.0, "facing down, floor pixel {i} is black");
                    let error = (got - want).abs() / want;
                    worst = worst.max(error);
                    assert!(
                        error <= tolerance,
                        "facing down, floor pixel {i} at {world}: the aggregate gives {got}, the lights {want} ({:.0}% off)",
                        100.0 * error
                    );
                }
            }
            judged += 1;
        }
        println!("facing {facing}: {judged} floor pixels, worst relative error {worst:.3}");
        assert!(
            judged >= 50,
            "facing {facing}: only {judged} floor pixels judged"
        );
    }
}

/// From above the cornell room's front edge, looking down at the floor.
fn looking_down_at_the_floor() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 2.8, 1.9),
        Vec3::new(0.0, 0.0, -0.5),
        70.0,
        0.05,
        20.0,
    )
}

/// A cubic lattice of `steps`^3 points filling the box of half-width `half` about `centre`,
/// each at its cell's centre.
fn lattice(centre: Vec3, half: f32, steps: usize) -> impl Iterator<Item = Vec3> {
    (0..steps * steps * steps).map(move |i| {
        let cell = Vec3::new(
            (i % steps) as f32,
            (i / steps % steps) as f32,
            (i / (steps * steps)) as f32,
        );
        centre + ((cell + 0.5) / steps as f32 * 2.0 - 1.0) * half
    })
}

/// The tree with one slot: each cluster's far field is a single aggregate.
fn one_aggregate() -> FarField {
    FarField {
        slots: 1,
        ..FarField::with_tolerance(FarFieldMethod::Tree, 1.0)
    }
}

/// The tree's slots dial: every cluster's cut holds at most its slots, a frame with more
/// slots uses them (some cut is longer than the fewer slots allow), and with the tolerance
/// tight enough that the slots bind, more slots bring the image closer to the unbounded
/// one (on average over the lit pixels: a longer cut refines where the bounds are largest,
/// which need not help every pixel).
#[test]
fn more_slots_make_longer_cuts_and_a_closer_image() {
    let (mut renderer, mut settings) = renderer("sponza", (128, 96));
    settings.lights.count = 20_000;
    settings.lights.radius = RadiusMode::Fixed(0.5);
    let pipeline = PipelineSettings::default();
    let reference = naive_inverse_square(&mut renderer, &settings);
    assert_lit("sponza inverse-square", &reference, 0.2);
    let mut errors = Vec::new();
    for slots in [8, 64, 256] {
        let far_field = FarField {
            slots,
            ..FarField::with_tolerance(FarFieldMethod::Tree, 0.01)
        };
        let image = render(
            &mut renderer,
            &with_far_field(&settings, pipeline, Some(far_field)),
        );
        let cuts = renderer.read_far_field_cuts().expect("cuts");
        let longest = cuts.iter().map(Vec::len).max().unwrap_or(0);
        assert!(
            longest <= slots as usize,
            "{slots} slots: a cut of {longest} entries"
        );
        if slots > 8 {
            assert!(
                longest > 8,
                "{slots} slots: no cut is longer than 8 entries, the dial did nothing"
            );
        }
        errors.push((slots, mean_relative_error(&reference, &image)));
    }
    println!("mean relative error by slots: {errors:?}");
    for pair in errors.windows(2) {
        assert!(
            pair[1].1 < pair[0].1,
            "{} slots gave {:.4}, no better than {} slots' {:.4}",
            pair[1].0,
            pair[1].1,
            pair[0].0,
            pair[0].1
        );
    }
}

#[test]
fn settings_say_what_a_far_field_can_complete() {
    let loaded = LoadedScene::load("cornell").expect("cornell");
    let mut settings = FrameSettings::for_scene(&loaded);
    let tree = Some(FarField::new(FarFieldMethod::Tree));
    assert!(settings.set_falloff(Falloff::InverseSquare, None).is_err());
    assert!(
        settings
            .set_falloff(Falloff::ReferenceProjects, tree)
            .is_err()
    );
    settings
        .set_falloff(Falloff::InverseSquare, tree)
        .expect("inverse-square with a tree");
    assert_eq!(settings.rendered_falloff(), Falloff::InverseSquare);
    assert_eq!(settings.pipeline.falloff(), Falloff::WindowedInverseSquare);
    settings.pipeline = PipelineSettings::naive(Falloff::InverseSquare);
    let error = settings
        .set_falloff(Falloff::InverseSquare, tree)
        .unwrap_err();
    assert!(error.contains("no far field"), "{error}");
}
