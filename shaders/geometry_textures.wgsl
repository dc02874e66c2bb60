// Scene geometry paged into 2D textures of 16-byte texels (rgba32uint, 4096 texels a row):
// textures are not bound by the storage-binding limit, so a 10 M-triangle scene fits (lavapipe
// allows 16384 rows: 64 M texels, 21 M triangles). Same records as geometry_buffers.wgsl,
// texel for 16 bytes; src/gpu/mod.rs writes them.
#include "common.wgsl"

@group(0) @binding(1) var node_texels: texture_2d<u32>;
@group(0) @binding(2) var triangle_texels: texture_2d<u32>;
@group(0) @binding(3) var attribute_texels: texture_2d<u32>;

const PAGE_ROW_LOG2: u32 = 12u;

fn page_coord(i: u32) -> vec2<u32> {
    return vec2<u32>(i & ((1u << PAGE_ROW_LOG2) - 1u), i >> PAGE_ROW_LOG2);
}

fn load_node(i: u32) -> BvhNode {
    let a = textureLoad(node_texels, page_coord(2u * i), 0);
    let b = textureLoad(node_texels, page_coord(2u * i + 1u), 0);
    return BvhNode(bitcast<vec3<f32>>(a.xyz), a.w, bitcast<vec3<f32>>(b.xyz), b.w);
}

fn load_cw_node(i: u32) -> CwNode {
    let t = 6u * i;
    return CwNode(
        textureLoad(node_texels, page_coord(t), 0),
        textureLoad(node_texels, page_coord(t + 1u), 0),
        textureLoad(node_texels, page_coord(t + 2u), 0),
        textureLoad(node_texels, page_coord(t + 3u), 0),
        textureLoad(node_texels, page_coord(t + 4u), 0),
    );
}

fn load_triangle(i: u32) -> Triangle {
    let a = textureLoad(triangle_texels, page_coord(3u * i), 0);
    let b = textureLoad(triangle_texels, page_coord(3u * i + 1u), 0);
    let c = textureLoad(triangle_texels, page_coord(3u * i + 2u), 0);
    return Triangle(
        bitcast<vec3<f32>>(a.xyz), a.w, bitcast<vec3<f32>>(b.xyz), bitcast<f32>(b.w), bitcast<vec3<f32>>(c.xyz), c.w
    );
}

fn load_attributes(i: u32) -> Attributes {
    let a = textureLoad(attribute_texels, page_coord(3u * i), 0);
    let b = textureLoad(attribute_texels, page_coord(3u * i + 1u), 0);
    let c = textureLoad(attribute_texels, page_coord(3u * i + 2u), 0);
    return Attributes(a.xyz, a.w, b.xy, bitcast<vec2<f32>>(b.zw), bitcast<vec2<f32>>(c.xy), bitcast<vec2<f32>>(c.zw));
}
