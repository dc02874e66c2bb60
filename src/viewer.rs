//! `veach view`: an egui/eframe window over the same `Renderer`, refining progressively. The
//! film stays on the GPU: a compute pass (`shaders/display.wgsl`) tone-maps it into the
//! texture egui draws, so no pixels travel back to the CPU per frame.

use crate::gpu::{GpuContext, shaders};
use crate::packed::PackedScene;
use crate::scene::{Camera, Scene};
use crate::tonemap::Tonemap;
use crate::{Error, Renderer, Settings, Strategy};
use eframe::egui;
use eframe::egui_wgpu;
use eframe::wgpu;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

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
}

pub fn run(options: ViewOptions) -> Result<(), Error> {
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([options.window.0 as f32, options.window.1 as f32])
            .with_title("veach"),
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

/// Mouse and keyboard camera: orbit about a target, pan, zoom, fly.
#[derive(Clone, Debug)]
struct Orbit {
    target: Vec3,
    yaw: f32,
    pitch: f32,
    distance: f32,
    yfov: f32,
}

impl Orbit {
    fn from_camera(c: &Camera, scene_center: Vec3, extent: f32) -> Orbit {
        let distance = (scene_center - c.position).dot(c.forward).max(0.05 * extent).max(1e-3);
        let f = c.forward;
        Orbit {
            target: c.position + f * distance,
            yaw: f.x.atan2(-f.z),
            pitch: f.y.clamp(-1.0, 1.0).asin(),
            distance,
            yfov: c.yfov,
        }
    }

    fn forward(&self) -> Vec3 {
        Vec3::new(self.yaw.sin() * self.pitch.cos(), self.pitch.sin(), -self.yaw.cos() * self.pitch.cos())
    }

    fn camera(&self) -> Camera {
        let f = self.forward();
        Camera::look_at("viewer", self.target - f * self.distance, self.target, Vec3::Y, self.yfov)
    }
}

struct Display {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    texture: Option<(wgpu::Texture, wgpu::BindGroup, egui::TextureId, u32, u32)>,
}

struct Viewer {
    rs: egui_wgpu::RenderState,
    options: ViewOptions,
    outcome: Arc<Mutex<Result<(), Error>>>,
    scene_path: Option<PathBuf>,
    scene: Option<Scene>,
    renderer: Option<Renderer>,
    display: Display,
    orbit: Orbit,
    home: Orbit,
    extent: f32,
    settings: Settings,
    exposure: f32,
    tonemap: Tonemap,
    env_strength: f32,
    /// The strength the renderer's environment was built with (None: rebuild it).
    env_applied: Option<f32>,
    paused: bool,
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
}

impl Viewer {
    fn new(rs: egui_wgpu::RenderState, options: ViewOptions, outcome: Arc<Mutex<Result<(), Error>>>) -> Viewer {
        let display = Display::new(&rs.device);
        let settings = Settings { width: 64, height: 64, max_depth: options.max_depth, ..Settings::default() };
        let orbit = Orbit { target: Vec3::ZERO, yaw: 0.0, pitch: 0.0, distance: 4.0, yfov: 40f32.to_radians() };
        let mut v = Viewer {
            rs,
            outcome,
            scene_path: None,
            scene: None,
            renderer: None,
            display,
            home: orbit.clone(),
            orbit,
            extent: 1.0,
            settings,
            exposure: 0.0,
            tonemap: Tonemap::Aces,
            env_strength: 1.0,
            env_applied: None,
            paused: false,
            target_spp: 4096,
            samples: 0,
            row: 0,
            band: 8,
            rate: 0.0,
            scale_moving: 0.25,
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
            options,
        };
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
        let ctx = GpuContext::from_device(self.rs.device.clone(), self.rs.queue.clone(), self.rs.adapter.get_info());
        self.env_applied = Some(1.0);
        match Renderer::with_context(packed, &self.orbit.camera(), &self.settings, ctx) {
            Ok(r) => {
                self.renderer = Some(r);
                self.scene = Some(scene);
                self.error = None;
                self.dirty = true;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// The scene's environment scaled by the strength slider.
    fn environment(&self) -> Option<crate::Environment> {
        let env = &self.scene.as_ref()?.environment;
        Some(crate::Environment { map: env.map.clone(), radiance: env.radiance * self.env_strength })
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
        self.row = 0;
        self.dirty = false;
    }

    fn input(&mut self, ui: &egui::Ui, response: &egui::Response) -> bool {
        let mut changed = false;
        let d = response.drag_delta();
        let shift = ui.input(|i| i.modifiers.shift);
        if response.dragged_by(egui::PointerButton::Middle)
            || (shift && response.dragged_by(egui::PointerButton::Primary))
        {
            let c = self.orbit.camera();
            let k = self.orbit.distance * 0.0015;
            self.orbit.target += (-c.right * d.x + c.up * d.y) * k;
            changed |= d != egui::Vec2::ZERO;
        } else if response.dragged_by(egui::PointerButton::Primary) {
            self.orbit.yaw += d.x * 0.005;
            self.orbit.pitch = (self.orbit.pitch - d.y * 0.005).clamp(-1.55, 1.55);
            changed |= d != egui::Vec2::ZERO;
        }
        // A click focuses the lens on what is under the pointer.
        if response.clicked()
            && let (Some(p), Some(r)) = (response.interact_pointer_pos(), &self.renderer)
        {
            let uv = (p - response.rect.min) / response.rect.size();
            let pixel = glam::UVec2::new(
                (uv.x * self.settings.width as f32).max(0.0) as u32,
                (uv.y * self.settings.height as f32).max(0.0) as u32,
            );
            if let Some(depth) = r.pick_depth(pixel) {
                self.settings.focus_distance = Some(depth);
                self.status = format!("focus distance {:.4}", self.settings.focus_distance.unwrap_or(0.0));
                changed = true;
            }
        }
        if response.hovered() {
            let s = ui.input(|i| i.smooth_scroll_delta);
            let wheel = s.x + s.y;
            if wheel != 0.0 {
                self.orbit.distance = (self.orbit.distance * (-wheel * 0.002).exp()).max(1e-4 * self.extent);
                changed = true;
            }
        }
        if !ui.ctx().egui_wants_keyboard_input() {
            let dt = ui.input(|i| i.stable_dt).min(0.1);
            let speed = 0.5 * self.extent * dt;
            let c = self.orbit.camera();
            let mut mv = Vec3::ZERO;
            ui.input(|i| {
                for (key, dir) in [
                    (egui::Key::W, c.forward),
                    (egui::Key::S, -c.forward),
                    (egui::Key::D, c.right),
                    (egui::Key::A, -c.right),
                    (egui::Key::E, Vec3::Y),
                    (egui::Key::Q, -Vec3::Y),
                ] {
                    if i.key_down(key) {
                        mv += dir;
                    }
                }
            });
            if mv != Vec3::ZERO {
                self.orbit.target += mv * speed;
                changed = true;
            }
            if ui.input(|i| i.key_pressed(egui::Key::F)) {
                self.orbit = self.home.clone();
                changed = true;
            }
        }
        changed
    }

    fn side_panel(&mut self, ui: &mut egui::Ui) -> bool {
        let mut changed = false;
        ui.heading("veach");
        let adapter = self.renderer.as_ref().map(|r| r.adapter_name()).unwrap_or_else(|| "no scene".into());
        ui.label(format!("backend: gpu, {adapter}"));
        ui.label(format!("samples: {} / {}", self.samples, self.target_spp));
        ui.label(format!("{:.2} Msamples/s", self.rate / 1e6));
        ui.label(format!("resolution: {}×{}", self.settings.width, self.settings.height));
        if let Some(p) = &self.scene_path {
            ui.label(format!("scene: {}", p.file_name().map(|n| n.to_string_lossy()).unwrap_or_default()));
        }
        ui.separator();
        ui.checkbox(&mut self.paused, "pause");
        ui.add(egui::Slider::new(&mut self.target_spp, 1..=65536).logarithmic(true).text("target spp"));
        let before = (self.settings.strategy, self.settings.max_depth, self.env_strength);
        egui::ComboBox::from_label("strategy").selected_text(format!("{:?}", self.settings.strategy)).show_ui(
            ui,
            |ui| {
                for s in [Strategy::Bsdf, Strategy::Light, Strategy::MisBalance, Strategy::MisPower] {
                    ui.selectable_value(&mut self.settings.strategy, s, format!("{s:?}"));
                }
            },
        );
        ui.add(egui::Slider::new(&mut self.settings.max_depth, 0..=32).text("max depth (0 = ∞)"));
        ui.add(egui::Slider::new(&mut self.env_strength, 0.0..=10.0).text("environment"));
        changed |= before != (self.settings.strategy, self.settings.max_depth, self.env_strength);
        let max_aperture = 0.05 * self.extent;
        changed |=
            ui.add(egui::Slider::new(&mut self.settings.aperture, 0.0..=max_aperture).text("aperture (DOF)")).changed();
        let mut focus = self.settings.focus_distance.unwrap_or(self.orbit.distance);
        if ui
            .add(egui::Slider::new(&mut focus, 1e-3 * self.extent..=2.0 * self.extent).text("focus distance"))
            .changed()
        {
            self.settings.focus_distance = Some(focus);
            changed = true;
        }
        ui.label("click the image to focus there");
        ui.add(egui::Slider::new(&mut self.exposure, -8.0..=8.0).text("exposure (EV)"));
        egui::ComboBox::from_label("tone mapper").selected_text(self.tonemap.name()).show_ui(ui, |ui| {
            for t in Tonemap::ALL {
                ui.selectable_value(&mut self.tonemap, t, t.name());
            }
        });
        changed |= ui.add(egui::Slider::new(&mut self.scale, 0.1..=1.0).text("render scale")).changed();
        ui.add(egui::Slider::new(&mut self.scale_moving, 0.25..=1.0).text("scale while moving"));
        if let Some(scene) = &self.scene
            && !scene.cameras.is_empty()
        {
            let mut pick = None;
            egui::ComboBox::from_label("camera").selected_text("glTF cameras").show_ui(ui, |ui| {
                for c in &scene.cameras {
                    if ui.selectable_label(false, &c.name).clicked() {
                        pick = Some(c.clone());
                    }
                }
            });
            if let Some(c) = pick {
                let b = scene.bounds();
                self.orbit = Orbit::from_camera(&c, b.center(), self.extent);
                changed = true;
            }
        }
        if ui.button("reset view (F)").clicked() {
            self.orbit = self.home.clone();
            changed = true;
        }
        ui.separator();
        ui.label("open .gltf / .glb / .hdr (or drop a file here)");
        ui.text_edit_singleline(&mut self.open_path);
        if ui.button("open").clicked() {
            let p = PathBuf::from(self.open_path.trim());
            self.open(&p);
        }
        ui.separator();
        ui.text_edit_singleline(&mut self.save_path);
        ui.horizontal(|ui| {
            if ui.button("save PNG").clicked() {
                self.save(true);
            }
            if ui.button("save EXR").clicked() {
                self.save(false);
            }
        });
        if !self.status.is_empty() {
            ui.label(&self.status);
        }
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 110), format!("error: {e}"));
        }
        changed
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
            // Progressive refinement within about 30 ms of GPU work per frame: a sample is
            // rendered in bands of rows sized to ~10 ms each, so even a slow device (lavapipe
            // takes seconds per full-window sample) keeps the window responsive.
            if let Some(r) = &mut self.renderer
                && !self.paused
            {
                let (w, h) = (self.settings.width, self.settings.height.next_multiple_of(8));
                let t = Instant::now();
                let mut pixels = 0u64;
                while self.samples < self.target_spp && t.elapsed().as_secs_f64() < 0.030 {
                    let rows = self.band.min(h - self.row);
                    let t1 = Instant::now();
                    if let Err(e) = r.render_rows(self.samples, self.row, rows) {
                        self.error = Some(e.to_string());
                        break;
                    }
                    let secs = t1.elapsed().as_secs_f64().max(1e-6);
                    pixels += rows as u64 * w as u64;
                    self.band = (((rows as f64 * 0.010 / secs) as u32) / 8 * 8).clamp(8, h);
                    self.row += rows;
                    if self.row >= h {
                        self.row = 0;
                        self.samples += 1;
                    }
                }
                if pixels > 0 {
                    self.rate = pixels as f64 / t.elapsed().as_secs_f64().max(1e-6);
                }
            }
            if let Some(r) = &self.renderer
                && let Some(g) = r.gpu()
            {
                let id = self.display.resolve(
                    &self.rs,
                    g,
                    self.settings.width,
                    self.settings.height,
                    self.exposure,
                    self.tonemap,
                );
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
            if self.frame >= self.options.frames && !self.shot_requested {
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

impl Display {
    fn new(device: &wgpu::Device) -> Display {
        let source = shaders::compose(shaders::DISPLAY).unwrap_or_default();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("display"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let buffer = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display"),
            entries: &[
                buffer(0),
                buffer(1),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba8Unorm,
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("display"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("resolve"),
            compilation_options: Default::default(),
            cache: None,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display params"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Display { pipeline, layout, params, texture: None }
    }

    /// Tone-maps the film into the display texture and returns its egui id.
    fn resolve(
        &mut self,
        rs: &egui_wgpu::RenderState,
        g: &crate::gpu::GpuRenderer,
        w: u32,
        h: u32,
        exposure: f32,
        tonemap: Tonemap,
    ) -> egui::TextureId {
        let device = &rs.device;
        let stale = self.texture.as_ref().is_none_or(|t| (t.3, t.4) != (w, h));
        // The bind group names the film buffer, which a reset may have replaced: rebuild it each frame.
        let texture = if stale {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("display"),
                size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba8Unorm,
                usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            let id = match self.texture.take() {
                Some((_, _, id, _, _)) => {
                    rs.renderer.write().update_egui_texture_from_wgpu_texture(
                        device,
                        &view,
                        wgpu::FilterMode::Linear,
                        id,
                    );
                    id
                }
                None => rs.renderer.write().register_native_texture(device, &view, wgpu::FilterMode::Linear),
            };
            (texture, id)
        } else {
            let t = self.texture.take().expect("texture present");
            (t.0, t.2)
        };
        let (texture, id) = texture;
        let view = texture.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: g.film_buffer().as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&view) },
            ],
        });
        let p = [w, h, tonemap as u32, exposure.exp2().to_bits()];
        rs.queue.write_buffer(&self.params, 0, bytemuck::cast_slice(&p));
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        rs.queue.submit([encoder.finish()]);
        self.texture = Some((texture, bind_group, id, w, h));
        id
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orbit_reproduces_the_camera_it_starts_from() {
        // The viewer's first frame uses the same camera as `veach render`.
        let crate::Loaded { scene, camera, .. } =
            crate::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/assets/cornell-box.gltf")), None)
                .expect("asset");
        let b = scene.bounds();
        let c = Orbit::from_camera(&camera, b.center(), b.diagonal().length()).camera();
        assert!((c.position - camera.position).length() < 1e-3 * b.diagonal().length(), "{c:?} vs {camera:?}");
        assert!((c.forward - camera.forward).length() < 1e-5);
        assert!((c.up - camera.up).length() < 1e-5 && (c.right - camera.right).length() < 1e-5);
        assert_eq!(c.yfov, camera.yfov);
    }
}
