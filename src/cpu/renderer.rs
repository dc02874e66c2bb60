//! The CPU engine: the integrator of this folder over the film's pixels with rayon, the twin
//! of `gpu::GpuRenderer`.

use super::lanes;
use crate::adaptive::{adaptive_add_sample, adaptive_settle, adaptive_test_due};
use crate::aov::aov_add_sample;
use crate::film::{ADAPTIVE_WORDS, AOV_WORDS, Film, WORDS_PER_PIXEL, film_add_sample};
use crate::packed::PackedScene;
use crate::params::Params;
use rayon::prelude::*;

pub struct Renderer {
    scene: PackedScene,
    params: Params,
    film: Film,
    /// Samples taken by the pixels still sampling (adaptive sampling's test schedule).
    taken: u32,
    kernel: Kernel,
}

/// How the CPU engine runs the integrator: the same films either way, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// One path at a time through `li`: the reference the GPU kernel is held to.
    Reference,
    /// Packets of eight paths with their state in SIMD lanes (`cpu::lanes`): the default, the
    /// faster one (BENCHMARKS.md, session 18).
    Lanes,
}

impl Kernel {
    /// `Lanes`, unless the environment variable VEACH_CPU_KERNEL says `reference` (for
    /// benchmarks of the two in one build).
    pub fn from_env() -> Kernel {
        match std::env::var("VEACH_CPU_KERNEL").as_deref() {
            Ok("reference") => Kernel::Reference,
            _ => Kernel::Lanes,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Kernel::Reference => "reference",
            Kernel::Lanes => "lanes",
        }
    }
}

fn empty_film(params: &Params) -> Film {
    Film::with_layout(params.film_width, params.film_height, params.film_layout())
}

/// One film row's regions: its pixels' words, and when the film has them, adaptive
/// sampling's half-buffer records and convergence flags, and the AOV records.
struct Row<'a> {
    words: &'a mut [u32],
    adaptive: Option<(&'a mut [u32], &'a [u32])>,
    aovs: Option<&'a mut [u32]>,
}

/// Samples `samples` of film row `y` (converged pixels are skipped).
fn render_row(kernel: Kernel, scene: &PackedScene, base: &Params, samples: std::ops::Range<u32>, y: usize, row: Row) {
    if kernel == Kernel::Lanes && lanes::available() {
        return render_row_lanes(scene, base, samples, y, row);
    }
    let Row { words, mut adaptive, mut aovs } = row;
    for s in samples {
        let p = Params { sample_index: s, ..*base };
        for (x, words) in words.chunks_exact_mut(WORDS_PER_PIXEL).enumerate() {
            if adaptive.as_ref().is_some_and(|(_, flags)| flags[x] != 0) {
                continue;
            }
            let (l, aov) = super::render_sample(scene, &p, x as u32, y as u32);
            film_add_sample(words, l);
            if let Some((records, _)) = &mut adaptive {
                adaptive_add_sample(&p, words, &mut records[x * ADAPTIVE_WORDS..(x + 1) * ADAPTIVE_WORDS], l);
            }
            if let Some(records) = &mut aovs {
                aov_add_sample(&mut records[x * AOV_WORDS..(x + 1) * AOV_WORDS], &aov);
            }
        }
    }
}

/// `render_row` with the row's paths in packets of `LANES` lanes (`lanes::render_row`): each
/// pixel still gets its samples in order, so its sums are the same bits.
fn render_row_lanes(scene: &PackedScene, base: &Params, samples: std::ops::Range<u32>, y: usize, row: Row) {
    let Row { words, adaptive, mut aovs } = row;
    let width = words.len() / WORDS_PER_PIXEL;
    let (mut records, flags) = match adaptive {
        Some((records, flags)) => (Some(records), Some(flags)),
        None => (None, None),
    };
    let converged = |x: u32| flags.is_some_and(|f| f[x as usize] != 0);
    lanes::render_row(scene, base, samples, y as u32, width as u32, converged, |p, x, l, aov| {
        let x = x as usize;
        let pixel = &mut words[x * WORDS_PER_PIXEL..(x + 1) * WORDS_PER_PIXEL];
        film_add_sample(pixel, l);
        if let Some(records) = &mut records {
            adaptive_add_sample(p, pixel, &mut records[x * ADAPTIVE_WORDS..(x + 1) * ADAPTIVE_WORDS], l);
        }
        if let Some(records) = &mut aovs {
            aov_add_sample(&mut records[x * AOV_WORDS..(x + 1) * AOV_WORDS], aov);
        }
    });
}

impl Renderer {
    pub fn new(scene: PackedScene, params: Params) -> Renderer {
        Renderer::with_kernel(scene, params, Kernel::from_env())
    }

    pub fn with_kernel(scene: PackedScene, params: Params, kernel: Kernel) -> Renderer {
        let film = empty_film(&params);
        Renderer { scene, params, film, taken: 0, kernel }
    }

    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    pub fn set_kernel(&mut self, kernel: Kernel) {
        self.kernel = kernel;
    }

    pub fn scene(&self) -> &PackedScene {
        &self.scene
    }

    /// Accumulates sample indices `start .. start + count` into the film, row by row in
    /// parallel, pausing at each convergence test of adaptive sampling.
    pub fn render_samples(&mut self, start: u32, count: u32) {
        let mut done = 0;
        while done < count {
            let mut n = 1;
            while done + n < count && !adaptive_test_due(&self.params, self.taken + n) {
                n += 1;
            }
            self.render_range(start + done, n, 0..self.params.film_height as usize);
            done += n;
            self.after_sample(n);
        }
    }

    /// `n` more samples taken by every pixel still sampling: settles a test when one is due.
    fn after_sample(&mut self, n: u32) {
        self.taken += n;
        if adaptive_test_due(&self.params, self.taken) {
            adaptive_settle(&mut self.film);
        }
    }

    /// Samples `start .. start + count` of film rows `rows`, rows in parallel.
    fn render_range(&mut self, start: u32, count: u32, rows: std::ops::Range<usize>) {
        let (scene, base, kernel) = (&self.scene, self.params, self.kernel);
        let width = base.film_width as usize;
        let pixels = self.film.pixel_count();
        let layout = self.film.layout;
        let (main, rest) = self.film.data.split_at_mut(pixels * WORDS_PER_PIXEL);
        let (adaptive, aovs) = rest.split_at_mut(layout.aov_base(pixels) - pixels * WORDS_PER_PIXEL);
        let (records, flags) = adaptive.split_at_mut(if layout.adaptive { pixels * ADAPTIVE_WORDS } else { 0 });
        let flags: &[u32] = flags;
        // One task a row, each with its part of every region the film has.
        let mut tasks: Vec<Row> =
            main.chunks_mut(width * WORDS_PER_PIXEL).map(|words| Row { words, adaptive: None, aovs: None }).collect();
        if layout.adaptive {
            for ((row, rec), fl) in
                tasks.iter_mut().zip(records.chunks_mut(width * ADAPTIVE_WORDS)).zip(flags.chunks(width))
            {
                row.adaptive = Some((rec, fl));
            }
        }
        if layout.aovs {
            for (row, a) in tasks.iter_mut().zip(aovs.chunks_mut(width * AOV_WORDS)) {
                row.aovs = Some(a);
            }
        }
        tasks
            .into_par_iter()
            .enumerate()
            .skip(rows.start)
            .take(rows.len())
            .for_each(|(y, row)| render_row(kernel, scene, &base, start..start + count, y, row));
    }

    /// Accumulates sample `sample` for film rows `y0 .. y0 + rows`; the last band of a sample
    /// settles a convergence test when one is due.
    pub fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) {
        let h = self.params.film_height;
        let end = y0.saturating_add(rows).min(h);
        self.render_range(sample, 1, y0.min(end) as usize..end as usize);
        if y0.saturating_add(rows) >= h {
            self.after_sample(1);
        }
    }

    pub fn film(&self) -> &Film {
        &self.film
    }

    /// New parameters (camera, settings) and an empty film.
    pub fn reset(&mut self, params: Params) {
        self.params = params;
        self.film = empty_film(&params);
        self.taken = 0;
    }

    /// Continues from `film` (resume); its layout matches the parameters.
    pub fn set_film(&mut self, film: &Film) {
        self.film = film.clone();
        self.taken = film.samples();
    }

    /// A new environment for the scene; `reset` follows with the parameters made for it.
    pub fn set_environment(&mut self, environment: &crate::scene::Environment) {
        self.scene.set_environment(environment);
    }
}
