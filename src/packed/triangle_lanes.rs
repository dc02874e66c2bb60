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
    /// component an array of `stride` floats: `components.len() == 9 * stride` always
    /// (private, so `chunk`'s pointers stay inside).
    components: Vec<f32>,
    stride: usize,
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

    /// Triangles `first .. first + TRIANGLE_LANES` for the leaf test: a pointer to their
    /// first component's eight floats and the stride to the next component's (component `c`
    /// at `ptr + c * stride`, every one `TRIANGLE_LANES` floats inside the arrays), or None
    /// past the last triangle. One comparison instead of a slice's bounds checks per
    /// component (27 compares and branches per chunk: measured, BENCHMARKS.md session 35).
    #[inline(always)]
    pub fn chunk(&self, first: usize) -> Option<(*const f32, usize)> {
        (first.checked_add(TRIANGLE_LANES)? <= self.stride).then(|| (self.components[first..].as_ptr(), self.stride))
    }
}
