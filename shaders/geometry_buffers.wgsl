// Scene geometry in storage buffers (each at most max_storage_buffer_binding_size, 128 MiB on
// lavapipe: about 2.8 M triangles). The host picks geometry_textures.wgsl for larger scenes.
#include "common.wgsl"

@group(0) @binding(1) var<storage, read> nodes: array<BvhNode>;
@group(0) @binding(2) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(3) var<storage, read> attributes: array<Attributes>;

fn load_node(i: u32) -> BvhNode {
    return nodes[i];
}

fn load_triangle(i: u32) -> Triangle {
    return triangles[i];
}

fn load_attributes(i: u32) -> Attributes {
    return attributes[i];
}
