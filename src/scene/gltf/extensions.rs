//! glTF extensions: which ones veach reads, and the error or warnings for the rest.

/// Extensions veach reads (or can safely ignore) when a file requires them.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_materials_specular",
    "KHR_materials_ior",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_lights_punctual",
    "KHR_materials_unlit",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_anisotropy",
    "KHR_materials_iridescence",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
    "KHR_draco_mesh_compression",
    "EXT_texture_webp",
    "KHR_texture_basisu",
    "KHR_materials_variants",
    "EXT_mesh_gpu_instancing",
];

/// Extensions veach knows and ignores for now; files that merely use them render, with one
/// warning each.
const KNOWN_UNIMPLEMENTED: &[&str] = &[];

/// Required extensions veach cannot honour are an error naming them; used ones it does not
/// know get one warning each.
pub fn check_extensions(raw: &serde_json::Value, warnings: &mut Vec<String>) -> Result<(), String> {
    let list = |key: &str| -> Vec<String> {
        raw.get(key)
            .and_then(|v| v.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_str().map(str::to_string)).collect())
            .unwrap_or_default()
    };
    let missing: Vec<String> =
        list("extensionsRequired").into_iter().filter(|e| !SUPPORTED_EXTENSIONS.contains(&e.as_str())).collect();
    if !missing.is_empty() {
        return Err(format!("requires glTF extensions veach does not support: {}", missing.join(", ")));
    }
    for e in list("extensionsUsed") {
        if !SUPPORTED_EXTENSIONS.contains(&e.as_str()) {
            let what = if KNOWN_UNIMPLEMENTED.contains(&e.as_str()) { "not implemented yet" } else { "unknown" };
            warnings.push(format!("extension {e} is {what}; ignoring it"));
        }
    }
    Ok(())
}
