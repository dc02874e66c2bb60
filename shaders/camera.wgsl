// Camera rays: jittered uniformly inside the pixel (box filter); a pinhole, or a thin lens
// focused at params.focus_distance when params.aperture > 0, or an orthographic view.
// Twin: src/cpu/camera.rs.
#include "bindings.wgsl"
#include "sampler.wgsl"
#include "sampling.wgsl"

fn generate_ray(pixel: vec2<u32>, u: vec2<f32>, sampler: ptr<function, Sampler>) -> Ray {
    let x = (f32(pixel.x) + u.x) / f32(params.image_width) * 2.0 - 1.0;
    let y = 1.0 - (f32(pixel.y) + u.y) / f32(params.image_height) * 2.0;
    // An orthographic camera's rays are parallel, from points across its view (no lens).
    if (params.projection == PROJECTION_ORTHOGRAPHIC) {
        return Ray(params.cam_position + x * params.cam_right + y * params.cam_up, normalize(params.cam_forward));
    }
    let dir = normalize(params.cam_forward + x * params.cam_right + y * params.cam_up);
    if (params.aperture <= 0.0) {
        return Ray(params.cam_position, dir);
    }
    // Every ray through the lens meets the pinhole ray on the plane in focus.
    let focus = params.cam_position + dir * (params.focus_distance / dot(dir, params.cam_forward));
    let lens = sample_uniform_disk(sample_2d(sampler)) * params.aperture;
    let origin = params.cam_position + lens.x * normalize(params.cam_right) + lens.y * normalize(params.cam_up);
    return Ray(origin, normalize(focus - origin));
}

// The camera ray of `pixel` for sample params.sample_index, with the sampler its path goes on
// drawing from.
fn camera_sample(pixel: vec2<u32>, sampler: ptr<function, Sampler>) -> Ray {
    *sampler = sampler_init(params.sampler, pixel.y * params.image_width + pixel.x, params.sample_index, params.seed);
    return generate_ray(pixel, sample_2d(sampler), sampler);
}
