//! The CPU engine: the integrator of this folder over the film's pixels with rayon, the twin
//! of `gpu::GpuRenderer`.

use crate::film::{Film, WORDS_PER_PIXEL};
use crate::packed::PackedScene;
use crate::params::Params;
use rayon::prelude::*;

pub struct Renderer {
    scene: PackedScene,
    params: Params,
    film: Film,
}

impl Renderer {
    pub fn new(scene: PackedScene, params: Params) -> Renderer {
        let film = Film::new(params.film_width, params.film_height);
        Renderer { scene, params, film }
    }

    pub fn scene(&self) -> &PackedScene {
        &self.scene
    }

    /// Accumulates sample indices `start .. start + count` into the film, row by row in parallel.
    pub fn render_samples(&mut self, start: u32, count: u32) {
        let (scene, base) = (&self.scene, self.params);
        let width = base.film_width as usize;
        self.film.data.par_chunks_mut(width * WORDS_PER_PIXEL).enumerate().for_each(|(y, row)| {
            let mut row_film = Film { width: base.film_width, height: 1, data: row.to_vec() };
            for s in start..start + count {
                let p = Params { sample_index: s, ..base };
                for x in 0..width {
                    row_film.add_sample(x, super::render_sample(scene, &p, x as u32, y as u32));
                }
            }
            row.copy_from_slice(&row_film.data);
        });
    }

    /// Accumulates sample `sample` for film rows `y0 .. y0 + rows`.
    pub fn render_rows(&mut self, sample: u32, y0: u32, rows: u32) {
        let p = Params { sample_index: sample, ..self.params };
        let (w, h) = (p.film_width, p.film_height);
        for y in y0..(y0.saturating_add(rows)).min(h) {
            for x in 0..w {
                self.film.add_sample((y * w + x) as usize, super::render_sample(&self.scene, &p, x, y));
            }
        }
    }

    pub fn film(&self) -> &Film {
        &self.film
    }

    /// New parameters (camera, settings) and an empty film.
    pub fn reset(&mut self, params: Params) {
        self.params = params;
        self.film = Film::new(params.film_width, params.film_height);
    }

    pub fn set_film(&mut self, film: &Film) {
        self.film = film.clone();
    }

    /// A new environment for the scene; `reset` follows with the parameters made for it.
    pub fn set_environment(&mut self, environment: &crate::scene::Environment) {
        self.scene.set_environment(environment);
    }
}
