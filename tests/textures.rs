//! The texture atlas: every image read at its own size, wrapped inside its own rectangle,
//! packed without overlaps, shrunk only past the budget (with a warning), and the same on
//! both engines.

mod common;

use glam::{Mat4, Vec2, Vec3, Vec4};
use veach::packed::{PackedScene, TEX_HEIGHT_SHIFT, TEX_SIZE_MASK, TEX_WIDTH_SHIFT, pack_textures_within, shelf_pack};
use veach::scene::{Camera, Material, Scene, Texture, TextureRef, Triangle, Wrap};
use veach::{Environment, Settings};

/// A small hash: texel values no packing could produce by accident.
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

fn noise_image(name: &str, width: u32, height: u32, seed: u32) -> Texture {
    let rgba = (0..width * height * 4).map(|i| hash(i ^ seed.wrapping_mul(0x9e37_79b9)) as u8).collect();
    Texture { name: name.to_string(), width, height, rgba }
}

/// glTF's bilinear read of `t` at `uv`, texel centres at (i + ½)/n, from the image itself:
/// independent of where the atlas put it.
fn bilinear(t: &Texture, wrap: [Wrap; 2], uv: Vec2) -> Vec4 {
    let fold = |i: i32, n: i32, w: Wrap| match w {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
    };
    let at = |x: i32, y: i32| {
        let (x, y) = (fold(x, t.width as i32, wrap[0]), fold(y, t.height as i32, wrap[1]));
        let k = 4 * (y as usize * t.width as usize + x as usize);
        Vec4::from_slice(&t.rgba[k..k + 4].iter().map(|&b| b as f32 / 255.0).collect::<Vec<_>>())
    };
    let p = uv * Vec2::new(t.width as f32, t.height as f32) - 0.5;
    let (p0, f) = (p.floor(), p - p.floor());
    let (x, y) = (p0.x as i32, p0.y as i32);
    let top = at(x, y) * (1.0 - f.x) + at(x + 1, y) * f.x;
    let bottom = at(x, y + 1) * (1.0 - f.x) + at(x + 1, y + 1) * f.x;
    top * (1.0 - f.y) + bottom * f.y
}

const WRAPS: [Wrap; 3] = [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge];

/// Images of awkward sizes (1×1, odd, thin, tall), each read by one material as a linear
/// (metallic-roughness) texture with its own pair of wrap modes.
fn scene_of(sizes: &[(u32, u32)]) -> Scene {
    let mut scene = Scene::default();
    for (i, &(w, h)) in sizes.iter().enumerate() {
        scene.textures.push(noise_image(&format!("image {i}"), w, h, i as u32 + 1));
        let r = TextureRef {
            texture: i as u32,
            uv_set: 0,
            transform: TextureRef::IDENTITY,
            wrap: [WRAPS[i % 3], WRAPS[(i / 3) % 3]],
        };
        scene.materials.push(Material {
            metallic_roughness_texture: Some(r),
            base_color_texture: Some(r),
            ..Material::default()
        });
    }
    scene
}

const AWKWARD: [(u32, u32); 9] = [(1, 1), (3, 2), (17, 5), (64, 64), (5, 300), (200, 7), (129, 130), (2, 33), (40, 1)];

#[test]
fn every_image_is_read_at_its_own_size_and_wraps_inside_its_rectangle() {
    let scene = scene_of(&AWKWARD);
    let packed = PackedScene::try_new(&scene).unwrap();
    assert!(packed.warnings.is_empty(), "{:?}", packed.warnings);
    let mut state = 12345u32;
    let mut uniform = move || {
        state = hash(state.wrapping_add(0x6d2b_79f5));
        state as f32 / u32::MAX as f32
    };
    for (i, (m, t)) in packed.materials.iter().zip(&scene.textures).enumerate() {
        let r = m.metallic_roughness_texture;
        let stored = ((r.mode >> TEX_WIDTH_SHIFT) & TEX_SIZE_MASK, (r.mode >> TEX_HEIGHT_SHIFT) & TEX_SIZE_MASK);
        assert_eq!((stored.0 + 1, stored.1 + 1), (t.width, t.height), "image {i} was resized");
        let wrap = scene.materials[i].metallic_roughness_texture.unwrap().wrap;
        // UVs well outside [0, 1]: every wrap mode folds back into this image, never a neighbour.
        for _ in 0..400 {
            let uv = Vec2::new(uniform() * 6.0 - 2.5, uniform() * 6.0 - 2.5);
            let got = veach::cpu::texture::sample_texture(&packed, &r, uv.extend(0.0).extend(0.0));
            let want = bilinear(t, wrap, uv);
            assert!((got - want).abs().max_element() < 1e-4, "image {i} ({wrap:?}) at {uv}: {got} vs {want}");
        }
    }
    // Nine images the size of the largest page before: far smaller at their own sizes.
    let old = AWKWARD.len() as u64 * 512 * 512 * 4;
    let bytes = packed.texels.len() as u64 * 4;
    assert!(bytes * 4 <= old, "{bytes} bytes, {old} with one layer per image");
}

#[test]
fn shelf_packing_keeps_images_apart_and_inside_their_pages() {
    let mut s = 7u32;
    let mut next = |n: u32| {
        s = hash(s.wrapping_add(1));
        1 + s % n
    };
    let sizes: Vec<(u32, u32)> =
        (0..300).map(|i| if i % 10 == 0 { (next(1500), next(900)) } else { (next(200), next(120)) }).collect();
    let (placements, pages) = shelf_pack(&sizes, 2048).unwrap();
    assert!(pages >= 1);
    for (i, (p, &(w, h))) in placements.iter().zip(&sizes).enumerate() {
        assert_eq!((p.width, p.height), (w, h));
        assert!(p.page < pages && p.x + w <= 2048 && p.y + h <= 2048, "image {i}: {p:?}");
        for (j, q) in placements.iter().enumerate().take(i) {
            let apart = p.page != q.page
                || p.x + p.width <= q.x
                || q.x + q.width <= p.x
                || p.y + p.height <= q.y
                || q.y + q.height <= p.y;
            assert!(apart, "images {i} and {j} overlap: {p:?} {q:?}");
        }
    }
    let area: u64 = sizes.iter().map(|&(w, h)| w as u64 * h as u64).sum();
    let pages_area = pages as u64 * 2048 * 2048;
    assert!(area * 10 > pages_area * 6, "{area} texels of images on {pages} pages");
    assert!(shelf_pack(&[(2049, 1)], 2048).is_none(), "an image wider than a page");
}

#[test]
fn textures_past_the_budget_are_halved_largest_first_with_a_warning() {
    let mut textures: Vec<Texture> = (0..4).map(|i| noise_image(&format!("big{i}"), 1024, 1024, i)).collect();
    textures.extend((0..10).map(|i| noise_image(&format!("small{i}"), 64, 48, 100 + i)));
    textures.push(noise_image("wide", 5000, 3, 999));
    let budget = 8 << 20;
    let atlas = pack_textures_within(&textures, budget);
    assert!(atlas.bytes() <= budget, "{} bytes", atlas.bytes());
    for (t, p) in textures.iter().zip(&atlas.placements) {
        let shrunk = atlas.warnings.iter().find(|w| w.contains(&format!("{:?}", t.name)));
        if t.name.starts_with("small") {
            assert_eq!((p.width, p.height), (64, 48), "{} kept its size", t.name);
            assert!(shrunk.is_none(), "{shrunk:?}");
        } else {
            assert!(p.width < t.width, "{}: {p:?}", t.name);
            let w = shrunk.unwrap_or_else(|| panic!("no warning names {}: {:?}", t.name, atlas.warnings));
            assert!(w.contains(&format!("{}x{}", p.width, p.height)), "{w}");
        }
        // Shrinking filters: the stored image keeps the original's mean colour.
        let side = atlas.side as usize;
        let mut stored = Vec4::ZERO;
        for y in 0..p.height as usize {
            for x in 0..p.width as usize {
                let k = (p.page as usize * side + p.y as usize + y) * side + p.x as usize + x;
                stored += Vec4::from(atlas.texels[k].to_le_bytes().map(|b| b as f32));
            }
        }
        stored /= (p.width * p.height) as f32;
        let mean = t.rgba.chunks(4).fold(Vec4::ZERO, |a, c| a + Vec4::from([c[0], c[1], c[2], c[3]].map(f32::from)))
            / (t.width * t.height) as f32;
        assert!((stored - mean).abs().max_element() < 3.0, "{}: mean {stored} vs {mean}", t.name);
    }
    assert_eq!(atlas.placements[4].width, 64);
    // The wide image is halved until one page (1024², 4 MiB) fits the budget, and the big
    // ones once, until all fit.
    assert_eq!((atlas.placements[14].width, atlas.placements[14].height), (1024, 1));
    assert!(atlas.placements[..4].iter().all(|p| p.width == 512), "{:?}", &atlas.placements[..4]);
}

/// Quads in a grid under an orthographic camera, each with one image of AWKWARD as its base
/// colour (sRGB), UVs from −1.5 to 2.5 so the wrap modes show: the albedo AOV.
fn atlas_albedo(ctx: Option<veach::gpu::GpuContext>) -> Vec<f32> {
    let mut scene = scene_of(&AWKWARD);
    for (i, m) in scene.materials.iter_mut().enumerate() {
        m.metallic = 1.0;
        m.roughness = 0.5;
        m.metallic_roughness_texture = None;
        let (x, y) = ((i % 3) as f32 * 0.66 - 0.99, (i / 3) as f32 * 0.66 - 0.99);
        let corner = |dx: f32, dy: f32| Vec3::new(x + dx * 0.64, y + dy * 0.64, 0.0);
        let uv = |dx: f32, dy: f32| Vec2::new(-1.5 + 4.0 * dx, -1.5 + 4.0 * (1.0 - dy));
        for tri in [[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)], [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0)]] {
            scene.triangles.push(Triangle {
                positions: tri.map(|(a, b)| corner(a, b)),
                normals: [Vec3::Z; 3],
                uvs: tri.map(|(a, b)| uv(a, b)),
                material: i as u32,
                ..Triangle::default()
            });
        }
    }
    scene.environment = Environment::constant(Vec3::ONE);
    let camera = Camera::orthographic("top".into(), Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0)), 1.0);
    let settings = Settings { width: 48, height: 48, aovs: vec![veach::aov::Aov::Albedo], ..Settings::default() };
    let mut r = common::renderer(PackedScene::try_new(&scene).unwrap(), &camera, &settings, ctx).unwrap();
    r.render_samples(0, 2).unwrap();
    r.film().unwrap().aov_image(veach::aov::Aov::Albedo).unwrap()
}

#[test]
fn atlas_albedo_shows_the_images() {
    let albedo = atlas_albedo(None);
    // Every quad shows its image: the pixel means per quad differ (no image is read twice).
    let mean_of = |i: usize| {
        let x0 = ((i % 3) as f32 * 0.66 * 24.0) as usize + 4;
        let y0 = ((2 - i / 3) as f32 * 0.66 * 24.0) as usize + 4;
        let mut m = Vec3::ZERO;
        for y in y0..y0 + 8 {
            for x in x0..x0 + 8 {
                m += Vec3::from_slice(&albedo[3 * (y * 48 + x)..]);
            }
        }
        m / 64.0
    };
    let means: Vec<Vec3> = (0..AWKWARD.len()).map(mean_of).collect();
    for i in 0..means.len() {
        for j in 0..i {
            assert!((means[i] - means[j]).abs().max_element() > 1e-3, "quads {i} and {j}: {}", means[i]);
        }
    }
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn atlas_reads_agree_across_engines_on_the_gpu() {
    let Some(ctx) = common::gpu("atlas_reads_agree_across_engines_on_the_gpu") else { return };
    let (gpu, cpu) = (atlas_albedo(Some(ctx)), atlas_albedo(None));
    let close = cpu.iter().zip(&gpu).filter(|(a, b)| (*a - *b).abs() <= 1e-4 * a.abs().max(1.0)).count();
    assert!(close as f32 >= 0.98 * cpu.len() as f32, "{close} of {} values agree", cpu.len());
}

/// A thousand 1024² images (4 GiB) in the 512 MiB budget: every one is halved once before any
/// is halved twice, and the packed pages fit.
#[test]
fn a_thousand_large_images_share_the_budget_fairly() {
    let sizes = vec![(1024u32, 1024u32); 1000];
    let budget = veach::packed::TEXTURE_BUDGET_BYTES;
    let kept = veach::packed::atlas_sizes(&sizes, budget);
    let sides: std::collections::BTreeSet<u32> = kept.iter().map(|s| s.0).collect();
    assert!(kept.iter().all(|s| s.0 == s.1 && s.0.is_power_of_two()), "{sides:?}");
    assert!(sides.len() <= 2 && *sides.last().unwrap() <= 512, "{sides:?}");
    let (_, pages) = shelf_pack(&kept, veach::packed::MAX_PAGE_SIDE).unwrap();
    assert!(pages as u64 * 4096 * 4096 * 4 <= budget, "{pages} pages");
    // Nothing is shrunk that did not have to be: the images fill more than half the budget.
    let bytes: u64 = kept.iter().map(|s| s.0 as u64 * s.1 as u64 * 4).sum();
    assert!(bytes * 2 > budget, "{bytes} bytes");
}
