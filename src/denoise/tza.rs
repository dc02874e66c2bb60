//! OIDN's TZA tensor archives: the trained weights of its networks.
//!
//! Little-endian: a u16 magic 0x41D7, a u8 major version (2), a u8 minor version, a u64
//! absolute offset of the table. The table: a u32 tensor count, then per tensor a u16 name
//! length and the UTF-8 name, a u8 rank, that many u32 dimensions, as many ASCII layout
//! characters (`oihw` for convolution weights, `x` for biases), one data-type byte (`h` f16,
//! `f` f32) and the u64 absolute offset of its data, row-major in the order of the
//! dimensions. Every read is bounds-checked: a damaged file is an error, never a panic.

/// One tensor of an archive, converted to f32.
#[derive(Clone, Debug, PartialEq)]
pub struct Tensor {
    pub name: String,
    pub dims: Vec<usize>,
    pub layout: String,
    pub data: Vec<f32>,
}

const MAGIC: u16 = 0x41D7;
/// More elements than any tensor of OIDN's networks has, by far: a guard against sizes made
/// to overflow.
const MAX_ELEMENTS: usize = 1 << 28;

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| format!("truncated TZA file: {what} at byte {} runs past its end", self.at))?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }
    fn u16(&mut self, what: &str) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.take(2, what)?.try_into().map_err(|_| "u16")?))
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().map_err(|_| "u32")?))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().map_err(|_| "u64")?))
    }
}

/// Parses a whole archive.
pub fn parse(bytes: &[u8]) -> Result<Vec<Tensor>, String> {
    let mut r = Reader { bytes, at: 0 };
    if r.u16("the magic number")? != MAGIC {
        return Err("not a TZA file (bad magic number)".into());
    }
    let major = r.u8("the version")?;
    let _minor = r.u8("the version")?;
    if major != 2 {
        return Err(format!("unsupported TZA version {major} (veach reads version 2)"));
    }
    let table = r.u64("the table offset")?;
    r.at = usize::try_from(table).ok().filter(|&t| t <= bytes.len()).ok_or("TZA table offset past the file's end")?;
    let count = r.u32("the tensor count")? as usize;
    // Each entry takes at least 2 + 1 + 1 + 8 bytes: a count beyond that is a damaged file.
    if count > bytes.len() / 12 {
        return Err(format!("TZA table claims {count} tensors, more than the file can hold"));
    }
    let mut tensors = Vec::with_capacity(count);
    for _ in 0..count {
        let name_len = r.u16("a tensor name")? as usize;
        let name = std::str::from_utf8(r.take(name_len, "a tensor name")?)
            .map_err(|_| "a TZA tensor name is not UTF-8".to_string())?
            .to_string();
        let rank = r.u8("a tensor rank")? as usize;
        let mut dims = Vec::with_capacity(rank);
        for _ in 0..rank {
            dims.push(r.u32("a tensor dimension")? as usize);
        }
        let layout = std::str::from_utf8(r.take(rank, "a tensor layout")?)
            .map_err(|_| format!("tensor {name}: layout is not ASCII"))?
            .to_string();
        let dtype = r.u8("a tensor type")?;
        let offset = r.u64("a tensor offset")?;
        let elements = dims
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
            .filter(|&n| n <= MAX_ELEMENTS)
            .ok_or_else(|| format!("tensor {name}: dimensions {dims:?} are too large"))?;
        let size = match dtype {
            b'h' => 2,
            b'f' => 4,
            other => return Err(format!("tensor {name}: unsupported data type {:?}", other as char)),
        };
        let start = usize::try_from(offset).map_err(|_| format!("tensor {name}: offset out of range"))?;
        let mut data_reader = Reader { bytes, at: start };
        let raw = data_reader.take(elements * size, &format!("tensor {name}'s data"))?;
        let data = if size == 2 {
            raw.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect()
        } else {
            raw.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
        };
        tensors.push(Tensor { name, dims, layout, data });
    }
    Ok(tensors)
}

/// Writes an archive of f32 or f16 tensors (the tests' small files, and the format's
/// definition in code): data blobs at 64-byte-aligned offsets, then the table.
pub fn write(tensors: &[Tensor], f16: bool) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC.to_le_bytes());
    out.extend_from_slice(&[2, 0]);
    out.extend_from_slice(&0u64.to_le_bytes());
    let mut offsets = Vec::new();
    for t in tensors {
        out.resize(out.len().next_multiple_of(64), 0);
        offsets.push(out.len() as u64);
        for &v in &t.data {
            if f16 {
                out.extend_from_slice(&half::f16::from_f32(v).to_le_bytes());
            } else {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    let table = out.len() as u64;
    out[4..12].copy_from_slice(&table.to_le_bytes());
    out.extend_from_slice(&(tensors.len() as u32).to_le_bytes());
    for (t, offset) in tensors.iter().zip(offsets) {
        out.extend_from_slice(&(t.name.len() as u16).to_le_bytes());
        out.extend_from_slice(t.name.as_bytes());
        out.push(t.dims.len() as u8);
        for &d in &t.dims {
            out.extend_from_slice(&(d as u32).to_le_bytes());
        }
        out.extend_from_slice(t.layout.as_bytes());
        out.push(if f16 { b'h' } else { b'f' });
        out.extend_from_slice(&offset.to_le_bytes());
    }
    out
}
