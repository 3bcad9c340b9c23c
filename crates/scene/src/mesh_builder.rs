//! Validation and completion of raw mesh data, shared by every loader: index and
//! finiteness checks, normals generated where missing or degenerate, tangents where a
//! normal map needs them.

use std::path::Path;

use glam::{Vec2, Vec3, Vec4};

use crate::error::{Result, SceneError};
use crate::model::{Mesh, bounds_of, smooth_normals};
use crate::tangents::generate_tangents;

/// Raw attribute streams as a loader read them.
#[derive(Debug, Default)]
pub struct RawMesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    pub tangents: Option<Vec<Vec4>>,
    pub indices: Vec<u32>,
    pub material: usize,
}

impl RawMesh {
    /// Checks the data and fills in what the renderer needs. `needs_tangents` is true when
    /// the mesh's material has a normal map.
    pub fn finish(self, file: &Path, needs_tangents: bool) -> Result<Mesh> {
        let vertex_count = self.positions.len();
        let invalid = |message: String| SceneError::InvalidMesh {
            file: file.to_path_buf(),
            mesh: self.name.clone(),
            message,
        };
        if !self.indices.len().is_multiple_of(3) {
            return Err(invalid(format!(
                "{} indices is not a whole number of triangles",
                self.indices.len()
            )));
        }
        if let Some(&index) = self.indices.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(SceneError::IndexOutOfRange {
                file: file.to_path_buf(),
                mesh: self.name.clone(),
                index,
                vertex_count,
            });
        }
        if let Some((vertex, p)) = self
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite())
        {
            return Err(SceneError::NonFinitePosition {
                file: file.to_path_buf(),
                mesh: self.name.clone(),
                vertex,
                value: format!("{p}"),
            });
        }
        for (stream, len) in [
            ("normal", self.normals.as_ref().map(Vec::len)),
            ("uv", self.uvs.as_ref().map(Vec::len)),
            ("tangent", self.tangents.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len
                && len != vertex_count
            {
                return Err(invalid(format!(
                    "{len} {stream}s for {vertex_count} positions"
                )));
            }
        }

        let smooth = smooth_normals(&self.positions, &self.indices);
        // Degenerate normals from the file (zero length, NaN) fall back to the smooth
        // normal of that vertex rather than poisoning the shading with NaN.
        let normals = match self.normals {
            None => smooth,
            Some(normals) => normals
                .into_iter()
                .zip(&smooth)
                .map(|(n, fallback)| n.try_normalize().unwrap_or(*fallback))
                .collect(),
        };
        let uvs: Vec<Vec2> = match self.uvs {
            None => vec![Vec2::ZERO; vertex_count],
            Some(uvs) => uvs
                .into_iter()
                .map(|uv| if uv.is_finite() { uv } else { Vec2::ZERO })
                .collect(),
        };
        let tangents = if needs_tangents {
            let from_file = self.tangents.filter(|tangents| {
                tangents
                    .iter()
                    .all(|t| t.is_finite() && t.truncate().length_squared() > 1e-12)
            });
            Some(match from_file {
                Some(tangents) => tangents
                    .into_iter()
                    .map(|t| {
                        let sign = if t.w < 0.0 { -1.0 } else { 1.0 };
                        t.truncate().normalize().extend(sign)
                    })
                    .collect(),
                None => generate_tangents(&self.positions, &normals, &uvs, &self.indices),
            })
        } else {
            None
        };

        Ok(Mesh {
            bounds: bounds_of(&self.positions),
            name: self.name,
            positions: self.positions,
            normals,
            uvs,
            tangents,
            indices: self.indices,
            material: self.material,
        })
    }
}
