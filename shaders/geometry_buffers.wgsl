// Scene geometry in storage buffers (each at most max_storage_buffer_binding_size, 128 MiB on
// lavapipe: about 2.8 M triangles). The host picks geometry_textures.wgsl for larger scenes.
#include "common.wgsl"

// Nodes as 16-byte words: a BvhNode slot is two, a CwNode five (of its six).
@group(0) @binding(1) var<storage, read> nodes: array<vec4<u32>>;
@group(0) @binding(2) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(3) var<storage, read> attributes: array<Attributes>;

fn load_node(i: u32) -> BvhNode {
    let a = nodes[2u * i];
    let b = nodes[2u * i + 1u];
    return BvhNode(bitcast<vec3<f32>>(a.xyz), a.w, bitcast<vec3<f32>>(b.xyz), b.w);
}

fn load_cw_node(i: u32) -> CwNode {
    let w = 6u * i;
    return CwNode(nodes[w], nodes[w + 1u], nodes[w + 2u], nodes[w + 3u], nodes[w + 4u]);
}

fn load_triangle(i: u32) -> Triangle {
    return triangles[i];
}

fn load_attributes(i: u32) -> Attributes {
    return attributes[i];
}
