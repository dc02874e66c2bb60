//! The viewer's side panel: statistics, render settings, camera, files.

use super::Viewer;
use super::orbit::Orbit;
use crate::tonemap::Tonemap;
use crate::{LightSampler, Strategy};
use eframe::egui;
use std::path::PathBuf;

/// The aperture slider's range, as a fraction of the scene's extent.
const MAX_APERTURE_EXTENTS: f32 = 0.05;

impl Viewer {
    pub(super) fn side_panel(&mut self, ui: &mut egui::Ui) -> bool {
        let mut changed = false;
        ui.heading("veach");
        let adapter = self.renderer.as_ref().map(|r| r.adapter_name()).unwrap_or_else(|| "no scene".into());
        let engine = format!("{:?}", self.backend.0).to_lowercase();
        ui.label(format!("backend: {engine}, {adapter}")).on_hover_text(&self.backend.1);
        ui.label(format!("samples: {} / {}", self.samples, self.target_spp));
        if let Some(c) = self.converged {
            ui.label(format!("converged: {:.1} % of pixels", 100.0 * c));
        }
        ui.label(format!("{:.2} Msamples/s", self.rate / 1e6));
        ui.label(format!("resolution: {}×{}", self.settings.width, self.settings.height));
        if let Some(p) = &self.scene_path {
            ui.label(format!("scene: {}", p.file_name().map(|n| n.to_string_lossy()).unwrap_or_default()));
        }
        ui.separator();
        ui.checkbox(&mut self.paused, "pause");
        ui.add(egui::Slider::new(&mut self.target_spp, 1..=65536).logarithmic(true).text("target spp"));
        let mut adaptive = self.settings.noise_threshold.is_some();
        let mut threshold = self.settings.noise_threshold.unwrap_or(super::NOISE_THRESHOLD);
        let hint = "adaptive sampling: a pixel stops once its noise, relative to the square root of its \
                    brightness, is below the threshold";
        changed |= ui.checkbox(&mut adaptive, "adaptive sampling").on_hover_text(hint).changed();
        if adaptive {
            changed |= ui
                .add(egui::Slider::new(&mut threshold, 0.002..=0.5).logarithmic(true).text("noise threshold"))
                .changed();
        }
        self.settings.noise_threshold = adaptive.then_some(threshold);
        ui.checkbox(&mut self.heat_map, "show samples per pixel").on_hover_text("a heat map: dark few, bright many");
        let hint = "Open Image Denoise's network, run by veach, whenever the image is still: at 1, 2, 4, ... \
                    samples and when rendering stops";
        if ui.checkbox(&mut self.denoise.on, "denoise").on_hover_text(hint).changed() {
            // The denoiser reads the albedo and normal AOVs: the film gains or loses them.
            self.settings.aovs = if self.denoise.on { super::DENOISER_AOVS.to_vec() } else { Vec::new() };
            changed = true;
        }
        if self.denoise.on {
            let before = self.denoise.quality;
            egui::ComboBox::from_label("denoise quality").selected_text(self.denoise.quality.name()).show_ui(
                ui,
                |ui| {
                    for q in [crate::denoise::Quality::Fast, crate::denoise::Quality::Balanced] {
                        ui.selectable_value(&mut self.denoise.quality, q, q.name());
                    }
                },
            );
            if before != self.denoise.quality {
                self.denoise.result = None;
                self.denoise.next_at = 1;
            }
            let text = match (&self.denoise.result, &self.denoise.job) {
                (_, Some(_)) => "denoising…".to_string(),
                (Some(d), None) => format!("denoised at {} spp in {:.2} s", d.samples, d.seconds),
                (None, None) => "denoised: not yet".to_string(),
            };
            ui.label(text);
        }
        let before = (self.settings.strategy, self.settings.light_sampler, self.settings.max_depth, self.env_strength);
        egui::ComboBox::from_label("strategy").selected_text(format!("{:?}", self.settings.strategy)).show_ui(
            ui,
            |ui| {
                for s in Strategy::ALL {
                    ui.selectable_value(&mut self.settings.strategy, s, format!("{s:?}"));
                }
            },
        );
        egui::ComboBox::from_label("light sampler").selected_text(self.settings.light_sampler.label()).show_ui(
            ui,
            |ui| {
                for s in LightSampler::ALL {
                    ui.selectable_value(&mut self.settings.light_sampler, s, s.label());
                }
            },
        );
        ui.add(egui::Slider::new(&mut self.settings.max_depth, 0..=32).text("max depth (0 = ∞)"));
        ui.add(egui::Slider::new(&mut self.env_strength, 0.0..=10.0).text("environment"));
        match self.environment_source() {
            Some(crate::EnvironmentSource::Studio) => {
                let text = if self.studio { "environment: the default studio" } else { "environment: none" };
                ui.label(text);
                if ui.checkbox(&mut self.studio, "studio light (the scene has no lights)").changed() {
                    self.env_applied = None;
                    changed = true;
                }
            }
            Some(source) => {
                ui.label(format!("environment: {}", source.describe()));
            }
            None => {}
        }
        changed |=
            before != (self.settings.strategy, self.settings.light_sampler, self.settings.max_depth, self.env_strength);
        let max_aperture = MAX_APERTURE_EXTENTS * self.extent;
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
}
