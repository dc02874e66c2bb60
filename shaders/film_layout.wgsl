// The film's layout (src/film.rs), in one place for every pass that reads films: the
// integrator's accumulation (film.wgsl, adaptive.wgsl, aov.wgsl) and the display.

// vec4<u32> rows a pixel: (Σ L high words, count), (Σ L low words, dropped), (Σ L², 0).
const FILM_WORDS: u32 = 3u;
// Largest radiance one sample may add (the largest f32 below 2^31).
const MAX_SAMPLE: f32 = 2147483520.0;
// Words a pixel of adaptive sampling's half buffer (src/adaptive.rs).
const ADAPTIVE_WORDS: u32 = 4u;
// vec4<u32> rows a pixel of the AOV region, from params.aov_base (src/aov.rs).
const AOV_ROWS: u32 = 4u;
