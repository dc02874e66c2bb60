//! Scenes beyond a storage binding (128 MiB on lavapipe, ~2.8 M triangles) read their geometry
//! from textures instead (shaders/geometry_textures.wgsl). The paged kernel must trace exactly
//! the paths the buffer kernel traces: same film, bit for bit. `GeometryPlacement::Textures`
//! forces paging for a small scene.

mod common;

use veach::Settings;

fn render(path: &std::path::Path, ctx: veach::gpu::GpuContext) -> veach::film::Film {
    let (scene, camera) = common::load_pair(path, None).unwrap();
    let packed = veach::packed::PackedScene::new(&scene);
    let settings = Settings { width: 48, height: 48, max_depth: 6, ..Settings::default() };
    let mut r = common::renderer(packed, &camera, &settings, Some(ctx)).unwrap();
    r.render_samples(0, 4).unwrap();
    r.film().unwrap()
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn geometry_in_textures_renders_the_same_film_as_in_buffers() {
    let Some(ctx) = common::gpu("geometry_in_textures_renders_the_same_film_as_in_buffers") else { return };
    for scene in ["veach-mis.gltf", "cornell-glass.gltf"] {
        let path = common::asset(scene);
        let buffers = render(&path, ctx.clone());
        let mut paged = ctx.clone();
        paged.options.geometry = veach::gpu::GeometryPlacement::Textures;
        let textures = render(&path, paged);
        assert_eq!(buffers.samples(), textures.samples());
        for i in 0..buffers.pixel_count() {
            assert_eq!(buffers.sum(i), textures.sum(i), "{scene}: pixel {i} differs");
        }
    }
}
