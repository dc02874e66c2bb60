// Instances (two-level BVH): records of object↔world transforms stored after the BVH nodes,
// and moving hit data to world space. Twin: src/cpu/instance.rs.
#include "bindings.wgsl"

// An instance record: four node-sized slots from params.instance_base.
struct Instance {
    object_to_world: mat3x4<f32>,
    world_to_object: mat3x4<f32>,
    blas_root: u32,
    flags: u32,
}

const INSTANCE_MIRRORED: u32 = 1u;

fn load_instance(k: u32) -> Instance {
    let base = params.instance_base + 4u * k;
    let a = load_node(base);
    let b = load_node(base + 1u);
    let c = load_node(base + 2u);
    let d = load_node(base + 3u);
    let r0 = vec4<f32>(a.min, bitcast<f32>(a.index));
    let r1 = vec4<f32>(a.max, bitcast<f32>(a.count));
    let r2 = vec4<f32>(b.min, bitcast<f32>(b.index));
    let r3 = vec4<f32>(b.max, bitcast<f32>(b.count));
    let r4 = vec4<f32>(c.min, bitcast<f32>(c.index));
    let r5 = vec4<f32>(c.max, bitcast<f32>(c.count));
    return Instance(mat3x4<f32>(r0, r1, r2), mat3x4<f32>(r3, r4, r5), bitcast<u32>(d.min.x), bitcast<u32>(d.min.y));
}

// Rows of a 3×4 affine transform applied to a point and to a direction.
fn transform_point(m: mat3x4<f32>, p: vec3<f32>) -> vec3<f32> {
    let h = vec4<f32>(p, 1.0);
    return vec3<f32>(dot(m[0], h), dot(m[1], h), dot(m[2], h));
}

fn transform_dir(m: mat3x4<f32>, d: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(m[0].xyz, d), dot(m[1].xyz, d), dot(m[2].xyz, d));
}

// A normal by the inverse transpose: the transpose of world→object's linear part.
fn transform_normal(world_to_object: mat3x4<f32>, n: vec3<f32>) -> vec3<f32> {
    return n.x * world_to_object[0].xyz + n.y * world_to_object[1].xyz + n.z * world_to_object[2].xyz;
}

// The hit triangle in world space (a copy moved by its instance; TRI_MIRRORED when the
// instance mirrors).
fn world_triangle(index: u32, instance: u32) -> Triangle {
    var tri = load_triangle(index);
    if (!INSTANCING) {
        return tri;
    }
    let inst = load_instance(instance);
    tri.p0 = transform_point(inst.object_to_world, tri.p0);
    tri.e1 = transform_dir(inst.object_to_world, tri.e1);
    tri.e2 = transform_dir(inst.object_to_world, tri.e2);
    if ((inst.flags & INSTANCE_MIRRORED) != 0u) {
        tri.flags |= TRI_MIRRORED;
    }
    return tri;
}

