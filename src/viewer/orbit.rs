//! The viewer's camera: orbit about a target, pan, zoom and fly, from mouse and keys.

use super::Viewer;
use crate::scene::Camera;
use eframe::egui;
use glam::Vec3;

/// Radians of yaw and pitch per point dragged.
const ROTATE_PER_POINT: f32 = 0.005;
/// Pan per point dragged, as a fraction of the orbit distance.
const PAN_PER_POINT: f32 = 0.0015;
/// Zoom per wheel point (exponential).
const ZOOM_PER_POINT: f32 = 0.002;
/// Pitch stays short of the poles, where yaw is undefined.
const MAX_PITCH: f32 = 1.55;
/// Fly speed: scene extents per second.
const FLY_EXTENTS_PER_SECOND: f32 = 0.5;

/// Mouse and keyboard camera: orbit about a target, pan, zoom, fly.
#[derive(Clone, Debug)]
pub struct Orbit {
    pub target: Vec3,
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
    pub yfov: f32,
}

impl Orbit {
    pub fn from_camera(c: &Camera, scene_center: Vec3, extent: f32) -> Orbit {
        let distance = (scene_center - c.position).dot(c.forward).max(0.05 * extent).max(1e-3);
        let f = c.forward;
        Orbit {
            target: c.position + f * distance,
            yaw: f.x.atan2(-f.z),
            pitch: f.y.clamp(-1.0, 1.0).asin(),
            distance,
            yfov: c.yfov,
        }
    }

    fn forward(&self) -> Vec3 {
        Vec3::new(self.yaw.sin() * self.pitch.cos(), self.pitch.sin(), -self.yaw.cos() * self.pitch.cos())
    }

    pub fn camera(&self) -> Camera {
        let f = self.forward();
        Camera::look_at("viewer", self.target - f * self.distance, self.target, Vec3::Y, self.yfov)
    }
}

impl Viewer {
    pub(super) fn input(&mut self, ui: &egui::Ui, response: &egui::Response) -> bool {
        let mut changed = false;
        let d = response.drag_delta();
        let shift = ui.input(|i| i.modifiers.shift);
        if response.dragged_by(egui::PointerButton::Middle)
            || (shift && response.dragged_by(egui::PointerButton::Primary))
        {
            let c = self.orbit.camera();
            let k = self.orbit.distance * PAN_PER_POINT;
            self.orbit.target += (-c.right * d.x + c.up * d.y) * k;
            changed |= d != egui::Vec2::ZERO;
        } else if response.dragged_by(egui::PointerButton::Primary) {
            self.orbit.yaw += d.x * ROTATE_PER_POINT;
            self.orbit.pitch = (self.orbit.pitch - d.y * ROTATE_PER_POINT).clamp(-MAX_PITCH, MAX_PITCH);
            changed |= d != egui::Vec2::ZERO;
        }
        // A click focuses the lens on what is under the pointer.
        if response.clicked()
            && let (Some(p), Some(r)) = (response.interact_pointer_pos(), &self.renderer)
        {
            let uv = (p - response.rect.min) / response.rect.size();
            let pixel = glam::UVec2::new(
                (uv.x * self.settings.width as f32).max(0.0) as u32,
                (uv.y * self.settings.height as f32).max(0.0) as u32,
            );
            if let Some(depth) = r.pick_depth(pixel) {
                self.settings.focus_distance = Some(depth);
                self.status = format!("focus distance {:.4}", self.settings.focus_distance.unwrap_or(0.0));
                changed = true;
            }
        }
        if response.hovered() {
            let s = ui.input(|i| i.smooth_scroll_delta);
            let wheel = s.x + s.y;
            if wheel != 0.0 {
                self.orbit.distance = (self.orbit.distance * (-wheel * ZOOM_PER_POINT).exp()).max(1e-4 * self.extent);
                changed = true;
            }
        }
        if !ui.ctx().egui_wants_keyboard_input() {
            let dt = ui.input(|i| i.stable_dt).min(0.1);
            let speed = FLY_EXTENTS_PER_SECOND * self.extent * dt;
            let c = self.orbit.camera();
            let mut mv = Vec3::ZERO;
            ui.input(|i| {
                for (key, dir) in [
                    (egui::Key::W, c.forward),
                    (egui::Key::S, -c.forward),
                    (egui::Key::D, c.right),
                    (egui::Key::A, -c.right),
                    (egui::Key::E, Vec3::Y),
                    (egui::Key::Q, -Vec3::Y),
                ] {
                    if i.key_down(key) {
                        mv += dir;
                    }
                }
            });
            if mv != Vec3::ZERO {
                self.orbit.target += mv * speed;
                changed = true;
            }
            if ui.input(|i| i.key_pressed(egui::Key::F)) {
                self.orbit = self.home.clone();
                changed = true;
            }
        }
        changed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_reproduces_the_camera_it_starts_from() {
        // The viewer's first frame uses the same camera as `veach render`.
        let crate::Loaded { scene, camera, .. } =
            crate::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cornell-box.gltf")), None)
                .expect("asset");
        let b = scene.bounds();
        let c = Orbit::from_camera(&camera, b.center(), b.diagonal().length()).camera();
        assert!((c.position - camera.position).length() < 1e-3 * b.diagonal().length(), "{c:?} vs {camera:?}");
        assert!((c.forward - camera.forward).length() < 1e-5);
        assert!((c.up - camera.up).length() < 1e-5 && (c.right - camera.right).length() < 1e-5);
        assert_eq!(c.yfov, camera.yfov);
    }
}
