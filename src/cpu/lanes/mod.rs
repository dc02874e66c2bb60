//! Paths in lanes: the CPU engine's default kernel (`cpu::Kernel::Lanes`). A packet of
//! `LANES` paths (pixels of one film row; a lane whose path ends takes the row's next pixel or
//! sample, `render_row`) keeps its state in SIMD lanes (`paths.rs`, types in `lane.rs`) and
//! goes through the integrator's stages together; on plain surfaces (`paths::plain_material`)
//! the surface, next-event and BSDF stages are arithmetic over lanes (the BSDF in `bsdf.rs`),
//! and what branches per path — the BVH walks, light selection (the tree's walks side by side,
//! `light_tree.rs`), the light sample, the shadow test — runs lane by lane. Every path draws
//! the same numbers and does the same operations in the same order as the scalar reference
//! (`integrator.rs`), so the films are the same bits (tests/lanes.rs holds the two to that).
//! On x86-64 the lanes' operations are AVX instructions: call into this module only where
//! `available()` says the CPU has AVX2 (the engine does so, and runs its reference kernel
//! elsewhere).

pub mod bsdf;
pub mod camera;
pub mod lane;
pub mod light_tree;
pub mod lights;
pub mod paths;
pub mod sampler;
pub mod trig;

use crate::aov::AovSample;
use crate::packed::PackedScene;
use crate::params::Params;
use glam::{UVec2, Vec3};
use paths::{PathQueue, Paths, trace_paths};

/// Paths in a packet.
pub const LANES: usize = 8;

/// Can this CPU run the lanes? On x86-64 their operations are AVX instructions (`lane`), so
/// only with AVX2 (checked at run time, a cached load); the CPU engine runs its reference
/// kernel elsewhere, which renders the same bits. Other architectures: always.
#[inline]
pub fn available() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    true
}

/// The lanes of `mask`, lowest first.
#[inline(always)]
pub fn lanes_of(mask: u32) -> impl Iterator<Item = usize> {
    let mut m = mask;
    std::iter::from_fn(move || {
        if m == 0 {
            return None;
        }
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        Some(i)
    })
}

/// Samples `samples` of the pixels `0..width` of film row `y` for which `skip` is false,
/// eight paths at a time in the lanes of one packet. Paths start in sample-major order, and a
/// lane whose path ends takes the next at once, so lanes stay busy however long their paths
/// are; a pixel's next sample waits while its last is in flight. `add(params, x, radiance,
/// aov)` receives each path's result as it ends (with the row's `params`), so each pixel's
/// samples in order (the film's sums, hence its bits, do not depend on which lane ran which
/// path).
pub fn render_row(
    scene: &PackedScene,
    params: &Params,
    samples: std::ops::Range<u32>,
    y: u32,
    width: u32,
    skip: impl Fn(u32) -> bool,
    add: impl FnMut(&Params, u32, Vec3, &AovSample),
) {
    let mut queue =
        RowQueue { params, y, width, end: samples.end, next: (samples.start, 0), running: [None; LANES], skip, add };
    queue.skip_converged();
    trace_paths(scene, params, &mut queue);
}

/// The (sample, pixel) pairs of a film row in sample-major order, handed to idle lanes.
struct RowQueue<'a, S, A> {
    params: &'a Params,
    y: u32,
    width: u32,
    end: u32,
    /// The next (sample, x) to start; sample == end when none is left.
    next: (u32, u32),
    /// The (sample, x) each lane runs.
    running: [Option<(u32, u32)>; LANES],
    skip: S,
    add: A,
}

impl<S: Fn(u32) -> bool, A: FnMut(&Params, u32, Vec3, &AovSample)> RowQueue<'_, S, A> {
    /// Moves `next` past the pixels `skip` leaves out.
    fn skip_converged(&mut self) {
        let (mut s, mut x) = self.next;
        while s < self.end && (x >= self.width || (self.skip)(x)) {
            if x >= self.width {
                (s, x) = (s + 1, 0);
            } else {
                x += 1;
            }
        }
        self.next = (s, x);
    }
}

impl<S: Fn(u32) -> bool, A: FnMut(&Params, u32, Vec3, &AovSample)> PathQueue for RowQueue<'_, S, A> {
    #[inline(always)]
    fn finished(&mut self, i: usize, paths: &Paths) {
        if let Some((_, x)) = self.running[i].take() {
            (self.add)(self.params, x, paths.radiance.lane(i), &paths.aov[i]);
        }
    }

    #[inline(always)]
    fn next(&mut self, i: usize) -> Option<(u32, UVec2)> {
        let (s, x) = self.next;
        if s >= self.end || self.running.iter().any(|r| r.is_some_and(|(_, rx)| rx == x)) {
            return None;
        }
        self.next = (s, x + 1);
        self.skip_converged();
        self.running[i] = Some((s, x));
        Some((s, UVec2::new(x + self.params.tile_x, self.y + self.params.tile_y)))
    }

    fn pending(&self) -> bool {
        self.next.0 < self.end
    }
}
