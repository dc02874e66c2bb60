// Adaptive sampling: pixels stop taking samples once their estimate has converged (Cycles'
// criterion; the derivation is in the twin, src/adaptive.rs). An adaptive film appends, after
// the pixels' rows, one row per pixel (Σ of its odd-numbered samples as f32 bits, 1 if it
// passed its last test), then one word per pixel, 1 once it has converged.
#include "bindings.wgsl"
#include "film.wgsl"


fn film_pixels() -> u32 {
    return params.film_width * params.film_height;
}

// Row of pixel `slot`'s half-buffer record.
fn adaptive_record(slot: u32) -> u32 {
    return FILM_WORDS * film_pixels() + slot;
}

fn adaptive_converged(slot: u32) -> bool {
    let at = (FILM_WORDS + 1u) * film_pixels() + slot / 4u;
    return film[at][slot % 4u] != 0u;
}

// Are pixels that have taken `n` samples tested now?
fn adaptive_test_due(n: u32) -> bool {
    return params.noise_threshold > 0.0 && n >= params.adaptive_min_samples && n % params.adaptive_step == 0u;
}

fn adaptive_error(sum: vec3<f32>, half_sum: vec3<f32>, n: f32) -> f32 {
    let scale = 1.0 / max(n, 1.0);
    let difference = abs(sum - 2.0 * half_sum) * scale;
    let intensity = (sum.x + sum.y + sum.z) * scale;
    return (difference.x + difference.y + difference.z) / (1e-4 + sqrt(max(intensity, 0.0)));
}

// After film_add_sample added `l` to pixel `slot`: an odd-numbered sample joins the half
// buffer, and the pixel runs its convergence test when one is due.
fn adaptive_add_sample(slot: u32, l: vec3<f32>) {
    let base = FILM_WORDS * slot;
    let count = film[base].w;
    let taken = count + film[base + 1u].w;
    let at = adaptive_record(slot);
    var record = film[at];
    var half_sum = bitcast<vec3<f32>>(record.xyz);
    if (taken % 2u == 0u && is_finite_vec3(l)) {
        half_sum += clamp(l, vec3<f32>(0.0), vec3<f32>(MAX_SAMPLE));
        record = vec4<u32>(bitcast<vec3<u32>>(half_sum), record.w);
    }
    if (adaptive_test_due(taken)) {
        record.w = select(0u, 1u, adaptive_error(film_sum(base), half_sum, f32(count)) < params.noise_threshold);
    }
    film[at] = record;
}

// After a test: a pixel that passed converges when every neighbour in the film passed too
// (converged pixels keep their passed mark). Reads records, writes only flags: no races.
@compute @workgroup_size(8, 8, 1)
fn adaptive_settle(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.film_width || gid.y >= params.film_height) {
        return;
    }
    let slot = gid.y * params.film_width + gid.x;
    if (adaptive_converged(slot)) {
        return;
    }
    var all_passed = true;
    for (var y = max(gid.y, 1u) - 1u; y <= min(gid.y + 1u, params.film_height - 1u); y += 1u) {
        for (var x = max(gid.x, 1u) - 1u; x <= min(gid.x + 1u, params.film_width - 1u); x += 1u) {
            all_passed = all_passed && film[adaptive_record(y * params.film_width + x)].w != 0u;
        }
    }
    if (all_passed) {
        film[(FILM_WORDS + 1u) * film_pixels() + slot / 4u][slot % 4u] = 1u;
    }
}
