//! The lights crate's CPU contracts, pinned: the hash, the animation path and the colours
//! must equal their WGSL twins (`shaders/lights/animate.wgsl`), which tests/naive.rs holds
//! to these functions on the GPU; so a change here is a change to every frame. The values
//! were computed by this code (x86-64, IEEE f32 without contraction, so the same on any
//! x86-64 machine); settings validation refuses each bad field on its own. Written against
//! the survivors of `cargo mutants -p manylights-lights` (docs/testing.md).

use glam::Vec3;
use manylights_lights::animation::{animated_position, hash_unit, pcg_hash};
use manylights_lights::reference::{Falloff, SurfacePoint, falloff, shade, shade_light};
use manylights_lights::{
    AnimationParams, Light, LightSet, LightSettings, RadiusMode, SPONZA_LIGHT_BOX, interior_box,
    light_color,
};
use manylights_scene::Aabb;

#[test]
fn pcg_hash_and_unit_values_are_pinned() {
    assert_eq!(pcg_hash(0), 129_708_002);
    assert_eq!(pcg_hash(1), 2_831_084_092);
    assert_eq!(pcg_hash(12_345), 4_099_845_390);
    assert_eq!(pcg_hash(u32::MAX), 3_861_530_882);
    assert_eq!(hash_unit(0).to_bits(), 1_022_846_432);
    assert_eq!(hash_unit(7).to_bits(), 1_056_755_236);
    assert_eq!(hash_unit(99).to_bits(), 1_058_764_499);
}

#[test]
fn animated_positions_are_pinned() {
    let params = AnimationParams::in_box(SPONZA_LIGHT_BOX);
    let cases = [
        ((1, 0, 0.0), [6.051962, 4.7451453, -0.4104972]),
        ((1, 42, 3.5), [-4.4093313, 1.9283786, 1.9717021]),
        ((9, 7, 100.25), [6.8548985, 1.7504816, 2.1918068]),
        ((3, 1000, 0.6), [-2.4531174, 3.9857216, -0.16309643]),
    ];
    for ((seed, index, time), expected) in cases {
        let position = animated_position(&params, seed, index, time);
        // 1e-6 m: a few f32 ulps of these coordinates, far below any mutant's change.
        assert!(
            position.distance(Vec3::from_array(expected)) < 1e-6,
            "seed {seed} light {index} t={time}: {position} instead of {expected:?}"
        );
    }
    assert_eq!(params.noise_time(2.0), 0.5, "0.25 lattice steps a second");
}

#[test]
fn light_colours_are_pinned_in_every_hue_sextant() {
    // Indices 10, 8, 4, 0, 2, 1 fall in sextants 0 to 5 of seed 5's hues.
    let cases = [
        (10, [1.0, 0.44589722, 0.0]),
        (8, [0.7216209, 1.0, 0.0]),
        (4, [0.0, 1.0, 0.3696456]),
        (0, [0.0, 0.41327524, 1.0]),
        (2, [0.46206045, 0.0, 1.0]),
        (1, [1.0, 0.0, 0.96706676]),
    ];
    for (index, expected) in cases {
        assert_eq!(
            light_color(5, index, 1.0).to_array(),
            expected,
            "light {index}"
        );
    }
}

#[test]
fn animation_settings_refuse_each_non_finite_field_and_an_empty_box() {
    let good = AnimationParams::in_box(SPONZA_LIGHT_BOX);
    assert!(good.validate().is_ok());
    let mut cases = Vec::new();
    let mut p = good;
    p.bounds.min.x = f32::NAN;
    cases.push(("min", p));
    let mut p = good;
    p.bounds.max.y = f32::INFINITY;
    cases.push(("max", p));
    let mut p = good;
    p.speed = f32::NAN;
    cases.push(("speed", p));
    let mut p = good;
    p.wander = f32::NEG_INFINITY;
    cases.push(("wander", p));
    let mut p = good;
    p.bounds = Aabb::new(Vec3::ONE, Vec3::ZERO);
    cases.push(("empty box", p));
    for (what, params) in cases {
        assert!(params.validate().is_err(), "{what} accepted");
    }
}

#[test]
fn radius_modes_and_the_interior_box() {
    assert_eq!(RadiusMode::Fixed(3.0).radius(0.7), 3.0);
    assert_eq!(RadiusMode::LuminanceThreshold(0.05).radius(0.2), 2.0);
    let inner = interior_box(&Aabb::new(Vec3::ZERO, Vec3::new(10.0, 20.0, 30.0)));
    assert_eq!(inner.min, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(inner.max, Vec3::new(9.0, 18.0, 27.0));
}

fn settings() -> LightSettings {
    LightSettings {
        count: 5,
        seed: 3,
        intensity: 0.2,
        radius: RadiusMode::Fixed(1.5),
        saturation: 0.5,
        spots: Default::default(),
        animation: AnimationParams::in_box(SPONZA_LIGHT_BOX),
        shape: manylights_lights::LightShape::Point,
    }
}

#[test]
fn generated_lights_follow_their_settings() {
    let s = settings();
    let set = LightSet::generate(&s).expect("valid settings");
    assert_eq!(set.len(), 5);
    assert!(!set.is_empty());
    assert!(LightSet::default().is_empty());
    for (index, light) in set.lights.iter().enumerate() {
        let index = index as u32;
        assert_eq!(
            light.position,
            animated_position(&s.animation, 3, index, 0.0).to_array()
        );
        assert_eq!(light.color, light_color(3, index, 0.5).to_array());
        assert_eq!((light.radius, light.intensity), (1.5, 0.2));
    }
    // Zero intensity is allowed (dark lights); each bad field is refused on its own.
    let mut dark = settings();
    dark.intensity = 0.0;
    assert!(LightSet::generate(&dark).is_ok());
    let mut bad = Vec::new();
    let mut s = settings();
    s.intensity = f32::NAN;
    bad.push(("NaN intensity", s));
    let mut s = settings();
    s.intensity = -0.1;
    bad.push(("negative intensity", s));
    let mut s = settings();
    s.radius = RadiusMode::Fixed(0.0);
    bad.push(("zero radius", s));
    let mut s = settings();
    s.radius = RadiusMode::LuminanceThreshold(0.0);
    bad.push(("zero threshold", s));
    let mut s = settings();
    s.radius = RadiusMode::LuminanceThreshold(f32::INFINITY);
    bad.push(("infinite threshold", s));
    let mut s = settings();
    s.animation.speed = f32::NAN;
    bad.push(("NaN speed", s));
    for (what, s) in bad {
        assert!(LightSet::generate(&s).is_err(), "{what} accepted");
    }
}

fn one_light() -> Light {
    Light::point(
        Vec3::new(0.0, 1.0, 0.0),
        2.0,
        Vec3::new(1.0, 0.5, 0.25),
        0.3,
    )
}

#[test]
fn light_sets_refuse_each_bad_field() {
    assert!(
        LightSet {
            lights: vec![one_light()]
        }
        .validate()
        .is_ok()
    );
    // A zero colour channel and zero intensity are fine.
    let mut edge = one_light();
    edge.color = [0.0, 1.0, 1.0];
    edge.intensity = 0.0;
    assert!(LightSet { lights: vec![edge] }.validate().is_ok());
    type Spoil = fn(&mut Light);
    let cases: [(&str, Spoil); 6] = [
        ("NaN position", |l| l.position[1] = f32::NAN),
        ("infinite radius", |l| l.radius = f32::INFINITY),
        ("zero radius", |l| l.radius = 0.0),
        ("negative radius", |l| l.radius = -1.0),
        ("negative intensity", |l| l.intensity = -0.5),
        ("negative colour", |l| l.color[2] = -0.5),
    ];
    for (what, spoil) in cases {
        let mut light = one_light();
        spoil(&mut light);
        // The bad light second: the index in the error must be 1.
        let set = LightSet {
            lights: vec![one_light(), light],
        };
        let error = set.validate().expect_err(what).to_string();
        assert!(error.contains('1'), "{what}: {error}");
    }
}

#[test]
fn falloff_modes_their_shader_codes_and_bounds() {
    assert_eq!(Falloff::WindowedInverseSquare.shader_mode(), 0);
    assert_eq!(Falloff::ReferenceProjects.shader_mode(), 1);
    assert_eq!(Falloff::InverseSquare.shader_mode(), 2);
    assert!(Falloff::WindowedInverseSquare.is_bounded());
    assert!(Falloff::ReferenceProjects.is_bounded());
    assert!(!Falloff::InverseSquare.is_bounded());
    // d = 1, r = 3 (not 2, where r * r = r + r): window 1 - (1/9)^2 = 80/81.
    let window = 80.0 / 81.0;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-15 * b;
    assert!(close(
        falloff(Falloff::WindowedInverseSquare, 1.0, 3.0),
        window * window
    ));
    assert!(close(falloff(Falloff::ReferenceProjects, 1.0, 3.0), window));
    assert_eq!(falloff(Falloff::InverseSquare, 4.0, 3.0), 0.25);
}

/// Where the floor point sits: away from the origin, so that a sign error in a difference
/// of positions shows.
const FLOOR: glam::DVec3 = glam::DVec3::new(2.0, 0.5, -1.0);

/// A light `offset` from the floor point.
fn light_over_floor(offset: [f32; 3]) -> Light {
    let mut light = one_light();
    light.position = (FLOOR.as_vec3() + Vec3::from_array(offset)).to_array();
    light
}

fn floor() -> SurfacePoint {
    SurfacePoint {
        position: FLOOR,
        normal: glam::DVec3::Y,
        albedo: glam::DVec3::new(0.5, 0.5, 0.5),
        specular: glam::DVec3::new(0.25, 0.25, 0.25),
        emission: glam::DVec3::ZERO,
        lobe: 8.0,
        shading: manylights_lights::reference::Shading::BlinnPhong,
    }
}

#[test]
fn a_light_above_a_floor_shades_by_the_formula() {
    // Light 1 m above the floor at x = 0.5, eye straight above: n.l = 1/sqrt(1.25),
    // d^2 = 1.25, half vector between l and the view direction.
    let light = light_over_floor([0.5, 1.0, 0.0]);
    let view = glam::DVec3::Y;
    let to_light = glam::DVec3::new(0.5, 1.0, 0.0);
    let l = to_light.normalize();
    let n_dot_l = l.y;
    let half = (l + view).normalize();
    let specular = 0.25 * half.y.powf(8.0);
    let window = 1.0 - (1.25f64 / 4.0).powi(2);
    let scale = 0.3 * window * window / 1.25 * n_dot_l * (0.5 + specular);
    let expected = glam::DVec3::new(1.0, 0.5, 0.25) * scale;
    let got = shade_light(&floor(), view, &light, Falloff::WindowedInverseSquare);
    assert!(
        (got - expected).abs().max_element() < 1e-7 * expected.max_element(),
        "{got} {expected}"
    );
    // `shade` takes the view direction from the camera position.
    let camera = FLOOR + glam::DVec3::new(0.0, 5.0, 0.0);
    let summed = shade(
        &floor(),
        camera,
        &[light, light],
        Falloff::WindowedInverseSquare,
    );
    assert!((summed - 2.0 * expected).abs().max_element() < 1e-7 * expected.max_element());
    // A camera off to the side changes the specular term.
    let side = shade(
        &floor(),
        FLOOR + glam::DVec3::new(-3.0, 1.0, 0.0),
        &[light],
        Falloff::WindowedInverseSquare,
    );
    assert!((side - expected).abs().max_element() > 1e-3 * expected.max_element());
    // At the radius exactly, the bounded modes give 0; the unbounded one does not.
    // (The bounded modes' early return at the radius is also what their window gives there
    // and beyond: replacing r * r by r + r in it changes nothing, an equivalent mutant.)
    let mut at_radius = light_over_floor([0.0, 1.0, 0.0]);
    at_radius.radius = 1.0;
    for bounded in [Falloff::ReferenceProjects, Falloff::WindowedInverseSquare] {
        assert_eq!(
            shade_light(&floor(), view, &at_radius, bounded),
            glam::DVec3::ZERO
        );
    }
    assert!(shade_light(&floor(), view, &at_radius, Falloff::InverseSquare).max_element() > 0.0);
    // An eye exactly opposite the light (below the floor): the half vector is zero, and the
    // specular term must be dropped rather than normalised into NaN.
    let above = light_over_floor([0.0, 1.0, 0.0]);
    let below = glam::DVec3::new(0.0, -1.0, 0.0);
    let g = shade_light(&floor(), below, &above, Falloff::InverseSquare);
    assert!(g.is_finite() && g.max_element() > 0.0, "{g}");
}
