//! The camera: position plus yaw/pitch (robust at +-90 degrees pitch, where look-at with a
//! fixed up vector degenerates), perspective projection with wgpu's 0..1 depth, and named
//! presets per scene.

use glam::{EulerRot, Mat4, Quat, Vec3};
use manylights_scene::Aabb;

/// How the camera projects.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Projection {
    /// Perspective with the camera's vertical field of view.
    #[default]
    Perspective,
    /// Orthographic, showing `height` metres vertically (width from the aspect ratio);
    /// near may be 0.
    Orthographic { height: f32 },
}

/// A camera. Right-handed, +Y up; yaw 0 and pitch 0 look down -Z; positive
/// yaw turns left (counter-clockwise seen from above), positive pitch looks up.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub position: Vec3,
    /// Radians.
    pub yaw: f32,
    /// Radians, in [-pi/2, pi/2].
    pub pitch: f32,
    /// Radians about the view direction (positive tilts the image clockwise).
    pub roll: f32,
    /// Vertical field of view, radians (perspective).
    pub fov_y: f32,
    pub projection: Projection,
    /// Reverse-Z: depth 1 at near and 0 at far. With the float depth buffer this keeps the
    /// depth error relative to the distance; see ARCHITECTURE.md for when it matters.
    pub reverse_z: bool,
    /// Near and far plane distances (0 < near < far); far may be infinite (an infinite
    /// projection; the cluster grid then fits its depth range to the scene).
    pub near: f32,
    /// Written `"inf"` when infinite (JSON has no infinity).
    #[serde(with = "infinite_as_text")]
    pub far: f32,
}

/// A distance that may be infinite, in a serialized camera: a number, or the text `inf`
/// (JSON, which the settings round-trip through, has no infinity).
mod infinite_as_text {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(value: &f32, serializer: S) -> Result<S::Ok, S::Error> {
        if value.is_infinite() && *value > 0.0 {
            serializer.serialize_str("inf")
        } else {
            serializer.serialize_f32(*value)
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f32, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Distance {
            Number(f32),
            Text(String),
        }
        match Distance::deserialize(deserializer)? {
            Distance::Number(value) => Ok(value),
            Distance::Text(text) if text == "inf" => Ok(f32::INFINITY),
            Distance::Text(text) => Err(serde::de::Error::custom(format!(
                "a distance is a number or `inf`, got `{text}`"
            ))),
        }
    }
}

impl Camera {
    /// A camera at `position` looking at `target` (which must differ from `position`).
    pub fn look_at(position: Vec3, target: Vec3, fov_y_degrees: f32, near: f32, far: f32) -> Self {
        let direction = (target - position).normalize_or(Vec3::NEG_Z);
        Self {
            position,
            yaw: (-direction.x).atan2(-direction.z),
            pitch: direction.y.clamp(-1.0, 1.0).asin(),
            roll: 0.0,
            projection: Projection::Perspective,
            reverse_z: false,
            fov_y: fov_y_degrees.to_radians(),
            near,
            far,
        }
    }

    pub fn rotation(&self) -> Quat {
        Quat::from_euler(EulerRot::YXZ, self.yaw, self.pitch, self.roll)
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        self.rotation() * Vec3::NEG_Z
    }

    /// World to view space with the camera at the origin: the view of camera-relative
    /// rendering (only the rotation).
    pub fn view_matrix_relative(&self) -> Mat4 {
        Mat4::from_quat(self.rotation()).inverse()
    }

    /// World to view space.
    pub fn view_matrix(&self) -> Mat4 {
        Mat4::from_rotation_translation(self.rotation(), self.position).inverse()
    }

    /// View to clip space, depth 0 at near and 1 at far (or at infinity), or the other
    /// way round with reverse-Z.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        use glam::camera::rh::proj::directx;
        // Reverse-Z swaps the planes: depth 1 at near, 0 at far.
        let (near, far) = if self.reverse_z {
            (self.far, self.near)
        } else {
            (self.near, self.far)
        };
        if let Projection::Orthographic { height } = self.projection {
            let (half_w, half_h) = (height * aspect * 0.5, height * 0.5);
            return directx::orthographic(-half_w, half_w, -half_h, half_h, near, far);
        }
        match (self.far == f32::INFINITY, self.reverse_z) {
            (true, false) => directx::perspective_infinite(self.fov_y, aspect, self.near),
            (true, true) => directx::perspective_infinite_reverse(self.fov_y, aspect, self.near),
            (false, _) => directx::perspective(self.fov_y, aspect, near, far),
        }
    }

    /// The depth convention this camera's projection needs.
    pub fn depth_convention(&self) -> manylights_gpu::DepthConvention {
        if self.reverse_z {
            manylights_gpu::DepthConvention::Reverse
        } else {
            manylights_gpu::DepthConvention::Standard
        }
    }

    /// Checks the numbers a projection needs.
    pub fn validate(&self) -> Result<(), String> {
        let finite = self.position.is_finite()
            && [self.yaw, self.pitch, self.roll, self.fov_y, self.near]
                .iter()
                .all(|v| v.is_finite());
        if !finite || self.far.is_nan() {
            return Err("camera values must be finite (only far may be infinite)".into());
        }
        if let Projection::Orthographic { height } = self.projection {
            if !(height > 0.0 && height.is_finite()) {
                return Err(format!(
                    "an orthographic camera needs a positive height, got {height}"
                ));
            }
            if !(self.near >= 0.0 && self.far.is_finite() && self.far > self.near) {
                return Err(format!(
                    "an orthographic camera needs 0 <= near < far < infinity (near {}, far {})",
                    self.near, self.far
                ));
            }
            return Ok(());
        }
        if !(self.near > 0.0 && self.far > self.near) {
            return Err(format!(
                "camera needs 0 < near < far (near {}, far {})",
                self.near, self.far
            ));
        }
        if !(self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return Err(format!(
                "field of view must be between 0 and 180 degrees, got {}",
                self.fov_y.to_degrees()
            ));
        }
        Ok(())
    }

    /// A `--camera` argument reproducing this camera: `x,y,z,yaw,pitch,fov,roll` (degrees).
    pub fn to_argument(&self) -> String {
        format!(
            "{:.3},{:.3},{:.3},{:.2},{:.2},{:.1},{:.2}",
            self.position.x,
            self.position.y,
            self.position.z,
            self.yaw.to_degrees(),
            self.pitch.to_degrees(),
            self.fov_y.to_degrees(),
            self.roll.to_degrees()
        )
    }

    /// A camera outside `bounds` looking at its centre along a diagonal (for scenes
    /// without presets).
    pub fn fit(bounds: &Aabb) -> Self {
        let center = bounds.center();
        let radius = (bounds.size().length() * 0.5).max(1e-3);
        let position = center + Vec3::new(1.0, 0.6, 1.0).normalize() * radius * 2.2;
        Self::look_at(position, center, 45.0, radius * 0.01, radius * 10.0)
    }
}
