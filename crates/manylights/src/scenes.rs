//! Named scenes (`sponza`, `cornell`, `pillars`) or a file, each with its light box and
//! camera presets.

use std::path::{Path, PathBuf};

use glam::Vec3;
use manylights_lights::{Light, RadiusMode, SPONZA_LIGHT_BOX, interior_box};
use manylights_scene::{Aabb, Scene, SceneError, procedural};

use crate::camera::Camera;

/// Where the project's assets are: `MANYLIGHTS_ASSETS` if set, else `assets/` of this
/// source tree. (The browser build has no disk: it fetches [`LoadedScene::asset_files`]
/// from the page's own `assets/` folder.)
pub fn assets_dir() -> PathBuf {
    std::env::var_os("MANYLIGHTS_ASSETS")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets"))
}

/// A scene ready for the renderer: geometry, the box its lights live in, camera presets.
#[derive(Debug, Clone)]
pub struct LoadedScene {
    pub name: String,
    pub scene: Scene,
    pub light_box: Aabb,
    /// Named cameras; the first is the default.
    pub presets: Vec<(String, Camera)>,
}

impl LoadedScene {
    /// `sponza`, `sponza-glass` (Sponza with tinted glass banners across the atrium and
    /// glowing embers, `assets/sponza-glass/sponza-glass.gltf`), `sponza-embers` (Sponza lit
    /// by 5,000 glowing quads, `assets/sponza-embers/sponza-embers.gltf`), `cornell`, `lamps` (the
    /// cornell room lit by its own point and spot lights, `assets/lamps/lamps.gltf`),
    /// `spheres` (dielectric and metal spheres from smooth to rough,
    /// `assets/spheres/spheres.gltf`), `glass` (blended panes and sparks,
    /// `assets/glass/glass.gltf`), `wall` (a floor, a wall and one light), `pillars` (or
    /// `pillars:GRIDxSEGMENTS`), or a path to a `.gltf`/`.glb`/`.obj` file.
    pub fn load(spec: &str) -> Result<Self, SceneError> {
        if let Some(procedural) = Self::procedural(spec) {
            return procedural;
        }
        let scene = match Self::asset_files(spec) {
            [] => manylights_scene::load(PathBuf::from(spec))?,
            [first, rest @ ..] => {
                let mut scene = manylights_scene::load(assets_dir().join(first))?;
                for file in rest {
                    scene.append(manylights_scene::load(assets_dir().join(file))?);
                }
                scene
            }
        };
        Ok(Self::from_scene(spec, scene))
    }

    /// The files a named scene is read from, relative to the assets folder, laid into one
    /// world in order (`sponza-glass`: Sponza, then its blended overlay); none for a
    /// procedural scene or a path. The browser build fetches them.
    pub fn asset_files(name: &str) -> &'static [&'static str] {
        match name {
            "sponza" => &["sponza/sponza.gltf"],
            "sponza-glass" => &["sponza/sponza.gltf", "sponza-glass/sponza-glass.gltf"],
            "lamps" => &["lamps/lamps.gltf"],
            "spheres" => &["spheres/spheres.gltf"],
            "glass" => &["glass/glass.gltf"],
            "panel" => &["panel/panel.gltf"],
            "sponza-embers" => &["sponza/sponza.gltf", "sponza-embers/sponza-embers.gltf"],
            _ => &[],
        }
    }

    /// A scene read from a file, with what its name gives: the light box and cameras of
    /// `sponza` and `lamps`; for any other file, a box inside its bounds and a camera that
    /// frames it.
    pub fn from_scene(name: &str, scene: Scene) -> Self {
        match name {
            "sponza" | "sponza-glass" | "sponza-embers" => Self {
                name: name.into(),
                scene,
                light_box: SPONZA_LIGHT_BOX,
                presets: sponza_presets(),
            },
            "lamps" => {
                // From the corner above the grille: the spots' pools on the floor, the red
                // wall and the sphere in view.
                let overview = Camera {
                    position: Vec3::new(1.7, 2.6, 1.9),
                    yaw: 37f32.to_radians(),
                    pitch: (-27f32).to_radians(),
                    fov_y: 75f32.to_radians(),
                    ..Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, 75.0, 0.05, 20.0)
                };
                Self {
                    name: "lamps".into(),
                    light_box: interior_box(&scene.bounds()),
                    presets: vec![("overview".into(), overview)],
                    scene,
                }
            }
            "glass" => {
                // From the front, a little above: the panes overlap, the sparks between them.
                let front = Camera::look_at(
                    Vec3::new(0.6, 1.6, 4.2),
                    Vec3::new(0.0, 1.0, -1.0),
                    60.0,
                    0.05,
                    30.0,
                );
                Self {
                    name: "glass".into(),
                    light_box: interior_box(&scene.bounds()),
                    presets: vec![("front".into(), front)],
                    scene,
                }
            }
            "spheres" => {
                // Straight at the grid from in front, the light over the left shoulder.
                let front = Camera::look_at(
                    Vec3::new(0.0, 1.1, 4.6),
                    Vec3::new(0.0, 1.1, 0.0),
                    50.0,
                    0.05,
                    30.0,
                );
                Self {
                    name: "spheres".into(),
                    light_box: interior_box(&scene.bounds()),
                    presets: vec![("front".into(), front)],
                    scene,
                }
            }
            _ => {
                let bounds = scene.bounds();
                Self {
                    name: scene.name.clone(),
                    light_box: if bounds.is_empty() {
                        Aabb::new(Vec3::ZERO, Vec3::ONE)
                    } else {
                        interior_box(&bounds)
                    },
                    presets: vec![("fit".into(), Camera::fit(&bounds))],
                    scene,
                }
            }
        }
    }

    /// The scenes built in code (`cornell`, `wall`, `pillars[:GRIDxSEGMENTS]`), or `None`
    /// when `spec` names none of them.
    pub fn procedural(spec: &str) -> Option<Result<Self, SceneError>> {
        if spec == "cornell" {
            let scene = procedural::cornell();
            return Some(Ok(Self {
                name: "cornell".into(),
                light_box: interior_box(&scene.bounds()),
                presets: vec![(
                    "default".into(),
                    Camera::look_at(
                        Vec3::new(0.0, 1.5, 1.9),
                        Vec3::new(0.0, 1.2, -2.0),
                        60.0,
                        0.05,
                        20.0,
                    ),
                )],
                scene,
            }));
        }
        if spec == "wall" {
            let scene = procedural::shadow_wall();
            // 8 m above the wall, looking straight down; near and far as `Camera::fit`
            // would give the scene read from a file.
            let above = Camera {
                position: Vec3::new(0.0, 8.0, 0.0),
                yaw: 0.0,
                pitch: -std::f32::consts::FRAC_PI_2,
                ..Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, 60.0, 0.07, 72.0)
            };
            return Some(Ok(Self {
                name: "wall".into(),
                light_box: interior_box(&scene.bounds()),
                presets: vec![("above".into(), above)],
                scene,
            }));
        }
        if spec != "pillars" && !spec.starts_with("pillars:") {
            return None;
        }
        let Some(params) = parse_pillars(spec) else {
            return Some(Err(SceneError::UnsupportedFormat {
                file: PathBuf::from(spec),
            }));
        };
        let scene = procedural::pillars(params);
        let bounds = scene.bounds();
        let extent = bounds.size().x;
        Some(Ok(Self {
            name: scene.name.clone(),
            light_box: Aabb::new(
                bounds.min + Vec3::new(0.0, 0.2, 0.0),
                Vec3::new(bounds.max.x, 6.0, bounds.max.z),
            ),
            presets: vec![(
                "overview".into(),
                Camera::look_at(
                    Vec3::new(-0.55 * extent, 8.0, -0.55 * extent),
                    Vec3::new(0.0, 1.0, 0.0),
                    60.0,
                    0.1,
                    4.0 * extent,
                ),
            )],
            scene,
        }))
    }

    /// The preset called `name`.
    pub fn preset(&self, name: &str) -> Option<Camera> {
        self.presets
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, c)| *c)
    }

    /// A camera from a preset name (e.g. `reference`), `x,y,z,yaw,pitch[,fov[,roll]]`
    /// (metres and degrees; the rest as the scene's default camera) or `drawn:SEED:INDEX`
    /// (a camera drawn at random inside the scene: [`crate::drawn_cameras`]).
    pub fn camera(&self, text: &str) -> Result<Camera, String> {
        if let Some(camera) = self.preset(text) {
            return Ok(camera);
        }
        if let Some(drawn) = crate::drawn_cameras::parse_drawn_camera(text) {
            let (seed, index) = drawn?;
            let bvh = manylights_visibility::SceneBvh::build(&self.scene)
                .map_err(|error| format!("camera '{text}': {error}"))?;
            return crate::drawn_cameras::drawn_camera(self, &bvh, seed, index);
        }
        let numbers: Result<Vec<f32>, _> =
            text.split(',').map(|v| v.trim().parse::<f32>()).collect();
        match numbers {
            Ok(v) if (5..=7).contains(&v.len()) => {
                let mut camera = self.default_camera();
                camera.position = glam::Vec3::new(v[0], v[1], v[2]);
                camera.yaw = v[3].to_radians();
                camera.pitch = v[4]
                    .to_radians()
                    .clamp(-std::f32::consts::FRAC_PI_2, std::f32::consts::FRAC_PI_2);
                if let Some(fov) = v.get(5) {
                    camera.fov_y = fov.to_radians();
                }
                camera.roll = v.get(6).map_or(0.0, |roll| roll.to_radians());
                Ok(camera)
            }
            _ => {
                let names: Vec<&str> = self.presets.iter().map(|(n, _)| n.as_str()).collect();
                Err(format!(
                    "unknown camera '{text}': use a preset of {} ({}), x,y,z,yaw,pitch[,fov[,roll]] or a drawn camera drawn:SEED:INDEX",
                    self.name,
                    names.join(", ")
                ))
            }
        }
    }

    pub fn default_camera(&self) -> Camera {
        self.presets[0].1
    }
}

/// The scene's own lights (glTF `KHR_lights_punctual`) as renderer lights, static. Units:
/// glTF gives point and spot intensities in candela; a manylights intensity is the
/// radiance at 1 m in the renderer's relative units, and one candela is taken as one unit
/// (images are relative: the exposure, chosen from the frame, sets the absolute scale).
/// A light with a range ends there (the windowed falloff reaches zero at it, as glTF
/// asks); one without is unbounded: its radius comes from `radius` (the luminance
/// threshold, as generated lights'), and a far field (`--far-field`) completes it beyond.
pub fn scene_lights(scene: &Scene, radius: RadiusMode) -> Vec<Light> {
    scene
        .lights
        .iter()
        .map(|light| {
            let reach = light
                .range
                .unwrap_or_else(|| radius.radius(light.intensity.max(f32::MIN_POSITIVE)));
            match light.cone {
                None => Light::point(light.position, reach, light.color, light.intensity),
                Some(cone) => Light::spot(
                    light.position,
                    reach,
                    light.color,
                    light.intensity,
                    light.direction,
                    cone,
                ),
            }
        })
        .collect()
}

/// A line saying what the scene's own lights are and how far the unbounded ones reach
/// (`None` for a scene without lights): the render output and the viewer show it.
pub fn describe_scene_lights(
    lights: &[manylights_scene::SceneLight],
    radius: RadiusMode,
    far_field: bool,
) -> Option<String> {
    if lights.is_empty() {
        return None;
    }
    let spots = lights.iter().filter(|l| l.cone.is_some()).count();
    let mut text = format!(
        "scene lights: {} ({} point, {spots} spot; candela taken as intensity units)",
        lights.len(),
        lights.len() - spots
    );
    let unbounded: Vec<&manylights_scene::SceneLight> =
        lights.iter().filter(|l| l.range.is_none()).collect();
    if !unbounded.is_empty() {
        let radii: Vec<String> = unbounded
            .iter()
            .map(|l| {
                format!(
                    "'{}' {:.2} m",
                    l.name,
                    radius.radius(l.intensity.max(f32::MIN_POSITIVE))
                )
            })
            .collect();
        let source = match radius {
            RadiusMode::LuminanceThreshold(t) => format!("the luminance threshold {t}"),
            RadiusMode::Fixed(r) => format!("the fixed radius {r} m"),
        };
        text += &format!(
            "; {} without a range: radius from {source} ({}){}",
            unbounded.len(),
            radii.join(", "),
            if far_field {
                ", the far field adds what lies beyond"
            } else {
                ", nothing beyond it (a far field, --far-field tree, adds it)"
            }
        );
    }
    Some(text)
}

/// `pillars` or `pillars:GRIDxSEGMENTS` (e.g. `pillars:32x48`).
fn parse_pillars(spec: &str) -> Option<procedural::PillarsParams> {
    match spec.strip_prefix("pillars:") {
        None => Some(procedural::PillarsParams::default()),
        Some(rest) => {
            let (grid, segments) = rest.split_once('x')?;
            Some(procedural::PillarsParams {
                grid: grid.parse().ok()?,
                segments: segments.parse().ok()?,
            })
        }
    }
}

/// Sponza's cameras. `reference` is the reference projects' view: (-7, 2, 0) looking along
/// the court's long axis, 45 degrees, near 0.1, far 1000.
fn sponza_presets() -> Vec<(String, Camera)> {
    vec![
        (
            "reference".into(),
            Camera::look_at(
                Vec3::new(-7.0, 2.0, 0.0),
                Vec3::new(10.0, 2.0, 0.0),
                45.0,
                0.1,
                1000.0,
            ),
        ),
        (
            "gallery".into(),
            Camera::look_at(
                Vec3::new(-12.0, 6.5, 4.5),
                Vec3::new(8.0, 5.0, -3.0),
                60.0,
                0.1,
                1000.0,
            ),
        ),
        (
            "floor".into(),
            Camera::look_at(
                Vec3::new(9.0, 1.0, 3.0),
                Vec3::new(-4.0, 0.0, -1.0),
                70.0,
                0.05,
                1000.0,
            ),
        ),
        // Outside the castle, above its western end: the roof and outer walls, and the lit
        // atrium seen from above through its open top (the reference projects' "outside"
        // view).
        (
            "outside".into(),
            Camera::look_at(
                Vec3::new(-8.0, 30.0, 3.0),
                Vec3::new(0.0, 0.0, 0.0),
                55.0,
                0.1,
                1000.0,
            ),
        ),
    ]
}
