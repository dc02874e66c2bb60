// Ray-throughput kernel for `veach bench`: traversal alone, without shading. TRACE_KIND 0
// traces a primary ray per pixel; 1 adds a shadow ray from its hit to a light sample; 2 adds a
// cosine-distributed bounce ray from its hit. The host times the three and takes differences,
// as the CPU twin (src/bench.rs, ray_throughput) times batches of the same kinds of rays.
// Each pixel adds (primary ray hit, secondary ray traced, secondary ray hit or unblocked) to
// the film, so that no trace is dead code and the host counts the rays it traced.
#include "integrator.wgsl"

override TRACE_KIND: u32 = 0u;

@compute @workgroup_size(8, 8, 1)
fn trace_rays(@builtin(global_invocation_id) gid: vec3<u32>) {
    let at = film_pixel(gid);
    if (!at.inside) {
        return;
    }
    var sampler: Sampler;
    let ray = camera_sample(at.pixel, &sampler);
    let hit = intersect_closest(ray);
    var count = vec3<f32>(0.0);
    if (hit.tri != NO_HIT) {
        count.x = 1.0;
        let tri = world_triangle(hit.tri, hit.instance);
        let n = normalize(cross(tri.e1, tri.e2));
        let ng = select(n, -n, dot(n, ray.dir) > 0.0);
        let point = tri.p0 + hit.u * tri.e1 + hit.v * tri.e2;
        if (TRACE_KIND == 1u && (params.light_count > 0u || params.tree_emitters > 0u || params.env_select > 0.0)) {
            let ctx = LightContext(point, ng, false);
            let ls = sample_light(ctx, vec3<f32>(sample_1d(&sampler), sample_2d(&sampler)));
            // As the CPU column: only light samples with a density are traced.
            if (ls.pdf > 0.0) {
                count.y = 1.0;
                count.z = select(0.0, 1.0, unoccluded(offset_ray(point, ng), ls));
            }
        } else if (TRACE_KIND == 2u) {
            let wi = from_local(frame_from_normal(ng), sample_cosine_hemisphere(sample_2d(&sampler)));
            count.y = 1.0;
            count.z = select(0.0, 1.0, intersect_closest(Ray(offset_ray(point, ng), wi)).tri != NO_HIT);
        }
    }
    film_add_sample(at.slot, count);
}
