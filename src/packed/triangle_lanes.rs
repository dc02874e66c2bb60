//! The mesh triangles again, component by component (structure of arrays), for the CPU
//! walk's eight-at-a-time leaf test: eight consecutive triangles' p0.x are one unaligned
//! load, where the 48-byte `Triangle` records would need a transpose. CPU only (the kernel
//! reads `Triangle`), built on the first CPU walk that wants it.

use crate::packed::Triangle;

/// Lanes the leaf test reads at once; every array has this many zero triangles after the
/// last, so a load from any triangle index stays inside (a zero triangle is never hit:
/// its determinant is 0).
pub const TRIANGLE_LANES: usize = 8;

#[derive(Clone, Debug, Default)]
pub struct TriangleLanes {
    /// p0.x, p0.y, p0.z, e1.x, e1.y, e1.z, e2.x, e2.y, e2.z of every triangle, each
    /// component an array of `stride` floats.
    pub components: Vec<f32>,
    pub stride: usize,
}

impl TriangleLanes {
    pub fn new(triangles: &[Triangle]) -> TriangleLanes {
        let stride = triangles.len() + TRIANGLE_LANES;
        let mut components = vec![0.0f32; 9 * stride];
        for (i, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                components[k * stride + i] = t.p0[k];
                components[(3 + k) * stride + i] = t.e1[k];
                components[(6 + k) * stride + i] = t.e2[k];
            }
        }
        TriangleLanes { components, stride }
    }

    /// Component `c` (0–8, as in `components`) of triangles `first ..`.
    #[inline(always)]
    pub fn component(&self, c: usize, first: usize) -> &[f32] {
        &self.components[c * self.stride + first..(c + 1) * self.stride]
    }
}
