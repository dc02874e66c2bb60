//! Pinhole perspective camera (glTF conventions: looks down −Z of its node).

use super::Bounds;
use glam::{Mat4, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub name: String,
    pub position: Vec3,
    /// Unit vectors of the camera frame in world space.
    pub forward: Vec3,
    pub up: Vec3,
    pub right: Vec3,
    /// Vertical field of view in radians (a perspective camera).
    pub yfov: f32,
    /// An orthographic camera's half height of view in scene units (glTF's `ymag`); None: a
    /// perspective camera.
    pub ortho: Option<f32>,
}

impl Camera {
    /// Camera from a glTF node's world matrix.
    pub fn from_matrix(name: String, m: Mat4, yfov: f32) -> Camera {
        let position = m.w_axis.truncate();
        let forward = (-m.z_axis.truncate()).normalize_or(Vec3::NEG_Z);
        let up0 = m.y_axis.truncate();
        let right = forward.cross(up0).normalize_or(Vec3::X);
        let up = right.cross(forward);
        Camera { name, position, forward, up, right, yfov, ortho: None }
    }

    /// An orthographic camera from a glTF node's world matrix and its half height `ymag`
    /// (the width follows the image's aspect, as a perspective camera's does).
    pub fn orthographic(name: String, m: Mat4, ymag: f32) -> Camera {
        Camera { ortho: Some(ymag), ..Camera::from_matrix(name, m, 40f32.to_radians()) }
    }

    pub fn look_at(name: &str, position: Vec3, target: Vec3, up: Vec3, yfov: f32) -> Camera {
        let forward = (target - position).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(up).normalize_or(Vec3::X);
        let up = right.cross(forward);
        Camera { name: name.to_string(), position, forward, up, right, yfov, ortho: None }
    }

    /// A default view: the bounding sphere seen from +Z, filling a 40° field of view.
    pub fn framing(bounds: Bounds) -> Camera {
        let yfov = 40f32.to_radians();
        if bounds.is_empty() {
            return Camera::look_at("default", Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, yfov);
        }
        let center = bounds.center();
        let radius = (0.5 * bounds.diagonal().length()).max(1e-6);
        let distance = radius / (0.5 * yfov).sin() * 1.05;
        Camera::look_at("default", center + Vec3::Z * distance, center, Vec3::Y, yfov)
    }
}
