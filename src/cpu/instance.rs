//! Twin of `shaders/instance.wgsl`: instance records and moving hit data to world space.

use crate::packed::{INSTANCE_MIRRORED, Instance, PackedScene, TRI_MIRRORED, Triangle};
use glam::{Vec3, Vec4};

/// The record of instance `k` (the kernel finds it through params.instance_base, the same value).
/// Borrowed, not copied: the walk and the hit's shading read it several times per hit.
#[inline(always)]
pub fn load_instance(scene: &PackedScene, k: u32) -> &Instance {
    let base = (scene.instance_base + 4 * k) as usize;
    &bytemuck::cast_slice::<_, Instance>(&scene.nodes[base..base + 4])[0]
}

pub fn transform_point(m: &[[f32; 4]; 3], p: Vec3) -> Vec3 {
    let h = p.extend(1.0);
    Vec3::new(Vec4::from(m[0]).dot(h), Vec4::from(m[1]).dot(h), Vec4::from(m[2]).dot(h))
}

pub fn transform_dir(m: &[[f32; 4]; 3], d: Vec3) -> Vec3 {
    let r = |i: usize| Vec4::from(m[i]).truncate();
    Vec3::new(r(0).dot(d), r(1).dot(d), r(2).dot(d))
}

pub fn transform_normal(world_to_object: &[[f32; 4]; 3], n: Vec3) -> Vec3 {
    let r = |i: usize| Vec4::from(world_to_object[i]).truncate();
    n.x * r(0) + n.y * r(1) + n.z * r(2)
}

pub fn world_triangle(scene: &PackedScene, index: u32, instance: u32) -> Triangle {
    let mut tri = scene.triangles[index as usize];
    if scene.instance_count == 0 {
        return tri;
    }
    let inst = load_instance(scene, instance);
    tri.p0 = transform_point(&inst.object_to_world, tri.p0.into()).into();
    tri.e1 = transform_dir(&inst.object_to_world, tri.e1.into()).into();
    tri.e2 = transform_dir(&inst.object_to_world, tri.e2.into()).into();
    if inst.flags & INSTANCE_MIRRORED != 0 {
        tri.flags |= TRI_MIRRORED;
    }
    tri
}
