// KHR_materials_iridescence's thin film: the Airy reflectance of a dielectric film over the
// base integrated against the CIE observer in Fourier space (Belcour & Barla 2017), two
// harmonics, as the extension's reference does. Twin: src/cpu/iridescence.rs.
#include "common.wgsl"

const XYZ_TO_REC709: mat3x3<f32> = mat3x3<f32>(
    vec3<f32>(3.2404542, -0.9692660, 0.0556434),
    vec3<f32>(-1.5371385, 1.8760108, -0.2040259),
    vec3<f32>(-0.4985314, 0.0415560, 1.0572252),
);

fn ior_to_fresnel0(transmitted: f32, incident: f32) -> f32 {
    let r = (transmitted - incident) / (transmitted + incident);
    return r * r;
}

fn fresnel0_to_ior(f0: vec3<f32>) -> vec3<f32> {
    let s = sqrt(clamp(f0, vec3<f32>(0.0), vec3<f32>(0.9999)));
    return (vec3<f32>(1.0) + s) / (vec3<f32>(1.0) - s);
}

fn eval_sensitivity(opd: f32, shift: vec3<f32>) -> vec3<f32> {
    let phase = 2.0 * PI * opd * 1e-9;
    let val = vec3<f32>(5.4856e-13, 4.4201e-13, 5.2481e-13);
    let pos = vec3<f32>(1.6810e6, 1.7953e6, 2.2084e6);
    let var_ = vec3<f32>(4.3278e9, 9.3046e9, 6.6121e9);
    var xyz = val * sqrt(2.0 * PI * var_) * cos(pos * phase + shift) * exp(-phase * phase * var_);
    xyz.x += 9.7470e-14 * sqrt(2.0 * PI * 4.5282e9) * cos(2.2399e6 * phase + shift.x) * exp(-4.5282e9 * phase * phase);
    return XYZ_TO_REC709 * (xyz / 1.0685e-7);
}

fn schlick_film(f0: f32, c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    return f0 + (1.0 - f0) * m * m * m * m * m;
}

fn iridescence_fresnel(outside: f32, film_ior: f32, cos_theta1: f32, thickness: f32, base_f0: vec3<f32>) -> vec3<f32> {
    let t = clamp(thickness / 0.03, 0.0, 1.0);
    let film = outside + (film_ior - outside) * (t * t * (3.0 - 2.0 * t));
    let c1 = clamp(cos_theta1, 0.0, 1.0);
    let sin2_t2 = (outside / film) * (outside / film) * (1.0 - c1 * c1);
    let cos2_t2 = 1.0 - sin2_t2;
    if (cos2_t2 < 0.0) {
        return vec3<f32>(1.0);
    }
    let c2 = sqrt(cos2_t2);
    let r12 = schlick_film(ior_to_fresnel0(film, outside), c1);
    let t121 = 1.0 - r12;
    let phi12 = select(0.0, PI, film < outside);
    let phi21 = PI - phi12;
    let base_ior = fresnel0_to_ior(base_f0);
    let r1 = vec3<f32>(
        ior_to_fresnel0(base_ior.x, film),
        ior_to_fresnel0(base_ior.y, film),
        ior_to_fresnel0(base_ior.z, film),
    );
    let r23 = vec3<f32>(schlick_film(r1.x, c2), schlick_film(r1.y, c2), schlick_film(r1.z, c2));
    let phi23 = select(vec3<f32>(0.0), vec3<f32>(PI), base_ior < vec3<f32>(film));
    let opd = 2.0 * film * thickness * c2;
    let phi = vec3<f32>(phi21) + phi23;
    let r123 = clamp(r12 * r23, vec3<f32>(1e-5), vec3<f32>(0.9999));
    let sqrt_r123 = sqrt(r123);
    let rs = t121 * t121 * r23 / (vec3<f32>(1.0) - r123);
    var i = r12 + rs;
    var cm = rs - t121;
    for (var m = 1; m <= 2; m++) {
        cm *= sqrt_r123;
        i += cm * 2.0 * eval_sensitivity(f32(m) * opd, f32(m) * phi);
    }
    return clamp(i, vec3<f32>(0.0), vec3<f32>(1.0));
}
