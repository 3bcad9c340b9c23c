//! The light (point, spot, or an area: sphere, rectangle, triangle) and the light set:
//! layout, seeded generation, and radius from intensity.

use glam::Vec3;
use manylights_scene::{Aabb, SpotCone};

use crate::animation::{AnimationParams, animated_position};
use crate::error::LightError;

/// A light as stored in GPU buffers: a point light, a spot light (a point light whose
/// emission is limited to a cone, as glTF's `KHR_lights_punctual` spot), or an area light:
/// a sphere, a rectangle or a triangle emitting a uniform radiance (one-sided for the flat
/// two). Mirrors `struct Light` in `shaders/lights/light_set.wgsl` (64 bytes, std430; a
/// test checks the offsets). Build one with [`Light::point`], [`Light::spot`],
/// [`Light::sphere`], [`Light::rect`] or [`Light::triangle`].
///
/// The last 28 bytes depend on the kind (one layout for all keeps every light 64 bytes,
/// which the shading loops read per light):
/// - spot: `direction` the cone's axis, `sin2_outer` and `sin2_inner` its angles;
/// - sphere: `extent` the sphere's radius;
/// - rectangle: `position` its centre, `direction` and [`Light::second_edge`] (the
///   `sin2_outer`, `sin2_inner` and `extent` fields) its two half-edges, at right angles;
///   its corners are centre +- first +- second, and it emits towards first x second;
/// - triangle: `position` its centroid, `direction` and [`Light::second_edge`] the offsets
///   of two corners from it (the third is at -first - second); it emits towards
///   first x second.
///
/// `intensity` is, for every kind, the radiant intensity along the light's axis (a flat
/// light's normal; a sphere's in every direction): at a distance large against its size,
/// an area light is the point light of that intensity (times the cosine at the light for
/// the flat ones). Its radiance is `intensity / projected area` ([`Light::emitted_radiance`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Light {
    pub position: [f32; 3],
    /// Distance at which windowed falloffs reach zero.
    pub radius: f32,
    /// Linear RGB, brightest channel 1.
    pub color: [f32; 3],
    /// Radiance at 1 m (on the spot's axis, an area light's normal) is `color * intensity`.
    pub intensity: f32,
    /// Spot lights: the unit direction the cone points along. Zero for point lights and
    /// spheres; the first edge of rectangles and triangles.
    pub direction: [f32; 3],
    /// [`LIGHT_POINT`], [`LIGHT_SPOT`], [`LIGHT_SPHERE`], [`LIGHT_RECT`] or
    /// [`LIGHT_TRIANGLE`].
    pub kind: u32,
    /// Spot lights: sin^2 of the outer cone's half-angle (nothing outside is lit). Stored
    /// as sin^2 rather than cos because cos(1e-4) rounds to 1 in f32 while sin^2 keeps
    /// full precision: the shading and the cone tests stay exact for needle-thin cones.
    pub sin2_outer: f32,
    /// Spot lights: sin^2 of the inner half-angle (full intensity inside).
    pub sin2_inner: f32,
    /// Spheres: the radius. Rectangles and triangles: the second edge's z.
    pub extent: f32,
    pub _pad: f32,
}

/// `Light::kind` of a point light.
pub const LIGHT_POINT: u32 = 0;
/// `Light::kind` of a spot light.
pub const LIGHT_SPOT: u32 = 1;
/// `Light::kind` of a sphere light. Every kind from here on is an area light.
pub const LIGHT_SPHERE: u32 = 2;
/// `Light::kind` of a rectangle light.
pub const LIGHT_RECT: u32 = 3;
/// `Light::kind` of a triangle light.
pub const LIGHT_TRIANGLE: u32 = 4;

impl Light {
    /// A point light.
    pub fn point(position: Vec3, radius: f32, color: Vec3, intensity: f32) -> Self {
        Self {
            position: position.to_array(),
            radius,
            color: color.to_array(),
            intensity,
            direction: [0.0; 3],
            kind: LIGHT_POINT,
            sin2_outer: 0.0,
            sin2_inner: 0.0,
            extent: 0.0,
            _pad: 0.0,
        }
    }

    /// A sphere light of radius `sphere_radius` emitting `intensity` in every direction;
    /// `radius` is its reach (from its centre). A sphere of no size is the point light
    /// (its radiance, intensity over no area, would be infinite).
    pub fn sphere(
        position: Vec3,
        radius: f32,
        color: Vec3,
        intensity: f32,
        sphere_radius: f32,
    ) -> Self {
        if sphere_radius <= 0.0 {
            return Self::point(position, radius, color, intensity);
        }
        Self {
            kind: LIGHT_SPHERE,
            extent: sphere_radius,
            ..Self::point(position, radius, color, intensity)
        }
    }

    /// A rectangle light centred on `position` with half-edges `first` and `second` (at
    /// right angles), emitting towards `first x second` with `intensity` along that normal.
    pub fn rect(
        position: Vec3,
        radius: f32,
        color: Vec3,
        intensity: f32,
        (first, second): (Vec3, Vec3),
    ) -> Self {
        Self {
            kind: LIGHT_RECT,
            ..Self::point(position, radius, color, intensity).with_edges(first, second)
        }
    }

    /// A triangle light with corners `corners`, emitting towards
    /// `(b - a) x (c - a)` (counter-clockwise as seen from the lit side) with radiance
    /// `color * radiance`; `radius` is its reach from its centroid.
    pub fn triangle(corners: [Vec3; 3], radius: f32, color: Vec3, radiance: f32) -> Self {
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        let area = 0.5
            * (corners[1] - corners[0])
                .cross(corners[2] - corners[0])
                .length();
        Self {
            kind: LIGHT_TRIANGLE,
            ..Self::point(centroid, radius, color, radiance * area)
                .with_edges(corners[0] - centroid, corners[1] - centroid)
        }
    }

    fn with_edges(self, first: Vec3, second: Vec3) -> Self {
        Self {
            direction: first.to_array(),
            sin2_outer: second.x,
            sin2_inner: second.y,
            extent: second.z,
            ..self
        }
    }

    /// A rectangle's or triangle's second edge (see [`Light`]).
    pub fn second_edge(&self) -> Vec3 {
        Vec3::new(self.sin2_outer, self.sin2_inner, self.extent)
    }

    /// Whether the light is a sphere, a rectangle or a triangle.
    pub fn is_area(&self) -> bool {
        self.kind >= LIGHT_SPHERE
    }

    /// A rectangle's corners (4) or a triangle's (3), counter-clockwise seen from the lit
    /// side; empty for other kinds.
    pub fn corners(&self) -> Vec<Vec3> {
        let centre = Vec3::from_array(self.position);
        let first = Vec3::from_array(self.direction);
        let second = self.second_edge();
        match self.kind {
            LIGHT_RECT => vec![
                centre - first - second,
                centre + first - second,
                centre + first + second,
                centre - first + second,
            ],
            LIGHT_TRIANGLE => vec![centre + first, centre + second, centre - first - second],
            _ => Vec::new(),
        }
    }

    /// The light's area (0 for points and spots; a sphere's projected disk).
    pub fn area(&self) -> f32 {
        let first = Vec3::from_array(self.direction);
        match self.kind {
            LIGHT_SPHERE => std::f32::consts::PI * self.extent * self.extent,
            LIGHT_RECT => 4.0 * first.cross(self.second_edge()).length(),
            // The corners are c + a, c + b, c - a - b: edges b - a and -2a - b, whose cross
            // product is 3 (a x b).
            LIGHT_TRIANGLE => 1.5 * first.cross(self.second_edge()).length(),
            _ => 0.0,
        }
    }

    /// The radiance an area light emits (`color` times this), its intensity over its
    /// projected area; 0 for an area light of no area, which [`Light::is_area`] lights
    /// shade as the point they are.
    pub fn emitted_radiance(&self) -> f32 {
        let area = self.area();
        if area > 0.0 {
            self.intensity / area
        } else {
            0.0
        }
    }

    /// This light reaching `range` beyond its farthest point (its radius: `range` plus
    /// [`Light::bounding_radius`]).
    pub fn reaching(self, range: f32) -> Self {
        Self {
            radius: range + self.bounding_radius(),
            ..self
        }
    }

    /// The distance from the light's position to its farthest point (0 for points and
    /// spots): what its reach adds to the range of its intensity.
    pub fn bounding_radius(&self) -> f32 {
        let centre = Vec3::from_array(self.position);
        match self.kind {
            LIGHT_SPHERE => self.extent,
            LIGHT_RECT | LIGHT_TRIANGLE => self
                .corners()
                .iter()
                .map(|corner| corner.distance(centre))
                .fold(0.0, f32::max),
            _ => 0.0,
        }
    }

    /// A spot light pointing along `direction` (normalised here; a zero direction gives
    /// a zero axis, which [`LightSet::validate`] refuses).
    pub fn spot(
        position: Vec3,
        radius: f32,
        color: Vec3,
        intensity: f32,
        direction: Vec3,
        cone: SpotCone,
    ) -> Self {
        let sin2 = |angle: f32| (angle as f64).sin().powi(2) as f32;
        Self {
            direction: direction.normalize_or_zero().to_array(),
            kind: LIGHT_SPOT,
            sin2_outer: sin2(cone.outer),
            sin2_inner: sin2(cone.inner),
            ..Self::point(position, radius, color, intensity)
        }
    }

    pub fn is_spot(&self) -> bool {
        self.kind == LIGHT_SPOT
    }

    /// The spot's cone (`None` for a point light).
    pub fn cone(&self) -> Option<SpotCone> {
        self.is_spot().then(|| SpotCone {
            inner: (self.sin2_inner as f64).sqrt().asin() as f32,
            outer: (self.sin2_outer as f64).sqrt().asin() as f32,
        })
    }
}

/// How each light's radius is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RadiusMode {
    /// The same radius for every light (the reference projects use 2 m in Sponza).
    Fixed(f32),
    /// The distance at which the unwindowed inverse-square illuminance drops to this
    /// threshold: radius = sqrt(intensity / threshold). Lights reach exactly as far as
    /// they matter; the threshold is the main speed/accuracy knob.
    LuminanceThreshold(f32),
}

impl RadiusMode {
    pub fn radius(&self, intensity: f32) -> f32 {
        match *self {
            RadiusMode::Fixed(radius) => radius,
            RadiusMode::LuminanceThreshold(threshold) => (intensity / threshold).sqrt(),
        }
    }
}

/// The light box of the reference projects in Sponza, inside its court.
pub const SPONZA_LIGHT_BOX: Aabb = Aabb {
    min: Vec3::new(-10.0, 0.0, -5.0),
    max: Vec3::new(10.0, 8.0, 5.0),
};

/// The fraction by which other scenes' bounds are shrunk (on each side) to get a light box
/// inside the scene rather than on its walls.
pub const INTERIOR_SHRINK: f32 = 0.1;

/// The light box for a scene: its bounds shrunk by [`INTERIOR_SHRINK`] on every side.
pub fn interior_box(bounds: &Aabb) -> Aabb {
    let margin = bounds.size() * INTERIOR_SHRINK;
    Aabb::new(bounds.min + margin, bounds.max - margin)
}

/// Everything that decides a generated light set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSettings {
    pub count: u32,
    pub seed: u32,
    pub intensity: f32,
    pub radius: RadiusMode,
    /// Colour saturation in [0, 1]: 1 is a pure random hue, 0 is white.
    pub saturation: f32,
    pub animation: AnimationParams,
    /// The spots among the generated lights.
    pub spots: SpotSettings,
    /// The shape of the generated lights that are not spots.
    pub shape: LightShape,
}

/// The shape of generated lights (`--light-shape`, `bench --light-shapes`: `point`,
/// `sphere:SIZE`, `rect:SIZE`, its [`std::str::FromStr`] and [`std::fmt::Display`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum LightShape {
    /// Point lights.
    #[default]
    Point,
    /// Spheres of this diameter, in metres, emitting the settings' intensity in every
    /// direction.
    Sphere(f32),
    /// Squares of this side, in metres, each facing a random direction of the lower
    /// hemisphere (as a spot would point: lights hung in a room light its floor and walls),
    /// with the settings' intensity along its normal.
    Rect(f32),
}

impl LightShape {
    /// The shape named `point`, `sphere` or `rect`, of `size` metres (ignored for points).
    pub fn new(name: &str, size: f32) -> Result<Self, String> {
        match name {
            "point" => Ok(Self::Point),
            "sphere" => Ok(Self::Sphere(size)),
            "rect" => Ok(Self::Rect(size)),
            other => Err(format!(
                "unknown light shape '{other}' (point, sphere or rect)"
            )),
        }
    }

    /// `point`, `sphere` or `rect`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Point => "point",
            Self::Sphere(_) => "sphere",
            Self::Rect(_) => "rect",
        }
    }

    /// The size in metres (a sphere's diameter, a square's side; 0 for points).
    pub fn size(&self) -> f32 {
        match *self {
            Self::Point => 0.0,
            Self::Sphere(size) | Self::Rect(size) => size,
        }
    }

    /// A finite size, positive for a square (a square of no size has no normal) and not
    /// negative for a sphere (one of no size is the point light).
    pub fn validate(&self) -> Result<(), LightError> {
        let size = self.size();
        let valid = match self {
            Self::Point => true,
            Self::Sphere(_) => size.is_finite() && size >= 0.0,
            Self::Rect(_) => size.is_finite() && size > 0.0,
        };
        if valid {
            Ok(())
        } else {
            Err(LightError::Settings(format!(
                "the light size must be a finite {} number of metres, got {size}",
                if matches!(self, Self::Rect(_)) {
                    "positive"
                } else {
                    "non-negative"
                }
            )))
        }
    }

    /// Light `index` of a generated set, at `position` and of `color`, in this shape;
    /// `range` is how far its intensity reaches, to which its size is added.
    fn light(
        &self,
        (seed, index): (u32, u32),
        position: Vec3,
        color: Vec3,
        (intensity, range): (f32, f32),
    ) -> Light {
        match *self {
            Self::Point => Light::point(position, range, color, intensity),
            Self::Sphere(diameter) => {
                Light::sphere(position, range, color, intensity, 0.5 * diameter).reaching(range)
            }
            Self::Rect(side) => {
                let normal = spot_direction(seed, index, 1.0).unwrap_or(Vec3::NEG_Y);
                // glam's basis is Duff et al.'s (2017): first x second = normal.
                let (first, second) = normal.any_orthonormal_pair();
                let half = 0.5 * side;
                Light::rect(
                    position,
                    range,
                    color,
                    intensity,
                    (first * half, second * half),
                )
                .reaching(range)
            }
        }
    }
}

impl LightSettings {
    /// Finite, non-negative intensity; a finite positive radius or threshold; saturation
    /// and spot fraction within 0..1; a valid animation box and spot cone; or why not.
    pub fn validate(&self) -> Result<(), LightError> {
        let check = |name: &str, value: f32, positive: bool| {
            if !value.is_finite() || (positive && value <= 0.0) {
                Err(LightError::Settings(format!(
                    "{name} must be a finite positive number, got {value}"
                )))
            } else {
                Ok(())
            }
        };
        check("intensity", self.intensity, false)?;
        if self.intensity < 0.0 {
            return Err(LightError::Settings(format!(
                "intensity must not be negative, got {}",
                self.intensity
            )));
        }
        match self.radius {
            RadiusMode::Fixed(r) => check("radius", r, true)?,
            RadiusMode::LuminanceThreshold(t) => check("luminance threshold", t, true)?,
        }
        if !(0.0..=1.0).contains(&self.saturation) {
            return Err(LightError::Settings(format!(
                "saturation must be between 0 and 1, got {}",
                self.saturation
            )));
        }
        self.animation.validate()?;
        if !(0.0..=1.0).contains(&self.spots.fraction) {
            return Err(LightError::Settings(format!(
                "the spot fraction must be between 0 and 1, got {}",
                self.spots.fraction
            )));
        }
        self.spots
            .cone
            .validate()
            .map_err(|e| LightError::Settings(format!("spot cone: {e}")))?;
        self.shape.validate()
    }
}

/// Which generated lights are spots, and their cones.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct SpotSettings {
    /// The fraction of lights that are spots, in [0, 1] (chosen per light by a hash of
    /// the seed and its index, so a fraction of 0.5 gives about half).
    pub fraction: f32,
    /// Every generated spot's cone.
    pub cone: SpotCone,
}

impl Default for SpotSettings {
    /// No spots; cones of 20 and 30 degrees when the fraction is raised.
    fn default() -> Self {
        Self {
            fraction: 0.0,
            cone: SpotCone {
                inner: 20f32.to_radians(),
                outer: 30f32.to_radians(),
            },
        }
    }
}

/// Default colour saturation: pure random hues, like the reference projects' random
/// colours, so individual pools of light stay visible. (Before, colours were mixed 80%
/// toward white: saturation 0.2.)
pub const DEFAULT_SATURATION: f32 = 1.0;

/// A set of point lights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightSet {
    pub lights: Vec<Light>,
}

impl LightSet {
    /// Generates `settings.count` lights, deterministic for a given seed: positions from
    /// the animation function at time 0, colours a random hue at the settings' saturation,
    /// intensity and radius from the settings.
    pub fn generate(settings: &LightSettings) -> Result<Self, LightError> {
        settings.validate()?;
        let radius = settings.radius.radius(settings.intensity);
        let lights = (0..settings.count)
            .map(|index| {
                let position = animated_position(&settings.animation, settings.seed, index, 0.0);
                let color = light_color(settings.seed, index, settings.saturation);
                let light = settings.shape.light(
                    (settings.seed, index),
                    position,
                    color,
                    (settings.intensity, radius),
                );
                match spot_direction(settings.seed, index, settings.spots.fraction) {
                    Some(direction) => Light::spot(
                        position,
                        radius,
                        color,
                        settings.intensity,
                        direction,
                        settings.spots.cone,
                    ),
                    None => light,
                }
            })
            .collect();
        Ok(Self { lights })
    }

    /// Adds lights after the generated ones (a scene's own lights: the animation moves
    /// only the first [`LightSettings::count`], so these stay where the scene put them).
    pub fn extend(&mut self, lights: impl IntoIterator<Item = Light>) {
        self.lights.extend(lights);
    }

    /// How many lights are spots.
    pub fn spot_count(&self) -> usize {
        self.lights.iter().filter(|l| l.is_spot()).count()
    }

    /// Checks lights given through the API (see [`validate_lights`]).
    pub fn validate(&self) -> Result<(), LightError> {
        validate_lights(&self.lights, 0)
    }

    pub fn len(&self) -> usize {
        self.lights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }
}

/// Checks lights an engine gives (a whole array, or a range of one starting at index
/// `first`): every field finite, the radius (the range a light reaches) positive, colour
/// and intensity not negative, a known kind, a spot's direction a unit vector and its cone
/// in range, an area light's shape not degenerate. The error names the light by its index
/// in the whole array (`first` plus its place in `lights`) and the field.
pub fn validate_lights(lights: &[Light], first: usize) -> Result<(), LightError> {
    for (offset, light) in lights.iter().enumerate() {
        let index = first + offset;
        all_finite(
            index,
            &[
                ("position", &light.position),
                ("radius", std::slice::from_ref(&light.radius)),
                ("color", &light.color),
                ("intensity", std::slice::from_ref(&light.intensity)),
            ],
        )?;
        if light.radius <= 0.0 {
            return Err(LightError::OutOfRange {
                index,
                field: "radius",
                value: light.radius,
                expected: "positive",
            });
        }
        if light.kind > LIGHT_TRIANGLE {
            return Err(LightError::OutOfRange {
                index,
                field: "kind",
                value: light.kind as f32,
                expected: "LIGHT_POINT (0), LIGHT_SPOT (1), LIGHT_SPHERE (2), LIGHT_RECT (3) or LIGHT_TRIANGLE (4)",
            });
        }
        if light.is_area() {
            validate_area(index, light)?;
        }
        if light.is_spot() {
            all_finite(
                index,
                &[
                    ("direction", &light.direction),
                    ("sin2_outer", std::slice::from_ref(&light.sin2_outer)),
                    ("sin2_inner", std::slice::from_ref(&light.sin2_inner)),
                ],
            )?;
            let length = Vec3::from_array(light.direction).length();
            if (length - 1.0).abs() > 1e-3 {
                return Err(LightError::OutOfRange {
                    index,
                    field: "direction length",
                    value: length,
                    expected: "1 (a unit vector)",
                });
            }
            if !(light.sin2_outer > 0.0 && light.sin2_outer <= 1.0) {
                return Err(LightError::OutOfRange {
                    index,
                    field: "sin2_outer",
                    value: light.sin2_outer,
                    expected: "in (0, 1]: an outer angle in (0, pi/2]",
                });
            }
            if !(0.0..=light.sin2_outer).contains(&light.sin2_inner) {
                return Err(LightError::OutOfRange {
                    index,
                    field: "sin2_inner",
                    value: light.sin2_inner,
                    expected: "in [0, sin2_outer]: an inner angle no wider than the outer",
                });
            }
        }
        if light.intensity < 0.0 || light.color.iter().any(|c| *c < 0.0) {
            return Err(LightError::OutOfRange {
                index,
                field: "intensity/color",
                value: light
                    .intensity
                    .min(light.color.iter().copied().fold(f32::INFINITY, f32::min)),
                expected: "non-negative",
            });
        }
    }
    Ok(())
}

impl std::fmt::Display for LightShape {
    /// `point`, `sphere:SIZE`, `rect:SIZE`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Point => write!(f, "point"),
            _ => write!(f, "{}:{}", self.name(), self.size()),
        }
    }
}

impl std::str::FromStr for LightShape {
    type Err = String;

    /// `point`, `sphere:SIZE` or `rect:SIZE` (metres), checked ([`LightShape::validate`]).
    fn from_str(text: &str) -> Result<Self, String> {
        let (name, size) = match text.split_once(':') {
            Some((name, size)) => (
                name,
                size.parse::<f32>()
                    .map_err(|e| format!("light shape '{text}': size '{size}': {e}"))?,
            ),
            None if text == "point" => (text, 0.0),
            None => return Err(format!("light shape '{text}': give its size, NAME:METRES")),
        };
        let shape = Self::new(name, size)?;
        shape.validate().map_err(|e| e.to_string())?;
        Ok(shape)
    }
}

/// An area light's shape: finite, a sphere's radius not negative, a flat light's normal
/// defined (a rectangle or triangle of no area has none) and a rectangle's edges at right
/// angles (its shading clamps to it in the edges' coordinates).
fn validate_area(index: usize, light: &Light) -> Result<(), LightError> {
    all_finite(
        index,
        &[
            ("direction (first edge)", &light.direction),
            ("second edge", &light.second_edge().to_array()),
        ],
    )?;
    let first = Vec3::from_array(light.direction);
    let second = light.second_edge();
    let out_of_range = |field, value, expected| {
        Err(LightError::OutOfRange {
            index,
            field,
            value,
            expected,
        })
    };
    match light.kind {
        LIGHT_SPHERE if light.extent < 0.0 => {
            out_of_range("sphere radius", light.extent, "not negative")
        }
        LIGHT_RECT | LIGHT_TRIANGLE if first.cross(second).length() <= 0.0 => out_of_range(
            "area",
            light.area(),
            "positive (a flat light of no area has no normal)",
        ),
        LIGHT_RECT if first.dot(second).abs() > 1e-3 * first.length() * second.length() => {
            out_of_range(
                "cosine between the rectangle's edges",
                first.normalize().dot(second.normalize()),
                "0 (edges at right angles)",
            )
        }
        _ => Ok(()),
    }
}

/// The first field of light `index` holding a NaN or infinity, as an error.
fn all_finite(index: usize, fields: &[(&'static str, &[f32])]) -> Result<(), LightError> {
    match fields
        .iter()
        .find(|(_, values)| values.iter().any(|v| !v.is_finite()))
    {
        Some((field, values)) => Err(LightError::NonFinite {
            index,
            field,
            value: format!("{values:?}"),
        }),
        None => Ok(()),
    }
}

/// Whether generated light `index` is a spot (a hash below `fraction`), and if so its
/// direction: uniform over the downward hemisphere (spots hung in a room light its floor
/// and walls; upward ones would light the sky of an open court).
pub fn spot_direction(seed: u32, index: u32, fraction: f32) -> Option<Vec3> {
    use crate::animation::{hash_unit, pcg_hash};
    let key = pcg_hash(seed ^ 0x2545f491) ^ pcg_hash(index);
    if hash_unit(key) >= fraction {
        return None;
    }
    // Uniform on the hemisphere y <= 0: -y uniform in [0, 1), azimuth uniform.
    let down = hash_unit(key ^ 0x68e31da4);
    let azimuth = hash_unit(key ^ 0xb5297a4d) * std::f32::consts::TAU;
    let across = (1.0 - down * down).max(0.0).sqrt();
    Some(Vec3::new(across * azimuth.cos(), -down, across * azimuth.sin()).normalize())
}

/// A random hue, mixed toward white by `1 - saturation` (saturation 1: the pure hue;
/// 0: white).
pub fn light_color(seed: u32, index: u32, saturation: f32) -> Vec3 {
    let hue = crate::animation::hash_unit(
        crate::animation::pcg_hash(seed ^ 0x5bd1e995) ^ crate::animation::pcg_hash(index),
    );
    let h = hue * 6.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let rgb = match h as u32 {
        0 => Vec3::new(1.0, x, 0.0),
        1 => Vec3::new(x, 1.0, 0.0),
        2 => Vec3::new(0.0, 1.0, x),
        3 => Vec3::new(0.0, x, 1.0),
        4 => Vec3::new(x, 0.0, 1.0),
        _ => Vec3::new(1.0, 0.0, x),
    };
    rgb.lerp(Vec3::ONE, 1.0 - saturation)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturation_moves_colours_between_the_pure_hue_and_white() {
        for index in 0..64 {
            let pure = light_color(7, index, 1.0);
            // A pure hue: one channel at 1, one at 0.
            assert_eq!(pure.max_element(), 1.0, "light {index}: {pure}");
            assert_eq!(pure.min_element(), 0.0, "light {index}: {pure}");
            assert_eq!(light_color(7, index, 0.0), Vec3::ONE);
            // The old pastel colours (80% toward white) are saturation 0.2, bit for bit.
            assert_eq!(
                light_color(7, index, 0.2),
                pure.lerp(Vec3::ONE, 0.8),
                "light {index}"
            );
        }
    }

    /// A sphere of no size is the point light (not infinite radiance over no area), and a
    /// generated shape's reach is its range plus its size.
    #[test]
    fn a_sphere_of_no_size_is_the_point_and_shapes_reach_past_their_size() {
        let (at, colour) = (Vec3::new(1.0, 2.0, 3.0), Vec3::ONE);
        assert_eq!(
            Light::sphere(at, 2.0, colour, 0.5, 0.0),
            Light::point(at, 2.0, colour, 0.5)
        );
        let light = LightShape::Rect(0.4).light((1, 7), at, colour, (0.5, 2.0));
        assert!((light.radius - (2.0 + 0.2 * std::f32::consts::SQRT_2)).abs() < 1e-6);
        let sphere = LightShape::Sphere(0.4).light((1, 7), at, colour, (0.5, 2.0));
        assert_eq!(sphere.radius, 2.2);
    }

    #[test]
    fn saturation_outside_zero_to_one_is_refused() {
        for saturation in [-0.1, 1.5, f32::NAN] {
            let settings = LightSettings {
                count: 4,
                seed: 1,
                intensity: 0.2,
                radius: RadiusMode::Fixed(1.0),
                saturation,
                animation: AnimationParams::in_box(SPONZA_LIGHT_BOX),
                spots: SpotSettings::default(),
                shape: LightShape::Point,
            };
            let error = LightSet::generate(&settings).expect_err("refused");
            assert!(error.to_string().contains("saturation"), "{error}");
        }
    }
}
