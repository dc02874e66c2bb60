//! The thin-lens camera: rays through any point of the lens meet on the plane in focus, the
//! GPU and CPU agree with a lens, and an aperture alone focuses on what the centre sees.

mod common;

use common::*;
use glam::{UVec2, Vec2, Vec3};
use veach::Tile;
use veach::cpu::camera::{autofocus, generate_ray};
use veach::cpu::sampler::{SAMPLER_SOBOL, sampler_init};
use veach::packed::PackedScene;
use veach::params::Params;

fn params(aperture: f32, focus: f32) -> (PackedScene, Params) {
    let (scene, camera) = common::load_pair(&asset("cornell-box.gltf"), None).unwrap();
    let packed = PackedScene::new(&scene);
    let tile = Tile { x: 0, y: 0, width: 64, height: 48 };
    let mut p = Params::new(&camera, &veach::Settings { width: 64, height: 48, ..Default::default() }, tile, &packed);
    p.aperture = aperture;
    p.focus_distance = focus;
    (packed, p)
}

#[test]
fn lens_rays_meet_on_the_plane_in_focus() {
    let (_, pinhole) = params(0.0, 1.0);
    let (_, lens) = params(25.0, 1000.0);
    let forward = Vec3::from(pinhole.cam_forward);
    for k in 0..200u32 {
        let pixel = UVec2::new(k * 7 % 64, k * 13 % 48);
        let jitter = Vec2::new((k as f32 * 0.37).fract(), (k as f32 * 0.61).fract());
        let centre = generate_ray(&pinhole, pixel, jitter, &mut sampler_init(SAMPLER_SOBOL, 0, 0, 0));
        let r = generate_ray(&lens, pixel, jitter, &mut sampler_init(SAMPLER_SOBOL, k, 0, 0));
        assert!(r.origin.distance(centre.origin) <= 25.0 + 1e-3 && r.origin != centre.origin);
        // Both rays reach the plane at distance 1000 along the view direction at one point.
        let at = |ray: &veach::cpu::bvh::Ray| {
            ray.origin + ray.dir * ((1000.0 - (ray.origin - centre.origin).dot(forward)) / ray.dir.dot(forward))
        };
        assert!(at(&r).distance(at(&centre)) < 1e-2, "pixel {pixel}: {} vs {}", at(&r), at(&centre));
    }
}

#[test]
fn aperture_alone_focuses_on_what_the_centre_sees() {
    let (scene, p) = params(10.0, 0.0);
    let d = autofocus(&scene, &p);
    // The camera is 800 mm in front of the box, whose back wall is 559 mm deep.
    assert!((800.0..=1360.0).contains(&d), "focus distance {d}");
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn gpu_and_cpu_agree_with_a_lens() {
    let Some(ctx) = gpu("gpu_and_cpu_agree_with_a_lens") else { return };
    let mut s = settings(48, 8, 31);
    s.aperture = 30.0;
    let g = render(&asset("cornell-box.gltf"), &s, 128, Some(ctx));
    s.seed = 32;
    let c = render(&asset("cornell-box.gltf"), &s, 128, None);
    let (gm, gv) = film_stats(&g);
    let (cm, cv) = film_stats(&c);
    let a = agreement(&gm, &gv, &cm, &cv);
    eprintln!("lens gpu vs cpu: {a:?}");
    assert!(a.mean_z.abs().max_element() < 5.0 && a.mean_rel.abs().max_element() < 0.02 && a.outliers < 0.01, "{a:?}");
    // And a wide lens focused near the camera blurs the box: the light's and walls' edges.
    let mut wide = settings(48, 8, 33);
    (wide.aperture, wide.focus_distance) = (150.0, Some(850.0));
    let blurred = render(&asset("cornell-box.gltf"), &wide, 128, None);
    let pinhole = render(&asset("cornell-box.gltf"), &settings(48, 8, 34), 128, None);
    let (bm, bv) = film_stats(&blurred);
    let (pm, pv) = film_stats(&pinhole);
    let d = agreement(&bm, &bv, &pm, &pv);
    assert!(d.outliers > 0.02, "depth of field is visible: {d:?}");
}

#[test]
fn the_first_camera_is_the_file_s_first_even_unnamed() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = common::build::GltfBuilder::new(dir.path(), "two-cameras");
    b.camera(0.8, 1.0, [1.0, 0.0, 5.0]);
    b.camera(0.8, 1.0, [-1.0, 0.0, 5.0]);
    let (scene, camera) = common::load_pair(&b.write(), None).unwrap();
    assert_eq!(camera.position, Vec3::new(1.0, 0.0, 5.0), "{:?}", scene.cameras);
    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["camera0", "camera1"]);
}

/// An orthographic glTF camera (ymag 1, seen from z = 5 or z = 50) shows a lamp quad of
/// half-size 0.5 at z = 0 over exactly the middle half of the image, whatever its distance.
fn orthographic_lamp(ctx: Option<veach::gpu::GpuContext>) {
    use common::build::{GltfBuilder, MeshData};
    let engine = if ctx.is_some() { "gpu" } else { "cpu" };
    for z in [5.0f32, 50.0] {
        let dir = std::env::temp_dir().join(format!("veach-ortho-{}-{engine}-{z}", std::process::id()));
        let mut b = GltfBuilder::new(&dir, "ortho");
        let lamp = b.material(serde_json::json!({"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
            "emissiveFactor": [1, 1, 1]}));
        let quad = b.mesh(&MeshData::quad(-0.5, -0.5, 0.5, 0.5, 0.0, MeshData::UPRIGHT), lamp);
        b.node(serde_json::json!({"mesh": quad}));
        b.orthographic_camera(1.0, 1.0, [0.0, 0.0, z]);
        let path = b.write();
        let loaded = veach::load(&path, None).unwrap();
        assert_eq!(loaded.camera.ortho, Some(1.0));
        let s = veach::Settings { width: 32, height: 32, env_color: Some([0.0; 3]), ..veach::Settings::default() };
        let film = common::render(&path, &s, 4, ctx.clone());
        for y in 0..32u32 {
            for x in 0..32u32 {
                let inside = (8..24).contains(&x) && (8..24).contains(&y);
                let v = film.mean((y * 32 + x) as usize).x;
                assert!((v - if inside { 1.0 } else { 0.0 }).abs() < 1e-5, "{engine} z {z}: pixel {x},{y} = {v}");
            }
        }
    }
}

#[test]
fn orthographic_cameras_see_parallel_rays() {
    orthographic_lamp(None);
}

#[test]
#[cfg_attr(veach_no_gpu, ignore = "needs a GPU adapter (no Vulkan driver on this machine)")]
fn orthographic_cameras_see_parallel_rays_on_the_gpu() {
    let Some(ctx) = common::gpu("orthographic_cameras_see_parallel_rays_on_the_gpu") else { return };
    orthographic_lamp(Some(ctx));
}
