//! glTF mesh primitives as world-space triangles: accessors checked before they are read,
//! triangulation of every mode, normals and tangents filled in.

use super::MAX_TRIANGLES;
use crate::scene::tangents::generate_tangents;
use crate::scene::{Scene, Triangle};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

pub fn load_mesh(
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &[gltf::buffer::Data],
    default_material: u32,
    scene: &mut Scene,
) -> Result<(), String> {
    let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
    // A mirroring transform flips the winding; swap two vertices to keep the front face.
    let mirrored = Mat3::from_mat4(world).determinant() < 0.0;
    for prim in mesh.primitives() {
        use gltf::mesh::Mode;
        let mode = prim.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            continue; // points and lines have no area to render
        }
        let name = mesh.name().map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
        // Check every accessor we read against its buffer before the reader touches it.
        use gltf::accessor::Dimensions;
        let attrs = [
            ("POSITION", prim.get(&gltf::Semantic::Positions), Dimensions::Vec3),
            ("NORMAL", prim.get(&gltf::Semantic::Normals), Dimensions::Vec3),
            ("TEXCOORD_0", prim.get(&gltf::Semantic::TexCoords(0)), Dimensions::Vec2),
            ("TANGENT", prim.get(&gltf::Semantic::Tangents), Dimensions::Vec4),
            ("indices", prim.indices(), Dimensions::Scalar),
        ];
        for (what, accessor, dims) in attrs {
            if let Some(a) = accessor {
                check_accessor(&a, Some(dims), buffers)
                    .map_err(|e| format!("{name}: {what} accessor {}: {e}", a.index()))?;
            }
        }
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let Some(positions) = reader.read_positions() else {
            continue;
        };
        let positions: Vec<Vec3> = positions.map(|p| world.transform_point3(Vec3::from(p))).collect();
        let nv = positions.len();
        let normals: Option<Vec<Vec3>> = reader
            .read_normals()
            .map(|n| n.map(|n| (normal_matrix * Vec3::from(n)).normalize_or_zero()).collect())
            .filter(|n: &Vec<Vec3>| n.len() == nv);
        let uvs: Option<Vec<Vec2>> = reader
            .read_tex_coords(0)
            .map(|t| t.into_f32().map(Vec2::from).collect())
            .filter(|t: &Vec<Vec2>| t.len() == nv);
        let indices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..nv as u32).collect(),
        };
        let mut tris = triangulate(&indices, mode);
        if scene.triangles.len() + tris.len() > MAX_TRIANGLES {
            return Err(format!("more than {MAX_TRIANGLES} triangles"));
        }
        if let Some(bad) = tris.iter().flatten().find(|&&i| i as usize >= nv) {
            return Err(format!("{name}: index {bad} is out of range ({nv} vertices)"));
        }
        if mirrored {
            for t in &mut tris {
                t.swap(1, 2);
            }
        }
        let material = prim.material().index().map_or(default_material, |i| i as u32);
        // Tangent frames for what reads them: normal maps (the base's or the coat's) and anisotropy.
        let wants_tangents = scene
            .materials
            .get(material as usize)
            .is_some_and(|m| m.normal_texture.is_some() || m.clearcoat_normal_texture.is_some() || m.anisotropy > 0.0);
        // Tangents: the file's (a direction: transformed by the upper 3×3; a mirroring
        // transform flips the bitangent's handedness), else generated from UVs.
        let tangents: Option<Vec<Vec4>> = match (&uvs, wants_tangents) {
            (Some(uvs), true) => {
                let given: Option<Vec<Vec4>> = reader
                    .read_tangents()
                    .map(|t| {
                        t.map(|t| {
                            let v = (Mat3::from_mat4(world) * Vec3::new(t[0], t[1], t[2])).normalize_or_zero();
                            let w = if (t[3] < 0.0) != mirrored { -1.0 } else { 1.0 };
                            v.extend(w)
                        })
                        .collect()
                    })
                    .filter(|t: &Vec<Vec4>| t.len() == nv && t.iter().all(|v| v.is_finite()));
                Some(given.unwrap_or_else(|| {
                    let vertex_normals = normals.clone().unwrap_or_else(|| face_normals_per_vertex(&positions, &tris));
                    generate_tangents(&positions, &vertex_normals, uvs, &tris)
                }))
            }
            _ => None,
        };
        for idx in tris {
            let p = idx.map(|i| positions[i as usize]);
            if !p.iter().all(|v| v.is_finite()) {
                return Err(format!("{name}: non-finite vertex position"));
            }
            let ng = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
            let n = match &normals {
                Some(ns) => idx.map(|i| {
                    let n = ns[i as usize];
                    if n == Vec3::ZERO || !n.is_finite() { ng } else { n }
                }),
                None => [ng; 3],
            };
            let uv = match &uvs {
                Some(t) => idx.map(|i| {
                    let v = t[i as usize];
                    if v.is_finite() { v } else { Vec2::ZERO }
                }),
                None => [Vec2::ZERO; 3],
            };
            let tangents = tangents.as_ref().map_or([Vec4::ZERO; 3], |t| idx.map(|i| t[i as usize]));
            scene.triangles.push(Triangle { positions: p, normals: n, uvs: uv, tangents, material });
        }
    }
    Ok(())
}

/// An accessor's bytes lie inside its view, and its view inside its buffer; its type is one
/// veach reads.
fn check_accessor(
    a: &gltf::Accessor,
    dims: Option<gltf::accessor::Dimensions>,
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    use gltf::accessor::{DataType, Dimensions};
    if a.sparse().is_some() {
        return Err("sparse accessors are not supported".into());
    }
    if let Some(d) = dims
        && a.dimensions() != d
    {
        return Err(format!("is {:?}, expected {:?}", a.dimensions(), d));
    }
    let ok_type = match a.dimensions() {
        Dimensions::Scalar => matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32),
        // Texture coordinates may be normalised integers.
        Dimensions::Vec2 => a.data_type() == DataType::F32 || (a.normalized() && a.data_type() != DataType::U32),
        _ => a.data_type() == DataType::F32,
    };
    if !ok_type {
        return Err(format!("component type {:?} is not supported here", a.data_type()));
    }
    let view = a.view().ok_or("has no buffer view")?;
    let buffer = buffers.get(view.buffer().index()).ok_or("its buffer is missing")?;
    let view_end = (view.offset() as u64).checked_add(view.length() as u64).ok_or("view overflows")?;
    if view_end > buffer.0.len() as u64 {
        return Err(format!("its view ends at byte {view_end}, past the buffer's {} bytes", buffer.0.len()));
    }
    let elem = a.size() as u64;
    let stride = view.stride().map_or(elem, |s| s as u64);
    if stride < elem {
        return Err(format!("byte stride {stride} is smaller than an element ({elem} bytes)"));
    }
    if a.count() == 0 {
        return Ok(());
    }
    let need = (a.offset() as u64)
        .checked_add(stride.checked_mul(a.count() as u64 - 1).ok_or("count overflows")?)
        .and_then(|x| x.checked_add(elem))
        .ok_or("count overflows")?;
    if need > view.length() as u64 {
        return Err(format!("{} elements need {need} bytes, its view has {}", a.count(), view.length()));
    }
    Ok(())
}

/// Area-weighted face normals averaged per vertex (for tangent generation without NORMAL).
fn face_normals_per_vertex(positions: &[Vec3], tris: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in tris {
        let p = t.map(|i| positions[i as usize]);
        let c = (p[1] - p[0]).cross(p[2] - p[0]);
        for i in t {
            n[*i as usize] += c;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Z)).collect()
}

fn triangulate(indices: &[u32], mode: gltf::mesh::Mode) -> Vec<[u32; 3]> {
    use gltf::mesh::Mode;
    match mode {
        Mode::TriangleStrip => (2..indices.len())
            .map(|i| {
                if i % 2 == 0 {
                    [indices[i - 2], indices[i - 1], indices[i]]
                } else {
                    [indices[i - 1], indices[i - 2], indices[i]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len()).map(|i| [indices[0], indices[i - 1], indices[i]]).collect(),
        _ => indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    }
}
