//! Adaptive sampling: pixels stop taking samples once their estimate has converged, by the
//! criterion Cycles uses. Twin: `shaders/adaptive.wgsl`.
//!
//! Besides the full sum I of its samples, each pixel keeps the sum A of its odd-numbered
//! samples (the half buffer). With n samples, I/n and 2A/n are two estimates of the pixel;
//! their difference, relative to the square root of the intensity (noise a viewer sees
//! scales with it), is the error:
//!
//! error = (|I − 2A|_r + |I − 2A|_g + |I − 2A|_b) / n / (10⁻⁴ + √((I_r + I_g + I_b) / n))
//!
//! Pixels are tested once they have `adaptive_min_samples` samples and then every
//! `adaptive_step`; a pixel that passes converges only when every neighbour in its 3×3
//! window passed too (Cycles' dilation of unconverged regions by one pixel: noise at an edge
//! of a converged region keeps its border sampling). A converged pixel takes no more samples.
//! The tests happen at fixed sample counts and read only the film, so an adaptive render is
//! deterministic for a seed and resumes exactly from its EXR, whatever the chunking.

use crate::film::{Film, film_sum};
use crate::params::Params;
use glam::Vec3;

pub use crate::settings::{ADAPTIVE_STEP, DEFAULT_MIN_SAMPLES};

/// Whether pixels that have taken `n` samples are tested now. Twin of `adaptive_test_due`.
pub fn adaptive_test_due(params: &Params, n: u32) -> bool {
    params.noise_threshold > 0.0 && n >= params.adaptive_min_samples && n.is_multiple_of(params.adaptive_step)
}

/// The error estimate of a pixel from its sum, its half buffer and its count. Twin of
/// `adaptive_error`.
pub fn adaptive_error(sum: Vec3, half: Vec3, n: f32) -> f32 {
    let scale = 1.0 / n.max(1.0);
    let difference = (sum - 2.0 * half).abs() * scale;
    let intensity = (sum.x + sum.y + sum.z) * scale;
    (difference.x + difference.y + difference.z) / (1e-4 + intensity.max(0.0).sqrt())
}

/// After `film_add_sample` added `l` to a pixel's words `p`: adds an odd-numbered sample to
/// the half buffer `record` and runs the pixel's convergence test when one is due. Twin of
/// `adaptive_add_sample`.
pub fn adaptive_add_sample(params: &Params, p: &[u32], record: &mut [u32], l: Vec3) {
    let taken = p[3].wrapping_add(p[7]);
    let mut half = Vec3::new(f32::from_bits(record[0]), f32::from_bits(record[1]), f32::from_bits(record[2]));
    if taken.is_multiple_of(2) && l.is_finite() {
        half += l.clamp(Vec3::ZERO, Vec3::splat(crate::film::MAX_SAMPLE));
        record[..3].copy_from_slice(&[half.x.to_bits(), half.y.to_bits(), half.z.to_bits()]);
    }
    if adaptive_test_due(params, taken) {
        record[3] = (adaptive_error(film_sum(p), half, p[3] as f32) < params.noise_threshold) as u32;
    }
}

/// After a test: every pixel that passed, with all its neighbours in the film, converges.
/// Twin of the `adaptive_settle` kernel (one invocation per pixel).
pub fn adaptive_settle(film: &mut Film) {
    let (w, h) = (film.width as usize, film.height as usize);
    let passed = |f: &Film, x: usize, y: usize| f.data[f.adaptive_record(y * w + x) + 3] != 0;
    let mut newly = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            if film.converged(i) {
                continue;
            }
            let all = (y.saturating_sub(1)..(y + 2).min(h))
                .all(|ny| (x.saturating_sub(1)..(x + 2).min(w)).all(|nx| passed(film, nx, ny)));
            if all {
                newly.push(i);
            }
        }
    }
    for i in newly {
        let at = film.converged_flag(i);
        film.data[at] = 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_error_is_the_halves_difference_relative_to_the_root_intensity() {
        // Four samples 1, 3, 1, 3: I = 8, A = 3 + 3 = 6, |I − 2A| / n = 1 per channel.
        let e = adaptive_error(Vec3::splat(8.0), Vec3::splat(6.0), 4.0);
        assert!((e - 3.0 / (1e-4 + 6f32.sqrt())).abs() < 1e-6, "{e}");
        assert_eq!(adaptive_error(Vec3::ZERO, Vec3::ZERO, 16.0), 0.0, "a black pixel has converged");
        assert_eq!(adaptive_error(Vec3::splat(4.0), Vec3::splat(2.0), 4.0), 0.0, "equal halves");
    }

    #[test]
    fn settling_dilates_unconverged_pixels_by_one() {
        let mut film = Film::with_layout(5, 5, crate::film::FilmLayout { adaptive: true, aovs: false });
        for i in 0..25 {
            let at = film.adaptive_record(i) + 3;
            film.data[at] = (i != 12) as u32; // every pixel passed but the centre
        }
        adaptive_settle(&mut film);
        for y in 0..5 {
            for x in 0..5 {
                let near = (x as i32 - 2).abs() <= 1 && (y as i32 - 2).abs() <= 1;
                assert_eq!(film.converged(y * 5 + x), !near, "pixel {x},{y}");
            }
        }
        assert_eq!(film.converged_fraction(), Some(16.0 / 25.0));
    }
}
