//! Image error metrics against a reference.

use crate::film::Film;
use glam::Vec3;

/// Root-mean-square error of the film's mean against a reference, over pixels and channels.
pub fn rmse(film: &Film, reference: &[Vec3]) -> f64 {
    let sum: f64 = reference
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let d = (film.mean(i) - *r).as_dvec3();
            d.dot(d)
        })
        .sum();
    (sum / (3.0 * reference.len().max(1) as f64)).sqrt()
}

/// RMSE of values clamped to [0, 1]: the error a tone-mapped image shows (the unclamped
/// RMSE is dominated by the few pixels that see a light directly).
pub fn rmse_clamped(film: &Film, reference: &[Vec3]) -> f64 {
    let sum: f64 = reference
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let d = (film.mean(i).clamp(Vec3::ZERO, Vec3::ONE) - r.clamp(Vec3::ZERO, Vec3::ONE)).as_dvec3();
            d.dot(d)
        })
        .sum();
    (sum / (3.0 * reference.len().max(1) as f64)).sqrt()
}
