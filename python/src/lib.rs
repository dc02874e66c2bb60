//! `veach._veach`: the Python extension over the lean library. `python/veach/__init__.py` is
//! the public API (argument conversion, the progress bar); this module loads, renders,
//! denoises, merges and converts films to NumPy arrays, with the GIL released while it works.

use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::exceptions::{PyException, PyFileNotFoundError, PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::{Duration, Instant};
use veach::{Backend, Budget, Control, Film, Job, Settings};

pyo3::create_exception!(
    veach,
    Error,
    PyException,
    "A scene, image or device veach cannot use (the CLI's one-line message)."
);
pyo3::create_exception!(
    veach,
    Interrupted,
    PyKeyboardInterrupt,
    "Ctrl-C stopped a render; `.image` holds what it computed."
);

/// veach's errors as Python's: a missing file is `FileNotFoundError`, a bad setting
/// `ValueError`, the rest (malformed files, devices, limits) `veach.Error`; the message is
/// the command line's line.
fn py_err(e: veach::Error) -> PyErr {
    match &e {
        veach::Error::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(e.to_string())
        }
        _ => Error::new_err(e.to_string()),
    }
}

fn value_err(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A missing input file, named as the CLI names it.
fn must_exist(path: &Path) -> PyResult<()> {
    if path.exists() { Ok(()) } else { Err(PyFileNotFoundError::new_err(format!("{}: no such file", path.display()))) }
}

/// A serde enum (kebab-case names, as the CLI spells them) from a Python string.
fn parse_name<T: serde::de::DeserializeOwned>(what: &str, name: &str, choices: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(name.to_string()))
        .map_err(|_| value_err(format!("unknown {what} '{name}' (use {choices})")))
}

fn parse_backend(name: &str) -> PyResult<Backend> {
    match name {
        "auto" => Ok(Backend::Auto),
        "gpu" => Ok(Backend::Gpu),
        "cpu" => Ok(Backend::Cpu),
        _ => Err(value_err(format!("unknown backend '{name}' (use auto, gpu or cpu)"))),
    }
}

fn parse_tonemap(name: &str) -> PyResult<veach::tonemap::Tonemap> {
    use veach::tonemap::Tonemap;
    match name {
        "clamp" => Ok(Tonemap::Clamp),
        "aces" => Ok(Tonemap::Aces),
        "agx" => Ok(Tonemap::Agx),
        "neutral" => Ok(Tonemap::Neutral),
        _ => Err(value_err(format!("unknown tonemap '{name}' (use clamp, aces, agx or neutral)"))),
    }
}

/// A loaded glTF scene: the chosen scene, camera and variant of a file.
#[pyclass(module = "veach")]
struct Scene {
    path: PathBuf,
    scene: Option<usize>,
    camera: Option<String>,
    variant: Option<String>,
    loaded: veach::Loaded,
    description: veach::scene::gltf::Description,
}

#[pymethods]
impl Scene {
    /// What `veach info` says of the scene, as a dict.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &serde_json::to_value(&self.description).map_err(value_err)?)
    }

    /// What the loader ignored, one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.warnings.clone()
    }

    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    fn __repr__(&self) -> String {
        format!("<veach.Scene {}: {} triangles>", self.path.display(), self.description.triangles)
    }

    fn __str__(&self) -> String {
        self.description.to_string()
    }
}

/// Python objects from JSON (Python's own `json` module, so dicts and lists are plain ones).
fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (v.to_string(),))
}

#[pyfunction]
#[pyo3(signature = (path, scene=None, camera=None, variant=None))]
fn load(
    py: Python<'_>,
    path: PathBuf,
    scene: Option<usize>,
    camera: Option<String>,
    variant: Option<String>,
) -> PyResult<Scene> {
    must_exist(&path)?;
    let path = std::fs::canonicalize(&path).unwrap_or(path);
    py.detach(|| {
        let options = veach::LoadOptions { camera: camera.as_deref(), scene, variant: variant.as_deref() };
        let loaded = veach::load_with(&path, &options)?;
        let choice = veach::scene::gltf::Choice { scene, variant: variant.clone() };
        let description = veach::scene::gltf::describe_scene(&path, &choice, camera.as_deref())?;
        Ok(Scene { path: path.clone(), scene, camera: camera.clone(), variant: variant.clone(), loaded, description })
    })
    .map_err(py_err)
}

/// A rendered (or read, merged, denoised) image: the film with its job, and the denoised
/// colour when there is one.
#[pyclass(module = "veach")]
struct Image {
    film: Film,
    job: Option<Job>,
    denoised: Option<Vec<f32>>,
    stats: serde_json::Value,
    rgb: OnceLock<Py<PyAny>>,
}

impl Image {
    fn new(film: Film, job: Option<Job>, denoised: Option<Vec<f32>>, stats: serde_json::Value) -> Image {
        Image { film, job, denoised, stats, rgb: OnceLock::new() }
    }

    /// A row-major image of `channels` floats a pixel as a (H, W, C) array, or (H, W) for one
    /// channel; the vector's memory becomes the array's (no copy).
    fn array<'py>(&self, py: Python<'py>, values: Vec<f32>, channels: usize) -> PyResult<Bound<'py, PyAny>> {
        let (w, h) = (self.film.width as usize, self.film.height as usize);
        let flat = values.into_pyarray(py);
        Ok(if channels == 1 { flat.reshape([h, w])?.into_any() } else { flat.reshape([h, w, channels])?.into_any() })
    }

    /// The image shown and saved as PNG: denoised when denoised, else the film's mean.
    fn display_rgb(&self) -> Vec<f32> {
        self.denoised.clone().unwrap_or_else(|| self.film.to_rgb32f())
    }
}

#[pymethods]
impl Image {
    /// Linear radiance, float32, shape (H, W, 3): the denoised image when the render was
    /// denoised, else the mean of the samples. The same array on every access.
    #[getter]
    fn rgb(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        if let Some(a) = self.rgb.get() {
            return Ok(a.clone_ref(py));
        }
        let a = self.array(py, self.display_rgb(), 3)?.unbind();
        Ok(self.rgb.get_or_init(|| a).clone_ref(py))
    }

    /// The mean of the samples (before denoising), float32 (H, W, 3).
    #[getter]
    fn noisy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.array(py, self.film.to_rgb32f(), 3)
    }

    /// An AOV: "albedo" and "normal" (H, W, 3), "depth" (H, W); "variance" (the variance of
    /// each pixel's mean, (H, W, 3)) and "spp" (samples per pixel, (H, W)) of every render.
    fn aov<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        match name {
            "variance" => return self.array(py, self.film.variance(), 3),
            "spp" => {
                let counts: Vec<f32> = self.film.counts().into_iter().map(|c| c as f32).collect();
                return self.array(py, counts, 1);
            }
            _ => {}
        }
        let aov: veach::aov::Aov = parse_name("AOV", name, "albedo, normal, depth, variance or spp")?;
        match self.film.aov_image(aov) {
            Some(v) => self.array(py, v, if aov == veach::aov::Aov::Depth { 1 } else { 3 }),
            None => Err(value_err(format!("the render has no AOVs: render with aovs=(\"{name}\",)"))),
        }
    }

    /// What `veach render --stats-json` writes of this render, as a dict.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.stats)
    }

    #[getter]
    fn width(&self) -> u32 {
        self.film.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.film.height
    }

    /// Samples per pixel (the most any pixel took, with adaptive sampling).
    #[getter]
    fn spp(&self) -> u32 {
        self.film.samples()
    }

    #[getter]
    fn denoised(&self) -> bool {
        self.denoised.is_some()
    }

    /// Writes the image as the CLI does: PNG (exposed, tone-mapped, sRGB; the denoised image
    /// when there is one) or EXR (linear, with the film and the job so it resumes and merges,
    /// and a `denoised` layer); atomically.
    #[pyo3(signature = (path, exposure=0.0, tonemap="clamp"))]
    fn save(&self, py: Python<'_>, path: PathBuf, exposure: f32, tonemap: &str) -> PyResult<()> {
        let operator = parse_tonemap(tonemap)?;
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("png" | "exr")) {
            return Err(value_err(format!("{}: unknown output format (use a .png or .exr extension)", path.display())));
        }
        py.detach(|| match &self.denoised {
            Some(d) => veach::output::write_denoised(&self.film, d, &path, exposure, operator, self.job.as_ref()),
            None => veach::output::write_with(&self.film, &path, exposure, operator, self.job.as_ref()),
        })
        .map_err(py_err)
    }

    /// The PNG a notebook shows.
    fn _repr_png_<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let rgb = self.display_rgb();
        let pixel = |i: usize| glam::Vec3::from_slice(&rgb[3 * i..3 * i + 3]);
        let img = veach::output::tonemap_pixels(
            self.film.width,
            self.film.height,
            pixel,
            0.0,
            veach::tonemap::Tonemap::Clamp,
        );
        let mut bytes = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).map_err(value_err)?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn __repr__(&self) -> String {
        format!(
            "<veach.Image {}x{}, {} spp{}>",
            self.film.width,
            self.film.height,
            self.film.samples(),
            if self.denoised.is_some() { ", denoised" } else { "" }
        )
    }
}

/// Renders `scene`; the Python wrapper documents the arguments.
#[pyfunction]
#[pyo3(signature = (
    scene, width, height, spp, max_depth, seed, backend, time, noise_threshold, min_samples,
    strategy, sampler, light_sampler, aovs, denoise, denoise_quality, env_map, env_color,
    env_strength, clamp_direct, clamp_indirect, aperture, focus_distance, progress
))]
#[allow(clippy::too_many_arguments)]
fn render(
    py: Python<'_>,
    scene: PyRef<'_, Scene>,
    width: u32,
    height: u32,
    spp: u32,
    max_depth: u32,
    seed: u32,
    backend: &str,
    time: Option<f64>,
    noise_threshold: Option<f32>,
    min_samples: Option<u32>,
    strategy: Option<String>,
    sampler: Option<String>,
    light_sampler: Option<String>,
    aovs: Vec<String>,
    denoise: bool,
    denoise_quality: &str,
    env_map: Option<PathBuf>,
    env_color: Option<[f32; 3]>,
    env_strength: f32,
    clamp_direct: Option<f32>,
    clamp_indirect: Option<f32>,
    aperture: f32,
    focus_distance: Option<f32>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Py<Image>> {
    let t0 = Instant::now();
    let mut settings = Settings {
        width,
        height,
        max_depth,
        seed,
        camera: scene.camera.clone(),
        scene: scene.scene,
        variant: scene.variant.clone(),
        env_color,
        env_strength,
        clamp_direct,
        clamp_indirect,
        aperture,
        focus_distance,
        noise_threshold,
        min_samples,
        ..Settings::default()
    };
    if let Some(m) = env_map {
        must_exist(&m)?;
        settings.env_map = Some(std::fs::canonicalize(&m).unwrap_or(m));
    }
    if let Some(n) = &strategy {
        settings.strategy = parse_name("strategy", n, "bsdf, light, mis-balance or mis-power")?;
    }
    if let Some(n) = &sampler {
        settings.sampler = parse_name("sampler", n, "sobol or independent")?;
    }
    if let Some(n) = &light_sampler {
        settings.light_sampler = parse_name("light sampler", n, "tree, ris or power")?;
    }
    for a in &aovs {
        settings.aovs.push(parse_name("AOV", a, "albedo, normal or depth")?);
    }
    let quality: veach::denoise::Quality = denoise_quality.parse().map_err(value_err)?;
    // The denoiser reads the albedo and the normal.
    if denoise {
        settings.aovs.extend([veach::aov::Aov::Albedo, veach::aov::Aov::Normal]);
    }
    settings.aovs.sort();
    settings.aovs.dedup();
    if spp == 0 {
        return Err(value_err("spp must be at least 1"));
    }
    if let Some(t) = time
        && !(t.is_finite() && t > 0.0)
    {
        return Err(value_err(format!("time {t}: expected a finite number of seconds > 0")));
    }
    settings.validate().map_err(value_err)?;
    let backend = parse_backend(backend)?;
    let job = Job { scene: scene.path.clone(), settings: settings.clone(), sample_start: 0, sample_end: spp };
    let loaded = &scene.loaded;
    // Ctrl-C (or the progress callback's exception) stops the loop after the chunk in flight.
    let mut stopped: Option<PyErr> = None;
    let result = py.detach(|| -> Result<(Film, Option<Vec<f32>>, serde_json::Value), veach::Error> {
        let packed = veach::PackedScene::new(&loaded.scene);
        let triangles = loaded.scene.triangles.len();
        let (bvh_nodes, bvh_depth) = (packed.bvh_nodes, packed.bvh_depth);
        let (mut renderer, reason) = match backend {
            Backend::Auto => {
                let (r, why) = veach::Renderer::auto(packed, &loaded.camera, &settings)?;
                (r, format!("auto: {why}"))
            }
            b => (veach::Renderer::new(packed, &loaded.camera, &settings, b)?, "requested".to_string()),
        };
        let budget = Budget { time: time.map(Duration::from_secs_f64), cancel: None, stop_at_powers_of_two: false };
        let p = veach::render_progressive(&mut renderer, 0, 0, spp, budget, &mut |_, p| {
            let answer = Python::attach(|py| -> PyResult<()> {
                py.check_signals()?;
                if let Some(f) = &progress {
                    f.call1(py, (p.done, p.total, p.seconds))?;
                }
                Ok(())
            });
            match answer {
                Ok(()) => Ok(Control::Continue),
                Err(e) => {
                    stopped = Some(e);
                    Ok(Control::Stop)
                }
            }
        })?;
        let film = renderer.film()?;
        let mut denoise_seconds = None;
        let denoised = if denoise && stopped.is_none() {
            let start = Instant::now();
            let engine = match renderer.gpu() {
                Some(g) => veach::denoise::Engine::Gpu(g.context()),
                None => veach::denoise::Engine::Cpu,
            };
            let options = veach::denoise::Options { quality, ..Default::default() };
            let d = veach::denoise::denoise_film(&film, &options, engine)?;
            denoise_seconds = Some(start.elapsed().as_secs_f64());
            Some(d)
        } else {
            None
        };
        let window = settings.window();
        let pixels = window.width as f64 * window.height as f64;
        let rendered = if film.is_adaptive() { film.mean_spp() * pixels } else { p.done as f64 * pixels };
        let mut stats = veach::render_stats(&job, &film, &renderer, &p, p.stopped_by(stopped.is_some()));
        let more = serde_json::json!({
            "interrupted": stopped.is_some(),
            "time_budget": time,
            "backend_reason": reason,
            "seconds_total": t0.elapsed().as_secs_f64(),
            "samples_per_second": rendered / p.seconds.max(1e-9),
            "triangles": triangles,
            "bvh_nodes": bvh_nodes,
            "bvh_depth": bvh_depth,
            "denoise_quality": denoise.then(|| quality.name()),
            "denoise_seconds": denoise_seconds,
        });
        veach::extend_stats(&mut stats, more);
        Ok((film, denoised, stats))
    });
    let (film, denoised, stats) = result.map_err(py_err)?;
    let image = Py::new(py, Image::new(film, Some(job), denoised, stats))?;
    match stopped {
        None => Ok(image),
        Some(e) if e.is_instance_of::<PyKeyboardInterrupt>(py) => {
            let err = Interrupted::new_err("the render was interrupted; `.image` holds what it computed");
            err.value(py).setattr("image", image)?;
            Err(err)
        }
        Some(e) => Err(e),
    }
}

/// A veach EXR (a render, checkpoint or part) with its film and job.
#[pyfunction]
fn read(py: Python<'_>, path: PathBuf) -> PyResult<Image> {
    must_exist(&path)?;
    let (film, job) = py.detach(|| veach::output::read_film(&path)).map_err(py_err)?;
    let stats = serde_json::json!({"scene": job.scene.display().to_string(), "spp": film.samples(),
        "sample_start": job.sample_start, "width": film.width, "height": film.height});
    Ok(Image::new(film, Some(job), None, stats))
}

/// Any RGB EXR (a reference from another renderer, say) as linear float32 (H, W, 3).
#[pyfunction]
fn read_rgb<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    must_exist(&path)?;
    let (w, h, rgb) = py.detach(|| veach::output::read_exr(&path)).map_err(py_err)?;
    Ok(rgb.into_pyarray(py).reshape([h as usize, w as usize, 3])?.into_any())
}

/// Farm parts (veach EXRs of disjoint sample ranges or tiles of one job) merged exactly.
#[pyfunction]
fn merge(py: Python<'_>, paths: Vec<PathBuf>) -> PyResult<Image> {
    if paths.is_empty() {
        return Err(value_err("merge needs at least one part"));
    }
    for p in &paths {
        must_exist(p)?;
    }
    let (film, job) = py
        .detach(|| {
            let mut parts = Vec::new();
            for path in &paths {
                let (film, job) = veach::output::read_film(path)?;
                parts.push(veach::Part { film, job, path: path.clone() });
            }
            veach::merge(&parts)
        })
        .map_err(py_err)?;
    let stats = serde_json::json!({"scene": job.scene.display().to_string(), "spp": film.samples(),
        "parts": paths.len(), "width": film.width, "height": film.height});
    Ok(Image::new(film, Some(job), None, stats))
}

/// The image denoised by Open Image Denoise's network (with its albedo and normal AOVs when
/// it has them); a new image.
#[pyfunction]
#[pyo3(signature = (image, quality="balanced", backend="auto"))]
fn denoise(py: Python<'_>, image: PyRef<'_, Image>, quality: &str, backend: &str) -> PyResult<Image> {
    let quality: veach::denoise::Quality = quality.parse().map_err(value_err)?;
    let backend = parse_backend(backend)?;
    let film = &image.film;
    let (denoised, engine_name) = py
        .detach(|| -> Result<_, veach::Error> {
            // As `veach denoise`: auto takes a hardware GPU, else the CPU twin.
            let (ctx, _) = veach::denoise::device(backend)?;
            let engine = ctx.as_ref().map_or(veach::denoise::Engine::Cpu, veach::denoise::Engine::Gpu);
            let options = veach::denoise::Options { quality, ..Default::default() };
            Ok((veach::denoise::denoise_film(film, &options, engine)?, engine.name()))
        })
        .map_err(py_err)?;
    let mut stats = image.stats.clone();
    if let Some(o) = stats.as_object_mut() {
        o.insert("denoise_quality".into(), quality.name().into());
        o.insert("denoise_engine".into(), engine_name.into());
    }
    Ok(Image::new(film.clone(), image.job.clone(), Some(denoised), stats))
}

#[pymodule]
fn _veach(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<Error>())?;
    m.add("Interrupted", m.py().get_type::<Interrupted>())?;
    m.add_class::<Scene>()?;
    m.add_class::<Image>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(read_rgb, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(denoise, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
