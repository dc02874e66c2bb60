//! The GLB container: its JSON and BIN chunks, bounds-checked.

/// The JSON chunk of a GLB and its BIN chunk if any, after checking the container's header
/// and chunk bounds.
pub fn glb_chunks(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let word = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| "truncated GLB".to_string())
    };
    let (version, length) = (word(4)?, word(8)? as usize);
    if version != 2 {
        return Err(format!("GLB version {version} (only 2 is glTF 2.0)"));
    }
    if length < 20 || length > bytes.len() {
        return Err(format!("GLB header says {length} bytes, the file has {}", bytes.len()));
    }
    let (chunk_len, chunk_type) = (word(12)? as usize, word(16)?);
    if chunk_type != 0x4E4F534A {
        return Err("GLB's first chunk is not JSON".into());
    }
    let end = 20usize.checked_add(chunk_len).filter(|&e| e <= length).ok_or("GLB JSON chunk runs past the file")?;
    // Chunks start at multiples of 4 bytes.
    let bin_at = end.next_multiple_of(4);
    let mut bin = None;
    if bin_at + 8 <= length {
        let (bin_len, bin_type) = (word(bin_at)? as usize, word(bin_at + 4)?);
        let bin_end = (bin_at + 8).checked_add(bin_len).filter(|&e| e <= length);
        let bin_end = bin_end.ok_or("GLB BIN chunk runs past the file")?;
        if bin_type == 0x004E4942 {
            bin = Some(&bytes[bin_at + 8..bin_end]);
        }
    }
    Ok((&bytes[20..end], bin))
}
