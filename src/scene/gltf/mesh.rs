//! glTF mesh primitives as world-space triangles: accessors read through `accessor.rs` (any
//! component type, sparse, meshopt) or a Draco stream, morph targets at their default weights,
//! skins at the rest pose, triangulation of every mode, normals and tangents filled in.

use super::MAX_TRIANGLES;
use super::accessor::{Views, read_floats, read_uints};
use crate::scene::tangents::generate_tangents;
use crate::scene::{Scene, Triangle};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};

/// What mesh loading reads besides the mesh: the document (Draco's views), every buffer
/// view's bytes, and every node's world transform (skins' joints).
pub struct MeshSources<'a> {
    pub doc: &'a gltf::Document,
    pub views: &'a Views<'a>,
    pub globals: &'a [Mat4],
    /// The KHR_materials_variants variant chosen (None: the default materials).
    pub variant: Option<usize>,
}

/// A primitive's material under a variant: the mapping that lists the variant, else its own.
fn variant_material(prim: &gltf::Primitive, variant: Option<usize>) -> Option<usize> {
    let v = variant?;
    let mappings = prim.extension_value("KHR_materials_variants")?.get("mappings")?.as_array()?;
    mappings.iter().find_map(|m| {
        let listed = m.get("variants")?.as_array()?.iter().any(|x| x.as_u64() == Some(v as u64));
        if listed { m.get("material")?.as_u64().map(|i| i as usize) } else { None }
    })
}

/// A primitive's vertex data in the mesh's own space: morph targets applied (at the node's
/// or the mesh's default weights), from its accessors or its Draco stream.
struct Vertices {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    uvs1: Option<Vec<Vec2>>,
    colors: Option<Vec<Vec4>>,
    tangents: Option<Vec<Vec4>>,
    indices: Vec<u32>,
    /// Per vertex, up to eight (joint, weight) influences (JOINTS_0/1, WEIGHTS_0/1).
    skin: Option<Vec<[(u32, f32); 8]>>,
}

fn rows<const N: usize>(flat: Vec<f32>) -> Vec<[f32; N]> {
    flat.chunks_exact(N).map(|c| std::array::from_fn(|i| c[i])).collect()
}

fn read_vertices(
    prim: &gltf::Primitive,
    src: &MeshSources,
    weights: Option<&[f32]>,
    name: &str,
) -> Result<Option<Vertices>, String> {
    use gltf::Semantic;
    let draco = super::draco::decode_primitive(prim, src.doc, src.views).map_err(|e| format!("{name}: {e}"))?;
    let attr = |semantic: Semantic, comps: usize| -> Result<Option<Vec<f32>>, String> {
        let key = semantic.to_string();
        if let Some(values) = draco.as_ref().and_then(|d| d.attributes.get(&key)) {
            return Ok(Some(values.clone()));
        }
        match prim.get(&semantic) {
            Some(a) => read_floats(&a, src.views, comps)
                .map(Some)
                .map_err(|e| format!("{name}: {key} accessor {}: {e}", a.index())),
            None => Ok(None),
        }
    };
    let Some(positions) = attr(Semantic::Positions, 3)? else {
        return Ok(None);
    };
    let mut positions: Vec<Vec3> = rows::<3>(positions).into_iter().map(Vec3::from).collect();
    let nv = positions.len();
    let same = |v: &Vec<f32>, comps: usize| v.len() == nv * comps;
    let mut normals: Option<Vec<Vec3>> =
        attr(Semantic::Normals, 3)?.filter(|v| same(v, 3)).map(|v| rows::<3>(v).into_iter().map(Vec3::from).collect());
    let uvs: Option<Vec<Vec2>> = attr(Semantic::TexCoords(0), 2)?
        .filter(|v| same(v, 2))
        .map(|v| rows::<2>(v).into_iter().map(Vec2::from).collect());
    let uvs1: Option<Vec<Vec2>> = attr(Semantic::TexCoords(1), 2)?
        .filter(|v| same(v, 2))
        .map(|v| rows::<2>(v).into_iter().map(Vec2::from).collect());
    // COLOR_0: RGB or RGBA, floats or normalised integers.
    let colors: Option<Vec<Vec4>> = match prim.get(&Semantic::Colors(0)).map(|a| a.dimensions().multiplicity()) {
        Some(4) => attr(Semantic::Colors(0), 4)?
            .filter(|v| same(v, 4))
            .map(|v| rows::<4>(v).into_iter().map(Vec4::from).collect()),
        Some(3) => attr(Semantic::Colors(0), 3)?
            .filter(|v| same(v, 3))
            .map(|v| rows::<3>(v).into_iter().map(|c| Vec3::from(c).extend(1.0)).collect()),
        _ => None,
    };
    let mut tangents: Option<Vec<Vec4>> =
        attr(Semantic::Tangents, 4)?.filter(|v| same(v, 4)).map(|v| rows::<4>(v).into_iter().map(Vec4::from).collect());
    let indices: Vec<u32> = match (&draco, prim.indices()) {
        (Some(d), _) => d.indices.clone(),
        (None, Some(a)) => {
            read_uints(&a, src.views, 1).map_err(|e| format!("{name}: indices accessor {}: {e}", a.index()))?
        }
        (None, None) => (0..nv as u32).collect(),
    };
    // Morph targets at the default weights: displacements added before skinning.
    for (k, target) in prim.morph_targets().enumerate() {
        let w = weights.and_then(|w| w.get(k)).copied().unwrap_or(0.0);
        if w == 0.0 || !w.is_finite() {
            continue;
        }
        let delta = |a: Option<gltf::Accessor>| -> Result<Option<Vec<Vec3>>, String> {
            let Some(a) = a else { return Ok(None) };
            let v = read_floats(&a, src.views, 3)
                .map_err(|e| format!("{name}: morph target {k} accessor {}: {e}", a.index()))?;
            Ok(same(&v, 3).then(|| rows::<3>(v).into_iter().map(Vec3::from).collect()))
        };
        if let Some(d) = delta(target.positions())? {
            positions.iter_mut().zip(&d).for_each(|(p, d)| *p += w * *d);
        }
        if let (Some(n), Some(d)) = (&mut normals, delta(target.normals())?) {
            n.iter_mut().zip(&d).for_each(|(n, d)| *n += w * *d);
        }
        if let (Some(t), Some(d)) = (&mut tangents, delta(target.tangents())?) {
            t.iter_mut().zip(&d).for_each(|(t, d)| *t += (w * *d).extend(0.0));
        }
    }
    // Skin influences: JOINTS_n (unsigned integers) with WEIGHTS_n.
    let mut skin: Option<Vec<[(u32, f32); 8]>> = None;
    for set in 0..2u32 {
        let joints = match prim.get(&Semantic::Joints(set)) {
            Some(a) => {
                read_uints(&a, src.views, 4).map_err(|e| format!("{name}: JOINTS_{set} accessor {}: {e}", a.index()))?
            }
            None => continue,
        };
        let Some(w) = attr(Semantic::Weights(set), 4)? else { continue };
        if joints.len() != nv * 4 || w.len() != nv * 4 {
            return Err(format!("{name}: JOINTS_{set}/WEIGHTS_{set} do not have one entry a vertex"));
        }
        let s = skin.get_or_insert_with(|| vec![[(0, 0.0); 8]; nv]);
        for (v, influences) in s.iter_mut().enumerate() {
            for c in 0..4 {
                influences[set as usize * 4 + c] = (joints[v * 4 + c], w[v * 4 + c]);
            }
        }
    }
    Ok(Some(Vertices { positions, normals, uvs, uvs1, colors, tangents, indices, skin }))
}

/// The joint matrices of a skin (each joint's world transform times its inverse bind
/// matrix), indexed as JOINTS_n index them.
fn joint_matrices(skin: &gltf::Skin, src: &MeshSources) -> Result<Vec<Mat4>, String> {
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    let inverse_bind: Vec<Mat4> = match skin.inverse_bind_matrices() {
        Some(a) => rows::<16>(
            read_floats(&a, src.views, 16).map_err(|e| format!("skin {}: inverse bind matrices: {e}", skin.index()))?,
        )
        .into_iter()
        .map(|m| Mat4::from_cols_array(&m))
        .collect(),
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    if inverse_bind.len() < joints.len() {
        return Err(format!(
            "skin {}: {} inverse bind matrices for {} joints",
            skin.index(),
            inverse_bind.len(),
            joints.len()
        ));
    }
    joints
        .iter()
        .zip(inverse_bind)
        .map(|(&j, ibm)| {
            let world = src
                .globals
                .get(j)
                .copied()
                .ok_or_else(|| format!("skin {}: joint node {j} is missing", skin.index()))?;
            Ok(world * ibm)
        })
        .collect()
}

/// Loads a node's mesh as world-space triangles: the node's transform `world`, or for a
/// skinned mesh its skin's joints at the rest pose (the node's own transform is then ignored,
/// as glTF specifies); morph targets at the default weights.
pub fn load_mesh(
    mesh: &gltf::Mesh,
    world: Mat4,
    node: Option<&gltf::Node>,
    src: &MeshSources,
    default_material: u32,
    scene: &mut Scene,
) -> Result<(), String> {
    let weights = node.and_then(|n| n.weights()).or_else(|| mesh.weights());
    let joints = match node.and_then(|n| n.skin()) {
        Some(skin) => Some(joint_matrices(&skin, src)?),
        None => None,
    };
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
        let Some(v) = read_vertices(&prim, src, weights, &name)? else {
            continue;
        };
        let nv = v.positions.len();
        // Per vertex: the transform of its point (the node's, or its skin's blend of joints).
        let skinned: Option<Vec<Mat4>> = match (&joints, &v.skin) {
            (Some(joints), Some(influences)) => Some(
                influences
                    .iter()
                    .map(|inf| {
                        let mut m = Mat4::ZERO;
                        for &(j, w) in inf {
                            if w != 0.0 {
                                let jm = joints
                                    .get(j as usize)
                                    .ok_or_else(|| format!("{name}: joint {j} is out of range"))?;
                                m += *jm * w;
                            }
                        }
                        Ok(m)
                    })
                    .collect::<Result<_, String>>()?,
            ),
            _ => None,
        };
        let point_to_world = |i: usize| skinned.as_ref().map_or(world, |m| m[i]);
        let positions: Vec<Vec3> = (0..nv).map(|i| point_to_world(i).transform_point3(v.positions[i])).collect();
        let normals: Option<Vec<Vec3>> = v.normals.as_ref().map(|ns| {
            ns.iter()
                .enumerate()
                .map(|(i, n)| {
                    let m = match &skinned {
                        Some(ms) => Mat3::from_mat4(ms[i]).inverse().transpose(),
                        None => normal_matrix,
                    };
                    (m * *n).normalize_or_zero()
                })
                .collect()
        });
        let uvs = v.uvs;
        let (uvs1, colors) = (v.uvs1, v.colors);
        let mut tris = triangulate(&v.indices, mode);
        if scene.triangles.len() + tris.len() > MAX_TRIANGLES {
            return Err(format!("more than {MAX_TRIANGLES} triangles"));
        }
        if let Some(bad) = tris.iter().flatten().find(|&&i| i as usize >= nv) {
            return Err(format!("{name}: index {bad} is out of range ({nv} vertices)"));
        }
        for t in &mut tris {
            let m = point_to_world(t[0] as usize);
            if (skinned.is_some() && Mat3::from_mat4(m).determinant() < 0.0) || (skinned.is_none() && mirrored) {
                t.swap(1, 2);
            }
        }
        let material = variant_material(&prim, src.variant)
            .filter(|&i| i < src.doc.materials().len())
            .or_else(|| prim.material().index())
            .map_or(default_material, |i| i as u32);
        // Tangent frames for what reads them: normal maps (the base's or the coat's) and anisotropy.
        let wants_tangents = scene
            .materials
            .get(material as usize)
            .is_some_and(|m| m.normal_texture.is_some() || m.clearcoat_normal_texture.is_some() || m.anisotropy > 0.0);
        // Tangents: the file's (a direction: transformed by the upper 3×3; a mirroring
        // transform flips the bitangent's handedness), else generated from UVs.
        let tangents: Option<Vec<Vec4>> = match (&uvs, wants_tangents) {
            (Some(uvs), true) => {
                let given: Option<Vec<Vec4>> = v
                    .tangents
                    .as_ref()
                    .map(|ts| {
                        ts.iter()
                            .enumerate()
                            .map(|(i, t)| {
                                let m = Mat3::from_mat4(point_to_world(i));
                                let d = (m * t.truncate()).normalize_or_zero();
                                let w = if (t.w < 0.0) != (m.determinant() < 0.0) { -1.0 } else { 1.0 };
                                d.extend(w)
                            })
                            .collect()
                    })
                    .filter(|t: &Vec<Vec4>| t.iter().all(|v| v.is_finite()));
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
            let finite2 = |v: Vec2| if v.is_finite() { v } else { Vec2::ZERO };
            let uvs1 = uvs1.as_ref().map(|t| idx.map(|i| finite2(t[i as usize])));
            let colors = colors.as_ref().map(|c| {
                idx.map(|i| {
                    let c = c[i as usize];
                    if c.is_finite() { c.clamp(Vec4::ZERO, Vec4::ONE) } else { Vec4::ONE }
                })
            });
            scene.triangles.push(Triangle { positions: p, normals: n, uvs: uv, tangents, material, colors, uvs1 });
        }
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
