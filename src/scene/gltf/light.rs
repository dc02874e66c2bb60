//! KHR_lights_punctual lights and the scene's environment from `extras`.

use crate::scene::{PunctualKind, PunctualLight};
use glam::{Mat4, Vec3};

/// A KHR_lights_punctual light placed by its node's world transform.
pub fn convert_light(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Option<PunctualLight> {
    use gltf::khr_lights_punctual::Kind;
    let intensity = Vec3::from(light.color()).max(Vec3::ZERO) * light.intensity().max(0.0);
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let kind = match light.kind() {
        Kind::Point => PunctualKind::Point,
        Kind::Directional => PunctualKind::Directional,
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            let outer = outer_cone_angle.clamp(0.0, std::f32::consts::FRAC_PI_2);
            let inner = inner_cone_angle.clamp(0.0, outer);
            PunctualKind::Spot { cos_inner: inner.cos(), cos_outer: outer.cos() }
        }
    };
    let range = light.range().filter(|r| r.is_finite() && *r > 0.0).unwrap_or(f32::INFINITY);
    let ok = intensity.is_finite() && position.is_finite() && direction != Vec3::ZERO && direction.is_finite();
    let intensity = intensity.min(Vec3::splat(super::material::MAX_RADIANCE));
    (ok && intensity.max_element() > 0.0).then_some(PunctualLight { kind, position, direction, intensity, range })
}

/// `extras.environment = {"type": "constant", "radiance": [r, g, b]}` on the scene, as the
/// reference scenes store it (glTF itself cannot describe an environment).
pub fn environment_from_extras(extras: &gltf::json::Extras) -> Option<Vec3> {
    let raw = extras.as_ref()?;
    let v: serde_json::Value = serde_json::from_str(raw.get()).ok()?;
    let env = v.get("environment")?;
    if env.get("type")?.as_str()? != "constant" {
        return None;
    }
    let r = env.get("radiance")?.as_array()?;
    let c: Vec<f32> = r.iter().filter_map(|x| x.as_f64().map(|x| x as f32)).collect();
    let ok = c.len() == 3 && c.iter().all(|x| x.is_finite() && *x >= 0.0);
    ok.then(|| Vec3::new(c[0], c[1], c[2]).min(Vec3::splat(super::material::MAX_RADIANCE)))
}
