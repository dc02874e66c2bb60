//! `veach view`: an egui/eframe window over the same `Renderer`, refining progressively, on
//! the faster engine for this machine (`viewer_backend`). A compute pass
//! (`shaders/display.wgsl`) tone-maps the film into the texture egui draws: the GPU engine's
//! film in place (no pixels travel back to the CPU), the CPU engine's uploaded each frame.

mod orbit;
mod panel;

use crate::gpu::{Display, GpuContext};
use crate::packed::PackedScene;
use crate::scene::{Camera, Scene};
use crate::tonemap::Tonemap;
use crate::{Error, ROW_BAND, Renderer, Settings};
use eframe::egui;
use eframe::egui_wgpu;
use eframe::wgpu;
use glam::Vec3;
use orbit::Orbit;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// GPU work per frame, and per band of rows within it.
const FRAME_SECONDS: f64 = 0.030;
const BAND_SECONDS: f64 = 0.010;
/// Samples the viewer accumulates before it stops (the panel changes it).
const TARGET_SPP: u32 = 4096;
/// The film's size before the window has laid out the image area.
const FIRST_FILM_SIDE: u32 = 64;
/// Render scale while the camera moves.
const SCALE_MOVING: f32 = 0.25;

pub struct ViewOptions {
    pub scene: Option<PathBuf>,
    /// Render this many frames, save a screenshot of the whole window here, and exit.
    pub screenshot: Option<PathBuf>,
    pub frames: u32,
    pub max_depth: u32,
    pub env: Option<PathBuf>,
    pub env_color: Option<Vec3>,
    /// Window size in points.
    pub window: (u32, u32),
    /// Fraction of the image area's pixels rendered when still (lavapipe is slow: 0.5).
    pub render_scale: f32,
    /// The engine: `Auto` renders on the window's GPU when it is a hardware one, else on
    /// the CPU engine (its film uploaded to the window each frame).
    pub backend: crate::Backend,
    /// Adaptive sampling's noise threshold (None: every pixel takes every sample).
    pub noise_threshold: Option<f32>,
    /// Show the samples each pixel took (a heat map) from the start.
    pub heat_map: bool,
    /// Start with the denoiser on.
    pub denoise: bool,
}

/// The viewer's default noise threshold: between Cycles' viewport (0.1) and final (0.01)
/// defaults; on the glass Cornell box half the pixels stop by 600 spp, the walls first.
pub const NOISE_THRESHOLD: f32 = 0.05;

pub fn run(options: ViewOptions) -> Result<(), Error> {
    // The window's device asks for the adapter's own limits (eframe asks for WebGPU's
    // defaults: a 128 MiB storage binding even on GPUs that offer GiBs), so scenes page their
    // geometry only when this device needs it, as `veach render` does.
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    setup.device_descriptor = Arc::new(|adapter: &wgpu::Adapter| wgpu::DeviceDescriptor {
        label: Some("veach viewer"),
        required_limits: adapter.limits(),
        required_features: adapter.features() & wgpu::Features::SHADER_F16,
        ..Default::default()
    });
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([options.window.0 as f32, options.window.1 as f32])
            .with_title("veach"),
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
            ..Default::default()
        },
        ..Default::default()
    };
    let result: Arc<Mutex<Result<(), Error>>> = Arc::new(Mutex::new(Ok(())));
    let outcome = result.clone();
    eframe::run_native(
        "veach",
        native,
        Box::new(move |cc| {
            let rs = cc.wgpu_render_state.clone().ok_or("the window has no wgpu renderer")?;
            Ok(Box::new(Viewer::new(rs, options, outcome)))
        }),
    )
    .map_err(|e| Error::Gpu(format!("cannot open the viewer window: {e}")))?;
    result.lock().map(|mut r| std::mem::replace(&mut *r, Ok(()))).unwrap_or(Ok(()))
}

struct Viewer {
    rs: egui_wgpu::RenderState,
    options: ViewOptions,
    outcome: Arc<Mutex<Result<(), Error>>>,
    scene_path: Option<PathBuf>,
    scene: Option<Scene>,
    renderer: Option<Renderer>,
    /// The engine in use, and why (the panel shows it).
    backend: (crate::Backend, String),
    display: Option<Display>,
    /// The CPU engine's film as the display pass reads it, uploaded each frame.
    uploaded_film: Option<wgpu::Buffer>,
    /// The display texture as egui knows it, and its size.
    display_id: Option<(egui::TextureId, u32, u32)>,
    orbit: Orbit,
    home: Orbit,
    extent: f32,
    settings: Settings,
    exposure: f32,
    tonemap: Tonemap,
    env_strength: f32,
    /// The strength the renderer's environment was built with (None: rebuild it).
    env_applied: Option<f32>,
    /// The environment came from the command line or a dropped map, not the scene.
    env_given: bool,
    /// Light scenes without lights by the default studio (the panel switches it off).
    studio: bool,
    paused: bool,
    /// Shows the samples each pixel took (a heat map) instead of the image.
    heat_map: bool,
    /// The fraction of pixels that stopped (adaptive sampling), after the last whole sample.
    converged: Option<f64>,
    target_spp: u32,
    samples: u32,
    /// Next film row of the sample in progress, and rows per dispatch (multiples of 8).
    row: u32,
    band: u32,
    rate: f64,
    scale_moving: f32,
    scale: f32,
    moving: bool,
    dirty: bool,
    error: Option<String>,
    open_path: String,
    save_path: String,
    status: String,
    frame: u32,
    shot: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    shot_requested: bool,
    /// The denoiser (a panel toggle): runs on a worker thread whenever the image is still.
    denoise: Denoise,
}

/// The viewer's denoiser state.
struct Denoise {
    on: bool,
    quality: crate::denoise::Quality,
    /// The denoise in progress on a worker thread.
    job: Option<std::sync::mpsc::Receiver<Result<Denoised, Error>>>,
    /// The latest result, shown while the camera is still.
    result: Option<Denoised>,
    /// Bumped by every restart: results of an older accumulation are dropped.
    generation: u64,
    /// Samples at which the next denoise starts (doubling: denoising costs about log2 of
    /// the samples' number of runs).
    next_at: u32,
}

/// A denoised image, as a film of one sample a pixel for the display pass.
struct Denoised {
    film: crate::Film,
    samples: u32,
    generation: u64,
    seconds: f64,
}

impl Viewer {
    fn new(rs: egui_wgpu::RenderState, options: ViewOptions, outcome: Arc<Mutex<Result<(), Error>>>) -> Viewer {
        let display_ctx = GpuContext::from_device(rs.device.clone(), rs.queue.clone(), rs.adapter.get_info());
        let display = match Display::new(&display_ctx) {
            Ok(d) => Some(d),
            Err(e) => {
                if let Ok(mut o) = outcome.lock() {
                    *o = Err(e);
                }
                None
            }
        };
        let settings = Settings {
            width: FIRST_FILM_SIDE,
            height: FIRST_FILM_SIDE,
            max_depth: options.max_depth,
            noise_threshold: options.noise_threshold,
            ..Settings::default()
        };
        let backend = viewer_backend(options.backend, &rs.adapter.get_info());
        let orbit = Orbit { target: Vec3::ZERO, yaw: 0.0, pitch: 0.0, distance: 4.0, yfov: 40f32.to_radians() };
        let mut v = Viewer {
            rs,
            outcome,
            scene_path: None,
            scene: None,
            renderer: None,
            backend,
            display,
            uploaded_film: None,
            display_id: None,
            home: orbit.clone(),
            orbit,
            extent: 1.0,
            settings,
            exposure: 0.0,
            tonemap: Tonemap::Aces,
            env_strength: 1.0,
            env_applied: None,
            env_given: false,
            studio: true,
            paused: false,
            heat_map: options.heat_map,
            converged: None,
            target_spp: TARGET_SPP,
            samples: 0,
            row: 0,
            band: ROW_BAND,
            rate: 0.0,
            scale_moving: SCALE_MOVING,
            scale: options.render_scale.clamp(0.05, 1.0),
            moving: false,
            dirty: true,
            error: None,
            open_path: String::new(),
            save_path: "veach.png".into(),
            status: String::new(),
            frame: 0,
            shot: Arc::new(Mutex::new(None)),
            shot_requested: false,
            denoise: Denoise {
                on: options.denoise,
                quality: crate::denoise::Quality::Fast,
                job: None,
                result: None,
                generation: 0,
                next_at: 1,
            },
            options,
        };
        if v.denoise.on {
            v.settings.aovs = DENOISER_AOVS.to_vec();
        }
        if let Some(p) = v.options.scene.clone() {
            v.open_path = p.display().to_string();
            v.open(&p);
        }
        v
    }

    /// Loads a scene; on failure the error shows in the window and the old scene stays.
    fn open(&mut self, path: &Path) {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if matches!(ext.as_deref(), Some("hdr") | Some("exr")) {
            match crate::scene::EnvironmentMap::load(path) {
                Ok(map) => {
                    // A new sky: the renderer keeps its BVH and geometry.
                    if let Some(scene) = &mut self.scene {
                        scene.environment = crate::Environment::map(map, Vec3::ONE);
                        self.env_given = true;
                        self.env_applied = None;
                        self.dirty = true;
                    }
                }
                Err(e) => self.error = Some(e.to_string()),
            }
            return;
        }
        match crate::load(path, None) {
            Ok(crate::Loaded { mut scene, camera, warnings }) => {
                self.status = warnings.join("; ");
                self.env_given = self.options.env.is_some() || self.options.env_color.is_some();
                if let Some(map) = &self.options.env {
                    match crate::scene::EnvironmentMap::load(map) {
                        Ok(m) => {
                            scene.environment = crate::Environment::map(m, self.options.env_color.unwrap_or(Vec3::ONE));
                        }
                        Err(e) => self.error = Some(e.to_string()),
                    }
                } else if let Some(c) = self.options.env_color {
                    scene.environment = crate::Environment::constant(c);
                }
                self.scene_path = Some(path.to_path_buf());
                self.install(scene, Some(camera));
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn install(&mut self, scene: Scene, camera: Option<Camera>) {
        let b = scene.bounds();
        self.extent = if b.is_empty() { 1.0 } else { b.diagonal().length().max(1e-6) };
        let center = if b.is_empty() { Vec3::ZERO } else { b.center() };
        if let Some(c) = camera {
            self.orbit = Orbit::from_camera(&c, center, self.extent);
            self.home = self.orbit.clone();
        }
        let packed = PackedScene::new(&scene);
        for w in &packed.warnings {
            self.status = if self.status.is_empty() { w.clone() } else { format!("{}; {w}", self.status) };
        }
        // The first restart installs `environment()`: the renderer alone cannot tell a sky
        // made black on purpose from none.
        self.env_applied = None;
        let built = match self.backend.0 {
            crate::Backend::Cpu => Renderer::new(packed, &self.orbit.camera(), &self.settings, crate::Backend::Cpu),
            _ => {
                let info = self.rs.adapter.get_info();
                let ctx = GpuContext::from_device(self.rs.device.clone(), self.rs.queue.clone(), info);
                Renderer::with_context(packed, &self.orbit.camera(), &self.settings, ctx)
            }
        };
        match built {
            Ok(r) => {
                self.renderer = Some(r);
                self.scene = Some(scene);
                self.error = None;
                self.dirty = true;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Where the environment in use comes from.
    fn environment_source(&self) -> Option<crate::EnvironmentSource> {
        let scene = self.scene.as_ref()?;
        Some(crate::EnvironmentSource::choose(self.env_given, &scene.environment, scene.has_lights()))
    }

    /// The environment in use (the scene's, the given one, or the default studio when the
    /// scene has no lights and the panel leaves it on), scaled by the strength slider.
    fn environment(&self) -> Option<crate::Environment> {
        let scene = self.scene.as_ref()?;
        let env = match self.environment_source()? {
            crate::EnvironmentSource::Studio if self.studio => crate::Environment::studio(),
            _ => scene.environment.clone(),
        };
        Some(crate::Environment { map: env.map, radiance: env.radiance * self.env_strength })
    }

    /// Restart accumulation at the size the image area wants.
    fn restart(&mut self, width: u32, height: u32) {
        let scale = self.scale * if self.moving { self.scale_moving } else { 1.0 };
        self.settings.width = ((width as f32 * scale) as u32).max(8);
        self.settings.height = ((height as f32 * scale) as u32).max(8);
        let camera = self.orbit.camera();
        let environment = (self.env_applied != Some(self.env_strength)).then(|| self.environment()).flatten();
        if let Some(r) = &mut self.renderer {
            let mut result = r.reset(&camera, &self.settings);
            if let (Ok(()), Some(env)) = (&result, environment) {
                result = r.set_environment(&camera, &env);
                self.env_applied = Some(self.env_strength);
            }
            if let Err(e) = result {
                self.error = Some(e.to_string());
            }
        }
        self.samples = 0;
        self.converged = None;
        self.row = 0;
        self.dirty = false;
        self.denoise.generation += 1;
        self.denoise.next_at = 1;
    }

    /// Collects a finished denoise, and starts one when the image is still and has gained
    /// samples since the last (at 1, 2, 4, ... spp, and when rendering stops).
    fn step_denoiser(&mut self) {
        let Some(r) = &self.renderer else { return };
        let d = &mut self.denoise;
        if let Some(rx) = &d.job {
            match rx.try_recv() {
                Ok(Ok(result)) => {
                    d.job = None;
                    if result.generation == d.generation {
                        d.result = Some(result);
                    }
                }
                Ok(Err(e)) => {
                    d.job = None;
                    self.error = Some(e.to_string());
                }
                Err(std::sync::mpsc::TryRecvError::Empty) => {}
                Err(std::sync::mpsc::TryRecvError::Disconnected) => d.job = None,
            }
        }
        let stopped = self.paused || self.samples >= self.target_spp || self.converged.is_some_and(|c| c >= 1.0);
        let done = d.result.as_ref().filter(|x| x.generation == d.generation).map_or(0, |x| x.samples);
        let due = self.samples >= d.next_at || (stopped && done < self.samples);
        if !d.on || self.moving || d.job.is_some() || self.samples == 0 || done >= self.samples || !due {
            return;
        }
        let film = match r.film() {
            Ok(f) => f,
            Err(e) => {
                self.error = Some(e.to_string());
                return;
            }
        };
        let options = crate::denoise::Options { quality: d.quality, ..Default::default() };
        // On the GPU engine the network runs on its device, else on the CPU twin.
        let ctx = r.gpu().map(|g| g.context().clone());
        let (generation, samples) = (d.generation, self.samples);
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let start = Instant::now();
            let engine = ctx.as_ref().map_or(crate::denoise::Engine::Cpu, crate::denoise::Engine::Gpu);
            let result = crate::denoise::denoise_film(&film, &options, engine).map(|rgb| Denoised {
                film: crate::Film::from_rgb(film.width, film.height, &rgb),
                samples,
                generation,
                seconds: start.elapsed().as_secs_f64(),
            });
            let _ = tx.send(result);
        });
        d.job = Some(rx);
        d.next_at = self.samples.saturating_mul(2);
    }

    /// The denoised image to show instead of the film (the camera is still and it is of this
    /// accumulation).
    fn denoised(&self) -> Option<&crate::Film> {
        let d = &self.denoise;
        d.result.as_ref().filter(|x| d.on && !self.moving && x.generation == d.generation).map(|x| &x.film)
    }

    fn save(&mut self, png: bool) {
        let Some(r) = &self.renderer else { return };
        let mut path = PathBuf::from(self.save_path.trim());
        path.set_extension(if png { "png" } else { "exr" });
        let result =
            r.film().and_then(|film| crate::output::write_with(&film, &path, self.exposure, self.tonemap, None));
        match result {
            Ok(()) => self.status = format!("saved {}", path.display()),
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn finish(&mut self, result: Result<(), Error>, ui: &egui::Ui) {
        if let Ok(mut o) = self.outcome.lock() {
            *o = result;
        }
        ui.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

impl eframe::App for Viewer {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame += 1;
        let dropped: Vec<PathBuf> = ui.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).collect());
        if let Some(p) = dropped.first() {
            self.open_path = p.display().to_string();
            self.open(p);
        }
        let mut changed = false;
        egui::Panel::left("settings").default_size(280.0).show(ui, |ui| {
            changed |= self.side_panel(ui);
        });
        egui::CentralPanel::default().show(ui, |ui| {
            let avail = ui.available_size();
            let (w, h) = (avail.x.max(8.0) as u32, avail.y.max(8.0) as u32);
            let (rect, response) = ui.allocate_exact_size(avail, egui::Sense::click_and_drag());
            let moved = self.input(ui, &response);
            let was_moving = self.moving;
            self.moving = moved;
            let full = ((w as f32 * self.scale * if self.moving { self.scale_moving } else { 1.0 }) as u32).max(8);
            if changed || moved || self.dirty || was_moving != self.moving || full != self.settings.width {
                self.restart(w, h);
            }
            // Progressive refinement within FRAME_SECONDS of GPU work per frame: a sample is
            // rendered in bands of rows sized to BAND_SECONDS each, so even a slow device
            // (lavapipe takes seconds per full-window sample) keeps the window responsive.
            if let Some(r) = &mut self.renderer
                && !self.paused
            {
                let (w, h) = (self.settings.width, self.settings.height.next_multiple_of(ROW_BAND));
                let t = Instant::now();
                let mut pixels = 0u64;
                let all_converged = |c: Option<f64>| c.is_some_and(|c| c >= 1.0);
                while self.samples < self.target_spp
                    && !all_converged(self.converged)
                    && t.elapsed().as_secs_f64() < FRAME_SECONDS
                {
                    let rows = self.band.min(h - self.row);
                    let t1 = Instant::now();
                    if let Err(e) = r.render_rows(self.samples, self.row, rows) {
                        self.error = Some(e.to_string());
                        break;
                    }
                    let secs = t1.elapsed().as_secs_f64().max(1e-6);
                    pixels += rows as u64 * w as u64;
                    self.band = (((rows as f64 * BAND_SECONDS / secs) as u32) / ROW_BAND * ROW_BAND).clamp(ROW_BAND, h);
                    self.row += rows;
                    if self.row >= h {
                        self.row = 0;
                        self.samples += 1;
                        self.converged = r.converged_fraction().unwrap_or(None);
                    }
                }
                if pixels > 0 {
                    self.rate = pixels as f64 / t.elapsed().as_secs_f64().max(1e-6);
                }
            }
            self.step_denoiser();
            let showing_denoised = self.denoised().is_some();
            let shown = if showing_denoised {
                let film = self.denoise.result.as_ref().map(|d| &d.film);
                film.and_then(|f| upload_film(f, &self.rs, &mut self.uploaded_film))
            } else {
                self.renderer.as_ref().and_then(|r| film_on_device(r, &self.rs, &mut self.uploaded_film))
            };
            if let Some(film) = shown {
                let (w, h) = (self.settings.width, self.settings.height);
                let Some(display) = &mut self.display else { return };
                let heat = if self.heat_map && !showing_denoised { self.samples.max(1) } else { 0 };
                let look = crate::gpu::Look { exposure: self.exposure, tonemap: self.tonemap, heat_max: heat };
                let (view, new) = display.resolve(&self.rs.device, &self.rs.queue, &film, (w, h), look);
                let mut egui_renderer = self.rs.renderer.write();
                let id = match self.display_id {
                    Some((id, dw, dh)) if !new && (dw, dh) == (w, h) => id,
                    Some((id, _, _)) => {
                        egui_renderer.update_egui_texture_from_wgpu_texture(
                            &self.rs.device,
                            view,
                            wgpu::FilterMode::Linear,
                            id,
                        );
                        id
                    }
                    None => egui_renderer.register_native_texture(&self.rs.device, view, wgpu::FilterMode::Linear),
                };
                drop(egui_renderer);
                self.display_id = Some((id, w, h));
                ui.painter().image(
                    id,
                    rect,
                    egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                    egui::Color32::WHITE,
                );
            } else {
                ui.centered_and_justified(|ui| ui.label("open a glTF scene (.gltf / .glb) or drop one here"));
            }
        });
        if let Some(out) = self.options.screenshot.clone() {
            // With the denoiser on, the screenshot waits for its first result.
            let ready = !self.denoise.on || self.denoised().is_some();
            if self.frame >= self.options.frames && ready && !self.shot_requested {
                let slot = self.shot.clone();
                let ctx = ui.ctx().clone();
                ui.ctx().request_screenshot(move |img| {
                    if let Ok(mut s) = slot.lock() {
                        *s = Some(img);
                    }
                    ctx.request_repaint();
                });
                self.shot_requested = true;
            }
            let taken = self.shot.lock().ok().and_then(|mut s| s.take());
            if let Some(img) = taken {
                let [w, h] = img.size;
                let mut rgb = image::RgbImage::new(w as u32, h as u32);
                for (p, c) in rgb.pixels_mut().zip(&img.pixels) {
                    *p = image::Rgb([c.r(), c.g(), c.b()]);
                }
                let result = crate::output::write_png(&rgb, &out);
                self.finish(result, ui);
            }
            self.rs.device.poll(wgpu::PollType::Poll).ok();
        }
        ui.ctx().request_repaint();
    }
}

/// The engine the viewer renders with, and why: as asked, or (`Auto`) the window's GPU when
/// it is a hardware adapter and the CPU engine when it is a software one (lavapipe runs the
/// kernel slower than the CPU engine runs its twin; BENCHMARKS.md).
fn viewer_backend(asked: crate::Backend, adapter: &wgpu::AdapterInfo) -> (crate::Backend, String) {
    match asked {
        crate::Backend::Auto if adapter.device_type == wgpu::DeviceType::Cpu => {
            (crate::Backend::Cpu, format!("auto: {} is a software adapter", adapter.name))
        }
        crate::Backend::Auto => (crate::Backend::Gpu, format!("auto: {}", adapter.name)),
        b => (b, "requested".into()),
    }
}

/// The AOVs the denoiser reads.
const DENOISER_AOVS: [crate::aov::Aov; 2] = [crate::aov::Aov::Albedo, crate::aov::Aov::Normal];

/// The film as a buffer of the window's device: the GPU engine's own, or the CPU engine's
/// uploaded into `upload` (same layout, 12 words a pixel; a few MB a frame).
fn film_on_device(
    r: &Renderer,
    rs: &egui_wgpu::RenderState,
    upload: &mut Option<wgpu::Buffer>,
) -> Option<wgpu::Buffer> {
    if let Some(g) = r.gpu() {
        return Some(g.film_buffer().clone());
    }
    upload_film(&r.film().ok()?, rs, upload)
}

/// A host film uploaded into `upload`, a buffer of the window's device.
fn upload_film(
    film: &crate::Film,
    rs: &egui_wgpu::RenderState,
    upload: &mut Option<wgpu::Buffer>,
) -> Option<wgpu::Buffer> {
    let bytes: &[u8] = bytemuck::cast_slice(&film.data);
    if upload.as_ref().is_none_or(|b| b.size() != bytes.len() as u64) {
        *upload = Some(rs.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("uploaded film"),
            size: bytes.len() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
    }
    let buffer = upload.as_ref()?;
    rs.queue.write_buffer(buffer, 0, bytes);
    Some(buffer.clone())
}
