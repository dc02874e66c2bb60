//! A small deterministic generator for test inputs (not the renderer's RNG): a 64-bit LCG.

pub struct Lcg(pub u64);

impl Lcg {
    fn step(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        self.0
    }

    /// A uniform number in [0, 1) with 24 bits.
    pub fn f(&mut self) -> f32 {
        (self.step() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// 31 random bits.
    pub fn next(&mut self) -> u64 {
        self.step() >> 33
    }

    /// A uniform index below `n` (0 for n = 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    pub fn v(&mut self) -> glam::Vec3 {
        glam::Vec3::new(self.f(), self.f(), self.f())
    }
}
