//! Tangent generation with MikkTSpace (the `bevy_mikktspace` crate, a safe-Rust port of
//! the reference implementation that glTF and Blender use). The older `mikktspace` crate,
//! an unsafe transliteration of the C code, read out of bounds on meshes the fuzzers built
//! (`fuzz/regressions/`), so it was replaced.
//!
//! MikkTSpace produces one tangent per triangle corner. Our meshes share vertices between
//! corners, so each vertex gets the normalised average of its corners' tangents. Where
//! the corners agree (no UV or mirroring seam through the vertex) this is exactly
//! MikkTSpace's result; at seams it is a smooth compromise. Meshes that need exact
//! tangents at seams should ship TANGENT in the file.

use glam::{Vec2, Vec3, Vec4};

struct Corners<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    uvs: &'a [Vec2],
    indices: &'a [u32],
    /// Sum of corner tangents (xyz) and of corner signs (w) per vertex.
    accumulated: Vec<Vec4>,
}

impl Corners<'_> {
    fn vertex(&self, face: usize, corner: usize) -> usize {
        self.indices[face * 3 + corner] as usize
    }
}

impl bevy_mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.positions[self.vertex(face, vert)].to_array()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.normals[self.vertex(face, vert)].to_array()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.vertex(face, vert)].to_array()
    }
    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        // `None` for corners of degenerate faces: they keep the fallback below.
        if let Some(tangent_space) = tangent_space {
            let vertex = self.vertex(face, vert);
            self.accumulated[vertex] += Vec4::from_array(tangent_space.tangent_encoded());
        }
    }
}

/// Per-vertex tangents (xyz unit, w = bitangent sign) for an indexed triangle mesh.
pub fn generate_tangents(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[u32],
) -> Vec<Vec4> {
    let mut corners = Corners {
        positions,
        normals,
        uvs,
        indices,
        accumulated: vec![Vec4::ZERO; positions.len()],
    };
    // An error means no face had a usable tangent space: every vertex keeps the fallback.
    let _all_degenerate = bevy_mikktspace::generate_tangents(&mut corners);
    corners
        .accumulated
        .iter()
        .zip(normals)
        .map(|(sum, normal)| {
            let sign = if sum.w < 0.0 { -1.0 } else { 1.0 };
            let tangent = sum.truncate().try_normalize().unwrap_or_else(|| {
                // No usable UV gradient: any unit vector perpendicular to the normal.
                normal.any_orthonormal_vector()
            });
            tangent.extend(sign)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tangent_of_a_flat_quad_follows_u() {
        // A quad in the XZ plane facing +Y, u along +X, v along +Z.
        let positions = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let normals = [Vec3::Y; 4];
        let uvs = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        let indices = [0, 2, 1, 0, 3, 2];
        let tangents = generate_tangents(&positions, &normals, &uvs, &indices);
        for t in tangents {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "tangent {t}");
            assert!(t.w.abs() == 1.0);
        }
    }
}
