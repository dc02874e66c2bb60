// Camera rays: pinhole, jittered uniformly inside the pixel (box filter). Twin: src/cpu/camera.rs.
#include "bindings.wgsl"

fn generate_ray(pixel: vec2<u32>, u: vec2<f32>) -> Ray {
    let x = (f32(pixel.x) + u.x) / f32(params.image_width) * 2.0 - 1.0;
    let y = 1.0 - (f32(pixel.y) + u.y) / f32(params.image_height) * 2.0;
    let dir = normalize(params.cam_forward + x * params.cam_right + y * params.cam_up);
    return Ray(params.cam_position, dir);
}
