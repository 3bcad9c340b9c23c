//! Deterministic procedural scenes: `cornell` (a small closed room for fast GPU tests),
//! `wall` (a floor and a wall, for shadow rays from rebuilt positions) and
//! `pillars` (a floor with a grid of pillars and spheres whose triangle count is set by
//! parameters, so benchmarks can grow geometry as well as lights).

use glam::{Mat4, Quat, Vec2, Vec3};

mod glass;

pub use glass::{
    GLASS_PANES, SPONZA_BANNERS, SPONZA_EMBERS, glass_room, sponza_embers, sponza_glass,
};

use crate::model::{
    AlphaMode, ColorSpace, Instance, Material, Mesh, Scene, SceneLight, Shading, SpotCone, Texture,
    bounds_of,
};

fn flat_material(name: &str, rgb: Vec3, specular: f32, shininess: f32) -> Material {
    Material {
        name: name.into(),
        base_color_factor: rgb.extend(1.0),
        specular_color: Vec3::splat(specular),
        shininess,
        roughness_factor: Material::roughness_from_shininess(shininess),
        ..Material::default()
    }
}

/// Builds meshes vertex by vertex; every face gets its own vertices (flat normals).
struct MeshBuilder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<u32>,
}

impl MeshBuilder {
    fn new() -> Self {
        Self {
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            indices: Vec::new(),
        }
    }

    /// A quad subdivided into `cells` x `cells`, spanned from `origin` by `u` and `v`,
    /// facing `u x v`.
    fn grid_quad(&mut self, origin: Vec3, u: Vec3, v: Vec3, cells: u32) {
        let normal = u.cross(v).normalize();
        let base = self.positions.len() as u32;
        for j in 0..=cells {
            for i in 0..=cells {
                let (s, t) = (i as f32 / cells as f32, j as f32 / cells as f32);
                self.positions.push(origin + u * s + v * t);
                self.normals.push(normal);
                self.uvs.push(Vec2::new(s, 1.0 - t));
            }
        }
        let row = cells + 1;
        for j in 0..cells {
            for i in 0..cells {
                let a = base + j * row + i;
                let (b, c, d) = (a + 1, a + row + 1, a + row);
                self.indices.extend_from_slice(&[a, b, c, a, c, d]);
            }
        }
    }

    /// An axis-aligned box with outward faces.
    fn cuboid(&mut self, min: Vec3, max: Vec3) {
        let s = max - min;
        let (x, y, z) = (Vec3::X * s.x, Vec3::Y * s.y, Vec3::Z * s.z);
        self.grid_quad(min, z, y, 1); // -X
        self.grid_quad(min + x, y, z, 1); // +X
        self.grid_quad(min, x, z, 1); // -Y
        self.grid_quad(min + y, z, x, 1); // +Y
        self.grid_quad(min, y, x, 1); // -Z
        self.grid_quad(min + z, x, y, 1); // +Z
    }

    /// An open cylinder along +Y from y = 0 to `height`, `segments` around, `rings` high.
    fn cylinder(&mut self, radius: f32, height: f32, segments: u32, rings: u32) {
        let base = self.positions.len() as u32;
        for ring in 0..=rings {
            let y = height * ring as f32 / rings as f32;
            for segment in 0..=segments {
                let angle = std::f32::consts::TAU * segment as f32 / segments as f32;
                let normal = Vec3::new(angle.cos(), 0.0, angle.sin());
                self.positions.push(normal * radius + Vec3::Y * y);
                self.normals.push(normal);
                self.uvs.push(Vec2::new(
                    segment as f32 / segments as f32,
                    1.0 - ring as f32 / rings as f32,
                ));
            }
        }
        self.ring_indices(base, segments, rings);
    }

    /// A UV sphere centred on the origin; rings go from the bottom pole up, like the
    /// cylinder's, so both share `ring_indices`.
    fn sphere(&mut self, radius: f32, segments: u32, rings: u32) {
        let base = self.positions.len() as u32;
        for ring in 0..=rings {
            let polar = std::f32::consts::PI * (1.0 - ring as f32 / rings as f32);
            for segment in 0..=segments {
                let azimuth = std::f32::consts::TAU * segment as f32 / segments as f32;
                let normal = Vec3::new(
                    polar.sin() * azimuth.cos(),
                    polar.cos(),
                    polar.sin() * azimuth.sin(),
                );
                self.positions.push(normal * radius);
                self.normals.push(normal);
                self.uvs.push(Vec2::new(
                    segment as f32 / segments as f32,
                    1.0 - ring as f32 / rings as f32,
                ));
            }
        }
        self.ring_indices(base, segments, rings);
    }

    /// Triangles between consecutive rings of `segments + 1` vertices, facing outward for
    /// the winding used by `cylinder` and `sphere`.
    fn ring_indices(&mut self, base: u32, segments: u32, rings: u32) {
        let row = segments + 1;
        for ring in 0..rings {
            for segment in 0..segments {
                let a = base + ring * row + segment;
                let (b, c, d) = (a + 1, a + row + 1, a + row);
                self.indices.extend_from_slice(&[a, d, c, a, c, b]);
            }
        }
    }

    fn build(self, name: &str, material: usize) -> Mesh {
        Mesh {
            name: name.into(),
            bounds: bounds_of(&self.positions),
            positions: self.positions,
            normals: self.normals,
            uvs: self.uvs,
            tangents: None,
            indices: self.indices,
            material,
        }
    }
}

/// A checkerboard texture of `cells` x `cells` squares, `size` texels square.
fn checker_texture(size: u32, cells: u32, light: [u8; 3], dark: [u8; 3]) -> Texture {
    let mut rgba8 = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let cell = (x * cells / size + y * cells / size) % 2;
            let rgb = if cell == 0 { light } else { dark };
            rgba8.extend_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        }
    }
    Texture {
        source: "procedural checker".into(),
        width: size,
        height: size,
        color_space: ColorSpace::Srgb,
        rgba8,
    }
}

/// A grille: opaque bars with fully transparent holes, for the alpha-mask path.
fn grille_texture(size: u32, bars: u32) -> Texture {
    let mut rgba8 = Vec::with_capacity((size * size * 4) as usize);
    let period = size / bars;
    for y in 0..size {
        for x in 0..size {
            let bar = x % period < period / 3 || y % period < period / 3;
            rgba8.extend_from_slice(&[200, 170, 60, if bar { 255 } else { 0 }]);
        }
    }
    Texture {
        source: "procedural grille".into(),
        width: size,
        height: size,
        color_space: ColorSpace::Srgb,
        rgba8,
    }
}

/// Interior bounds of the cornell room.
pub const CORNELL_ROOM_MIN: Vec3 = Vec3::new(-2.0, 0.0, -2.0);
pub const CORNELL_ROOM_MAX: Vec3 = Vec3::new(2.0, 3.0, 2.0);

/// A closed room (4 x 3 x 4 m, walls facing inward) with a red and a green wall, a
/// checker-textured floor, two blocks, a sphere and an alpha-masked grille: about 600
/// triangles using textures and alpha masking, so fast GPU tests cover those paths.
pub fn cornell() -> Scene {
    let mut scene = Scene {
        name: "cornell".into(),
        // Materials written as Blinn-Phong (their roughness is mapped from it).
        shading: Shading::BlinnPhong,
        ..Scene::default()
    };
    scene
        .textures
        .push(checker_texture(64, 8, [230, 230, 230], [90, 90, 90]));
    scene.textures.push(grille_texture(64, 4));
    scene.materials = vec![
        flat_material("white", Vec3::splat(0.75), 0.0, 1.0),
        flat_material("red", Vec3::new(0.65, 0.06, 0.05), 0.0, 1.0),
        flat_material("green", Vec3::new(0.12, 0.45, 0.09), 0.0, 1.0),
        Material {
            base_color_texture: Some(0),
            ..flat_material("checker floor", Vec3::ONE, 0.04, 16.0)
        },
        flat_material("glossy block", Vec3::new(0.2, 0.3, 0.7), 0.5, 64.0),
        Material {
            base_color_texture: Some(1),
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            double_sided: true,
            ..flat_material("grille", Vec3::ONE, 0.0, 1.0)
        },
    ];
    let (min, max) = (CORNELL_ROOM_MIN, CORNELL_ROOM_MAX);
    let size = max - min;
    let (x, y, z) = (Vec3::X * size.x, Vec3::Y * size.y, Vec3::Z * size.z);
    let cells = 4;
    let mut walls = MeshBuilder::new();
    walls.grid_quad(min + y, x, z, cells); // ceiling, facing -Y
    walls.grid_quad(min + z, y, x, cells); // front wall (+Z side), facing -Z
    walls.grid_quad(min, x, y, cells); // back wall, facing +Z
    let mut left = MeshBuilder::new();
    left.grid_quad(min, y, z, cells); // -X wall, facing +X
    let mut right = MeshBuilder::new();
    right.grid_quad(min + x, z, y, cells); // +X wall, facing -X
    let mut floor = MeshBuilder::new();
    floor.grid_quad(min, z, x, cells); // facing +Y
    let mut blocks = MeshBuilder::new();
    blocks.cuboid(Vec3::new(-1.2, 0.0, -1.0), Vec3::new(-0.2, 1.8, 0.0));
    blocks.cuboid(Vec3::new(0.4, 0.0, 0.2), Vec3::new(1.3, 0.9, 1.1));
    let mut sphere = MeshBuilder::new();
    sphere.sphere(0.4, 16, 8);
    let mut grille = MeshBuilder::new();
    grille.grid_quad(Vec3::new(-0.8, 0.2, 1.2), Vec3::X * 1.6, Vec3::Y * 1.2, 1);

    for (mesh, name, material, transform) in [
        (walls, "walls", 0, Mat4::IDENTITY),
        (left, "red wall", 1, Mat4::IDENTITY),
        (right, "green wall", 2, Mat4::IDENTITY),
        (floor, "floor", 3, Mat4::IDENTITY),
        (blocks, "blocks", 0, Mat4::IDENTITY),
        (
            sphere,
            "sphere",
            4,
            Mat4::from_translation(Vec3::new(0.85, 1.3, 0.65)),
        ),
        (grille, "grille", 5, Mat4::IDENTITY),
    ] {
        scene.meshes.push(mesh.build(name, material));
        scene.instances.push(Instance {
            mesh: scene.meshes.len() - 1,
            transform,
        });
    }
    scene
}

/// The roughness of each column of [`material_spheres`], left to right.
pub const SPHERE_ROUGHNESS: [f32; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];
/// The spheres' radius (m) and the distance between their centres.
pub const SPHERE_RADIUS: f32 = 0.4;
pub const SPHERE_SPACING: f32 = 1.0;

/// The centre of the sphere in `row` (0: dielectrics, 1: metals) and `column` of
/// [`material_spheres`].
pub fn sphere_centre(row: usize, column: usize) -> Vec3 {
    Vec3::new(
        (column as f32 - 2.0) * SPHERE_SPACING,
        0.6 + row as f32 * SPHERE_SPACING,
        0.0,
    )
}

/// glTF's metallic-roughness in a grid (after the Khronos MetalRoughSpheres, as
/// `assets/spheres/spheres.gltf` is exported): a row of black dielectrics (F0 0.04, no
/// diffuse: only their highlights show) under a row of gold metals, roughness 0 to 1 from
/// left to right ([`SPHERE_ROUGHNESS`]), on a grey floor, lit by one point light in front.
pub fn material_spheres() -> Scene {
    let mut scene = Scene {
        name: "spheres".into(),
        ..Scene::default()
    };
    let sphere_material = |name: String, base: Vec3, metallic: f32, roughness: f32| Material {
        name,
        base_color_factor: base.extend(1.0),
        metallic_factor: metallic,
        roughness_factor: roughness,
        ..Material::default()
    };
    const GOLD: Vec3 = Vec3::new(1.0, 0.78, 0.34);
    for (row, (kind, base, metallic)) in [("dielectric", Vec3::ZERO, 0.0), ("metal", GOLD, 1.0)]
        .into_iter()
        .enumerate()
    {
        for (column, roughness) in SPHERE_ROUGHNESS.into_iter().enumerate() {
            let material = scene.materials.len();
            scene.materials.push(sphere_material(
                format!("{kind} roughness {roughness}"),
                base,
                metallic,
                roughness,
            ));
            let mut sphere = MeshBuilder::new();
            sphere.sphere(SPHERE_RADIUS, 48, 24);
            scene
                .meshes
                .push(sphere.build(&format!("{kind} sphere {column}"), material));
            scene.instances.push(Instance {
                mesh: scene.meshes.len() - 1,
                transform: Mat4::from_translation(sphere_centre(row, column)),
            });
        }
    }
    scene.materials.push(Material {
        name: "floor".into(),
        base_color_factor: Vec3::splat(0.5).extend(1.0),
        ..Material::default()
    });
    let mut floor = MeshBuilder::new();
    floor.grid_quad(Vec3::new(-4.0, 0.0, -3.0), Vec3::Z * 6.0, Vec3::X * 8.0, 1);
    scene
        .meshes
        .push(floor.build("floor", scene.materials.len() - 1));
    scene.instances.push(Instance {
        mesh: scene.meshes.len() - 1,
        transform: Mat4::IDENTITY,
    });
    scene.lights = vec![SceneLight {
        name: "front lamp".into(),
        position: Vec3::new(-1.0, 2.5, 3.0),
        direction: Vec3::NEG_Z,
        cone: None,
        color: Vec3::ONE,
        intensity: 40.0,
        range: None,
    }];
    scene
}

/// A white 10 x 10 m floor (two triangles) with a wall across its middle (0.2 m thick,
/// 3 m high, along z at x = 0) and one point light at (-2, 1, 0): the frame of issue 46,
/// where a shadow ray that starts below the floor (a position rebuilt from depth a few
/// ulps too deep) turns the lit side black. Seen from 8 m above (`--camera
/// 0,8,0,0,-90,60`), the lit side is bright, the far side black.
pub fn shadow_wall() -> Scene {
    let mut scene = Scene {
        name: "wall".into(),
        // Materials written as Blinn-Phong (their roughness is mapped from it).
        shading: Shading::BlinnPhong,
        ..Scene::default()
    };
    scene.materials = vec![flat_material("white", Vec3::ONE, 0.0, 1.0)];
    let mut geometry = MeshBuilder::new();
    geometry.grid_quad(
        Vec3::new(-5.0, 0.0, -5.0),
        Vec3::Z * 10.0,
        Vec3::X * 10.0,
        1,
    );
    geometry.cuboid(Vec3::new(-0.1, 0.0, -5.0), Vec3::new(0.1, 3.0, 5.0));
    scene.meshes.push(geometry.build("floor and wall", 0));
    scene.instances.push(Instance {
        mesh: 0,
        transform: Mat4::IDENTITY,
    });
    scene.lights = vec![SceneLight {
        name: "lamp".into(),
        position: Vec3::new(-2.0, 1.0, 0.0),
        direction: Vec3::NEG_Z,
        cone: None,
        color: Vec3::ONE,
        intensity: 4.0,
        range: Some(8.0),
    }];
    scene
}

/// The radiance of [`panel_room`]'s panels: glTF's unit emissive factor times
/// `KHR_materials_emissive_strength` 40.
pub const PANEL_RADIANCE: f32 = 40.0;

/// A room lit only by its emissive surfaces (`assets/panel/panel.gltf`): a white floor 8 m
/// square, a low wall (3 m long, 1 m high) across it, a ceiling panel 1 m x 0.5 m at 2 m
/// facing down over the wall's west side, and a second panel at 1.5 m on the east side
/// facing up, which lights nothing below it. No point lights: without emissive surfaces
/// as lights the floor is black.
pub fn panel_room() -> Scene {
    let mut scene = Scene {
        name: "panel".into(),
        ..Scene::default()
    };
    let white = Material {
        roughness_factor: 0.8,
        ..flat_material("white", Vec3::splat(0.8), 0.0, 1.0)
    };
    let panel = Material {
        emissive_factor: Vec3::splat(PANEL_RADIANCE),
        ..flat_material("panel", Vec3::ZERO, 0.0, 1.0)
    };
    scene.materials = vec![white, panel];
    let mut room = MeshBuilder::new();
    room.grid_quad(Vec3::new(-4.0, 0.0, -4.0), Vec3::Z * 8.0, Vec3::X * 8.0, 1);
    room.cuboid(Vec3::new(-0.05, 0.0, -1.5), Vec3::new(0.05, 1.0, 1.5));
    scene.meshes.push(room.build("floor and wall", 0));
    let mut panels = MeshBuilder::new();
    // Facing down (X x Z = -Y), west of the wall.
    panels.grid_quad(Vec3::new(-1.5, 2.0, -0.25), Vec3::X, Vec3::Z * 0.5, 1);
    // Facing up (Z x X = +Y), east of it.
    panels.grid_quad(Vec3::new(1.5, 1.5, -0.25), Vec3::Z * 0.5, Vec3::X, 1);
    scene.meshes.push(panels.build("panels", 1));
    for mesh in 0..2 {
        scene.instances.push(Instance {
            mesh,
            transform: Mat4::IDENTITY,
        });
    }
    scene
}

/// The cornell room lit by its own lights (glTF `KHR_lights_punctual` once exported, as
/// `assets/lamps/lamps.gltf` is): a warm point light under the ceiling with a 5 m range,
/// an unbounded cool point light, and three spots: a narrow one on the sphere, a wide one
/// with a soft edge on the red wall, and a hard-edged one on the floor through the
/// grille. Intensities in candela.
pub fn lamp_room() -> Scene {
    let mut scene = cornell();
    scene.name = "lamps".into();
    let spot =
        |name: &str, position: Vec3, target: Vec3, inner_deg: f32, outer_deg: f32| SceneLight {
            name: name.into(),
            position,
            direction: (target - position).normalize(),
            cone: Some(SpotCone {
                inner: inner_deg.to_radians(),
                outer: outer_deg.to_radians(),
            }),
            color: Vec3::ONE,
            intensity: 0.0,
            range: Some(8.0),
        };
    scene.lights = vec![
        SceneLight {
            name: "ceiling lamp".into(),
            position: Vec3::new(0.0, 2.7, 0.0),
            direction: Vec3::NEG_Z,
            cone: None,
            color: Vec3::new(1.0, 0.85, 0.6),
            intensity: 1.5,
            range: Some(5.0),
        },
        SceneLight {
            name: "unbounded blue lamp".into(),
            position: Vec3::new(1.6, 2.2, -1.6),
            direction: Vec3::NEG_Z,
            cone: None,
            color: Vec3::new(0.5, 0.7, 1.0),
            intensity: 0.6,
            range: None,
        },
        SceneLight {
            intensity: 6.0,
            color: Vec3::new(1.0, 0.95, 0.8),
            ..spot(
                "sphere spot",
                Vec3::new(-1.2, 2.8, 1.6),
                Vec3::new(0.85, 1.3, 0.65),
                6.0,
                9.0,
            )
        },
        SceneLight {
            intensity: 4.0,
            color: Vec3::new(0.9, 0.9, 1.0),
            ..spot(
                "wall spot",
                Vec3::new(1.5, 2.5, 1.5),
                Vec3::new(-2.0, 1.2, -0.6),
                10.0,
                30.0,
            )
        },
        SceneLight {
            intensity: 5.0,
            color: Vec3::new(1.0, 0.6, 0.3),
            ..spot(
                "grille spot",
                Vec3::new(0.0, 2.9, 1.9),
                Vec3::new(0.0, 0.0, 0.6),
                20.0,
                20.0,
            )
        },
    ];
    scene
}

/// Parameters of the scalable `pillars` scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PillarsParams {
    /// Pillars per side: `grid * grid` pillars, each with a sphere on top.
    pub grid: u32,
    /// Tessellation: segments around each pillar and sphere (rings scale with it).
    pub segments: u32,
}

impl Default for PillarsParams {
    fn default() -> Self {
        Self {
            grid: 8,
            segments: 24,
        }
    }
}

impl PillarsParams {
    /// Triangles the scene will have (floor included).
    pub fn triangle_count(&self) -> usize {
        let s = self.segments as usize;
        let per_pillar = 2 * s * s.div_ceil(2) + 2 * s * s.div_ceil(2);
        2 * 16 * 16 + (self.grid as usize).pow(2) * per_pillar
    }

    /// The smallest tessellation giving at least `triangles` with this grid (capped at
    /// 1024 segments).
    pub fn with_triangles(grid: u32, triangles: usize) -> Self {
        let mut params = Self { grid, segments: 3 };
        while params.triangle_count() < triangles && params.segments < 1024 {
            params.segments += 1;
        }
        params
    }
}

/// Spacing between pillars, in metres.
const PILLAR_SPACING: f32 = 3.0;

/// A floor with `grid` x `grid` pillars (4 m tall cylinders) topped with spheres. Pillars
/// and spheres are instances of two meshes, so memory stays small while the drawn triangle
/// count ([`PillarsParams::triangle_count`]) grows from thousands to millions.
pub fn pillars(params: PillarsParams) -> Scene {
    let grid = params.grid.max(1);
    let segments = params.segments.max(3);
    let rings = segments.div_ceil(2);
    let extent = grid as f32 * PILLAR_SPACING;
    let mut scene = Scene {
        name: format!("pillars-{grid}x{grid}-s{segments}"),
        // Materials written as Blinn-Phong (their roughness is mapped from it).
        shading: Shading::BlinnPhong,
        ..Scene::default()
    };
    scene
        .textures
        .push(checker_texture(128, 16, [200, 200, 190], [120, 120, 110]));
    scene.materials = vec![
        Material {
            base_color_texture: Some(0),
            ..flat_material("floor", Vec3::ONE, 0.04, 32.0)
        },
        flat_material("pillar", Vec3::new(0.8, 0.75, 0.7), 0.04, 8.0),
        flat_material("sphere", Vec3::new(0.7, 0.2, 0.2), 0.5, 64.0),
    ];
    let mut floor = MeshBuilder::new();
    let corner = Vec3::new(-extent / 2.0, 0.0, -extent / 2.0);
    floor.grid_quad(corner, Vec3::Z * extent, Vec3::X * extent, 16);
    let mut pillar = MeshBuilder::new();
    pillar.cylinder(0.3, 4.0, segments, rings);
    let mut sphere = MeshBuilder::new();
    sphere.sphere(0.6, segments, rings);
    scene.meshes = vec![
        floor.build("floor", 0),
        pillar.build("pillar", 1),
        sphere.build("sphere", 2),
    ];
    scene.instances.push(Instance {
        mesh: 0,
        transform: Mat4::IDENTITY,
    });
    for j in 0..grid {
        for i in 0..grid {
            let position = corner + Vec3::new(i as f32 + 0.5, 0.0, j as f32 + 0.5) * PILLAR_SPACING;
            let spin = Quat::from_rotation_y(0.37 * (i * grid + j) as f32);
            scene.instances.push(Instance {
                mesh: 1,
                transform: Mat4::from_rotation_translation(spin, position),
            });
            scene.instances.push(Instance {
                mesh: 2,
                transform: Mat4::from_translation(position + Vec3::Y * 4.6),
            });
        }
    }
    scene
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cornell_is_small_closed_and_uses_textures_and_masks() {
        let scene = cornell();
        let triangles = scene.triangle_count();
        assert!((200..=1000).contains(&triangles), "{triangles} triangles");
        let bounds = scene.bounds();
        assert_eq!(bounds.min, CORNELL_ROOM_MIN);
        assert_eq!(bounds.max, CORNELL_ROOM_MAX);
        let features = scene.features();
        assert!(features.base_color_textures && features.alpha_mask && !features.normal_maps);
    }

    #[test]
    fn cornell_walls_face_inward() {
        let scene = cornell();
        let center = (CORNELL_ROOM_MIN + CORNELL_ROOM_MAX) / 2.0;
        for mesh in &scene.meshes[..4] {
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                assert!(
                    n.dot(center - *p) > 0.0,
                    "{}: normal {n} at {p} faces out",
                    mesh.name
                );
            }
        }
    }

    #[test]
    fn winding_matches_normals() {
        // Counter-clockwise triangles (seen from the front) must agree with the normals.
        for scene in [
            cornell(),
            pillars(PillarsParams {
                grid: 2,
                segments: 8,
            }),
        ] {
            for mesh in &scene.meshes {
                for t in mesh.indices.chunks_exact(3) {
                    let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
                    let face = (b - a).cross(c - a);
                    if face.length() < 1e-6 {
                        continue; // sphere poles
                    }
                    let n = mesh.normals[t[0] as usize]
                        + mesh.normals[t[1] as usize]
                        + mesh.normals[t[2] as usize];
                    assert!(
                        face.dot(n) > 0.0,
                        "{} in {}: winding disagrees with normals",
                        mesh.name,
                        scene.name
                    );
                }
            }
        }
    }

    #[test]
    fn pillars_scale_with_parameters_and_are_deterministic() {
        let small = PillarsParams {
            grid: 2,
            segments: 8,
        };
        assert_eq!(pillars(small).triangle_count(), small.triangle_count());
        let big = PillarsParams::with_triangles(16, 2_000_000);
        assert!(big.triangle_count() >= 2_000_000);
        assert_eq!(pillars(big).triangle_count(), big.triangle_count());
        assert_eq!(pillars(small), pillars(small));
    }
}
