//! Small scenes for the tests of this crate and of the pipelines' shadows: planes, a box,
//! a sphere and degenerate triangles, anywhere in the world.

use glam::{DVec3, Mat4, Vec2, Vec3, Vec4};
use manylights_scene::{
    AlphaMode, Instance, Material, Mesh, Scene, Texture, bounds_of, smooth_normals,
};

/// A scene of one mesh (`positions`, `indices`) with a default material, at `transform`.
pub fn mesh_scene(name: &str, positions: Vec<Vec3>, indices: Vec<u32>, transform: Mat4) -> Scene {
    let normals = smooth_normals(&positions, &indices);
    let uvs = positions.iter().map(|p| Vec2::new(p.x, p.z)).collect();
    let bounds = bounds_of(&positions);
    Scene {
        name: name.to_string(),
        meshes: vec![Mesh {
            name: name.to_string(),
            positions,
            normals,
            uvs,
            tangents: None,
            indices,
            material: 0,
            bounds,
        }],
        materials: vec![Material::default()],
        instances: vec![Instance { mesh: 0, transform }],
        ..Scene::default()
    }
}

/// A square of side `2 * half` in the y = 0 plane, facing +y, split along a diagonal.
pub fn plane(half: f32, transform: Mat4) -> Scene {
    let positions = vec![
        Vec3::new(-half, 0.0, -half),
        Vec3::new(half, 0.0, -half),
        Vec3::new(half, 0.0, half),
        Vec3::new(-half, 0.0, half),
    ];
    mesh_scene("plane", positions, vec![0, 2, 1, 0, 3, 2], transform)
}

/// A closed UV sphere of radius `radius` (`segments` around, `segments / 2` rings).
pub fn sphere(radius: f32, segments: u32, transform: Mat4) -> Scene {
    let rings = (segments / 2).max(2);
    let mut positions = Vec::new();
    for ring in 0..=rings {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..segments {
            let phi = std::f32::consts::TAU * segment as f32 / segments as f32;
            positions.push(
                radius
                    * Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.cos(),
                        theta.sin() * phi.sin(),
                    ),
            );
        }
    }
    let mut indices = Vec::new();
    for ring in 0..rings {
        for segment in 0..segments {
            let a = ring * segments + segment;
            let b = ring * segments + (segment + 1) % segments;
            let (c, d) = (a + segments, b + segments);
            indices.extend([a, b, c, b, d, c]);
        }
    }
    mesh_scene("sphere", positions, indices, transform)
}

/// A closed axis-aligned box from `min` to `max`, faces pointing out.
pub fn closed_box(min: Vec3, max: Vec3) -> Scene {
    let corner = |i: u32| {
        Vec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    let positions = (0..8).map(corner).collect();
    let indices = vec![
        0, 2, 1, 1, 2, 3, // z = min
        4, 5, 6, 5, 7, 6, // z = max
        0, 1, 4, 1, 5, 4, // y = min
        2, 6, 3, 3, 6, 7, // y = max
        0, 4, 2, 2, 4, 6, // x = min
        1, 3, 5, 3, 7, 5, // x = max
    ];
    mesh_scene("box", positions, indices, Mat4::IDENTITY)
}

/// Scenes merged into one (instances keep their transforms).
pub fn merged(scenes: impl IntoIterator<Item = Scene>) -> Scene {
    let mut out = Scene {
        name: "merged".into(),
        ..Scene::default()
    };
    for scene in scenes {
        let mesh_base = out.meshes.len();
        let material_base = out.materials.len();
        let texture_base = out.textures.len();
        out.textures.extend(scene.textures);
        out.materials
            .extend(scene.materials.into_iter().map(|mut m| {
                m.base_color_texture = m.base_color_texture.map(|t| t + texture_base);
                m
            }));
        out.meshes.extend(scene.meshes.into_iter().map(|mut m| {
            m.material += material_base;
            m
        }));
        out.instances
            .extend(scene.instances.into_iter().map(|mut i| {
                i.mesh += mesh_base;
                i
            }));
    }
    out
}

/// `scene` with its one material alpha-masked by a `size` x `size` texture whose alpha is
/// 1 in the left half (u < 0.5) and 0 in the right, cutoff 0.5.
pub fn half_masked(mut scene: Scene, size: u32) -> Scene {
    let mut rgba8 = Vec::new();
    for _y in 0..size {
        for x in 0..size {
            let alpha = if x < size / 2 { 255 } else { 0 };
            rgba8.extend([255, 255, 255, alpha]);
        }
    }
    scene.textures.push(Texture {
        source: "half mask".into(),
        width: size,
        height: size,
        color_space: manylights_scene::ColorSpace::Srgb,
        rgba8,
    });
    scene.materials[0] = Material {
        base_color_factor: Vec4::ONE,
        base_color_texture: Some(scene.textures.len() - 1),
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..Material::default()
    };
    scene
}

/// Reproducible numbers in [0, 1) for tests (splitmix64), without a dependency.
#[derive(Debug)]
pub struct Numbers(pub u64);

impl Numbers {
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A point of the box from `min` to `max`.
    pub fn in_box(&mut self, min: DVec3, max: DVec3) -> DVec3 {
        min + (max - min) * DVec3::new(self.uniform(), self.uniform(), self.uniform())
    }
}
