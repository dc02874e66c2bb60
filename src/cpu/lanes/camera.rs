//! `camera_sample` in lanes: the samplers and camera rays of the paths a packet starts
//! together (the lanes whose paths ended in the last bounce), the scalar's operations lane by
//! lane, so the same bits. The pinhole camera runs in lanes; an orthographic camera or a lens
//! takes the scalar `generate_ray` lane by lane.

use super::lane::{F8, M8, U8, V3};
use super::lanes_of;
use super::sampler::{SamplerLanes, pcg_hash};
use crate::cpu::camera::generate_ray;
use crate::cpu::rng;
use crate::cpu::sampler::{SAMPLER_INDEPENDENT, SOBOL_SEED_SALT};
use crate::params::{PROJECTION_ORTHOGRAPHIC, Params};
use glam::{UVec2, Vec2, Vec3};

/// `camera_sample` in the lanes of `m`: lane i starts sample `sample[i]` of pixel
/// (`x[i]`, `y[i]`) (film coordinates, the tile's offset added). Its sampler, as
/// `sampler_init` makes it and after the jitter's draw, goes into lane i of `sampler`; the
/// rays' origins and directions are returned (lanes outside `m`: not to be used).
#[inline(always)]
pub fn camera_samples(params: &Params, sample: U8, x: U8, y: U8, sampler: &mut SamplerLanes, m: M8) -> (V3, V3) {
    let pixel = y.zip(x, |y, x| y.wrapping_mul(params.image_width).wrapping_add(x));
    let take = |new: U8, old: U8| U8::from_fn(|i| if m.0[i] != 0 { new.0[i] } else { old.0[i] });
    // sampler_init
    let zero = U8::splat(0);
    let (pixel_seed, state) = if sampler.kind == SAMPLER_INDEPENDENT {
        let seed_hash = rng::pcg_hash(params.seed);
        (zero, pcg_hash(pixel.zip(pcg_hash(sample.map(|s| s ^ seed_hash)), |p, h| p ^ h)))
    } else {
        let seed_hash = rng::pcg_hash(params.seed ^ SOBOL_SEED_SALT);
        (pcg_hash(pixel.map(|p| p ^ seed_hash)), zero)
    };
    sampler.pixel_seed = take(pixel_seed, sampler.pixel_seed);
    sampler.index = take(sample, sampler.index);
    sampler.dim = take(zero, sampler.dim);
    sampler.state = take(state, sampler.state);
    let (ux, uy) = sampler.sample_2d(m);
    if params.projection == PROJECTION_ORTHOGRAPHIC || params.aperture > 0.0 {
        // (Orthographic and thin-lens cameras: the scalar function, lane by lane.)
        let (mut origin, mut dir) = (V3::splat(Vec3::ZERO), V3::splat(Vec3::Z));
        for i in lanes_of(m.bits()) {
            let mut s = sampler.lane(i);
            let ray = generate_ray(params, UVec2::new(x.0[i], y.0[i]), Vec2::new(ux.0[i], uy.0[i]), &mut s);
            sampler.set_lane(i, &s);
            origin.set_lane(i, ray.origin);
            dir.set_lane(i, ray.dir);
        }
        return (origin, dir);
    }
    // generate_ray's pinhole camera.
    let to_f32 = |v: U8| F8::from_fn(|i| v.0[i] as f32);
    let sx = (to_f32(x) + ux) / (params.image_width as f32) * 2.0 - 1.0;
    let sy = 1.0 - (to_f32(y) + uy) / (params.image_height as f32) * 2.0;
    let (forward, right, up) =
        (V3::splat(params.cam_forward.into()), V3::splat(params.cam_right.into()), V3::splat(params.cam_up.into()));
    let dir = (forward + right * sx + up * sy).normalize();
    (V3::splat(params.cam_position.into()), dir)
}
