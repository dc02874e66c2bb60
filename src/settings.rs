//! What a user chooses about a render, in one type validated in one place.

use crate::Error;
use glam::Vec3;
use std::path::PathBuf;

/// Veach's four direct-lighting estimators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
#[repr(u32)]
pub enum Strategy {
    /// BSDF sampling only: emission counts when a BSDF-sampled ray hits an emitter.
    Bsdf = 0,
    /// Light sampling only: BSDF rays continue the path but their emitter hits count nothing.
    Light = 1,
    /// One light and one BSDF sample, weighted by the balance heuristic.
    MisBalance = 2,
    /// One light and one BSDF sample, weighted by the power heuristic.
    MisPower = 3,
}

impl Strategy {
    pub const ALL: [Strategy; 4] = [Strategy::Bsdf, Strategy::Light, Strategy::MisBalance, Strategy::MisPower];

    /// The label of contact sheets and the viewer.
    pub fn label(self) -> &'static str {
        match self {
            Strategy::Bsdf => "BSDF",
            Strategy::Light => "LIGHT",
            Strategy::MisBalance => "MIS BALANCE",
            Strategy::MisPower => "MIS POWER",
        }
    }
}

impl TryFrom<u32> for Strategy {
    type Error = Error;
    fn try_from(v: u32) -> Result<Strategy, Error> {
        Strategy::ALL.into_iter().find(|s| *s as u32 == v).ok_or_else(|| Error::Input(format!("no strategy {v}")))
    }
}

/// How the numbers of a path's decisions are generated (`shaders/sampler.wgsl`); the
/// discriminants are the shaders' `SAMPLER_*` ids.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
#[repr(u32)]
pub enum SamplerKind {
    /// Independent uniform numbers (PCG); the default of renders saved before samplers existed.
    #[default]
    Independent = 0,
    /// Owen-scrambled Sobol', padded per 2D pair: lower error at equal spp.
    Sobol = 1,
}

/// How next-event estimation picks an emitter; the discriminants are the shaders'
/// `LIGHT_SAMPLER_*` ids.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
#[repr(u32)]
pub enum LightSampler {
    /// By power alone (an alias table over emissive triangles; punctual lights uniformly, in
    /// an estimate of their own); the default of renders saved before light samplers existed.
    #[default]
    Power = 0,
    /// The light BVH: emitters (triangles, point and spot lights) chosen by their importance
    /// to the shading point (distance, orientation, the surface's tangent plane).
    Tree = 1,
    /// Resampled importance sampling over the tree (the default of `Settings`): at glossy
    /// surfaces, `RIS_CANDIDATES` light samples from the tree, one kept in proportion to its
    /// unshadowed contribution (BSDF and cosine included) for a single shadow ray; elsewhere
    /// the tree's one sample. Best at equal time on every scene measured (BENCHMARKS.md).
    Ris = 2,
}

impl LightSampler {
    pub const ALL: [LightSampler; 3] = [LightSampler::Power, LightSampler::Tree, LightSampler::Ris];

    pub fn label(self) -> &'static str {
        match self {
            LightSampler::Power => "power",
            LightSampler::Tree => "tree",
            LightSampler::Ris => "ris",
        }
    }
}

/// Which engine renders: the WGSL kernel through wgpu, or the CPU reference; `Auto` picks
/// the faster one for this machine (see `Renderer::auto`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Backend {
    Auto,
    Gpu,
    Cpu,
}

/// Where a render's environment comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EnvironmentSource {
    /// `env_map` or `env_color` (the command line's `--env`, `--env-color`), or one set by
    /// `Renderer::set_environment`; `env_color` 0,0,0 keeps a scene without lights black.
    Settings,
    /// The scene's own (its glTF extras), or none when the scene has lights of its own.
    Scene,
    /// The default studio (`assets/studio.hdr`): the scene has no light of any kind.
    Studio,
}

impl EnvironmentSource {
    /// The rule, in one place: an environment given by the user wins; else the scene's own,
    /// unless the scene has no light of any kind (no emitter, no environment): the studio.
    pub fn choose(given: bool, scene: &crate::scene::Environment, scene_has_lights: bool) -> EnvironmentSource {
        if given {
            EnvironmentSource::Settings
        } else if scene_has_lights || !scene.is_black() {
            EnvironmentSource::Scene
        } else {
            EnvironmentSource::Studio
        }
    }

    /// How the command line and the viewer say it.
    pub fn describe(self) -> &'static str {
        match self {
            EnvironmentSource::Settings => "as given",
            EnvironmentSource::Scene => "the scene's",
            EnvironmentSource::Studio => "the default studio (the scene has no lights)",
        }
    }
}

pub use crate::tile::Tile;

/// Samples between two convergence tests of adaptive sampling (`src/adaptive.rs`).
pub const ADAPTIVE_STEP: u32 = 8;

/// Samples every pixel takes before its first test (a multiple of the step): fewer, and the
/// two half estimates of a dark pixel can agree by chance.
pub const DEFAULT_MIN_SAMPLES: u32 = 16;

/// Which AOV layers a render writes (`src/aov.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Aov {
    /// `albedo.R/G/B`: the first visible surface's albedo, in [0, 1].
    Albedo,
    /// `normal.X/Y/Z`: its shading normal in world space, in [−1, 1].
    Normal,
    /// `depth.Z`: its distance from the camera (infinite where nothing was hit).
    Depth,
}

impl Aov {
    pub const ALL: [Aov; 3] = [Aov::Albedo, Aov::Normal, Aov::Depth];

    pub fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
        }
    }
}

/// Largest image side accepted (a GPU texture/dispatch-friendly bound).
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Largest film held in memory (CPU) before asking for tiles.
pub const MAX_FILM_BYTES: u64 = 2 << 30;

/// Everything a user chooses about a render. Saved (with the scene and the sample range, as
/// a [`crate::Job`]) in every EXR veach writes, so renders resume and merge.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Settings {
    /// Camera node name (None: the first camera, else a view framing the scene).
    pub camera: Option<String>,
    pub width: u32,
    pub height: u32,
    /// Longest path in segments (Mitsuba's max_depth); 0: no limit.
    pub max_depth: u32,
    pub seed: u32,
    pub strategy: Strategy,
    /// An equirectangular environment map (.hdr/.exr) replacing the scene's environment.
    pub env_map: Option<PathBuf>,
    /// Constant environment radiance, or the tint of `env_map` (None: the scene's own, or
    /// white under a map).
    pub env_color: Option<[f32; 3]>,
    /// Scales the environment.
    pub env_strength: f32,
    /// The crop window rendered (None: the whole image).
    pub tile: Option<Tile>,
    /// Thin-lens radius in scene units (0: a pinhole camera).
    #[serde(default)]
    pub aperture: f32,
    /// Distance in focus; None with an aperture: what the image centre sees.
    #[serde(default)]
    pub focus_distance: Option<f32>,
    /// Renders saved before samplers existed used independent numbers.
    #[serde(default)]
    pub sampler: SamplerKind,
    /// Renders saved before light samplers existed sampled lights by power.
    #[serde(default)]
    pub light_sampler: LightSampler,
    /// Firefly control (biased; None: off): a sample's contribution of direct light (seen
    /// directly or after one bounce) is scaled so that its R + G + B is at most this, as
    /// Cycles' "clamp direct" does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamp_direct: Option<f32>,
    /// The same limit for indirect light (paths of three segments or more).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamp_indirect: Option<f32>,
    /// Adaptive sampling (None: off): a pixel stops taking samples once the error estimated
    /// from two halves of its samples, relative to the square root of its intensity, is below
    /// this (Cycles' noise threshold; `src/adaptive.rs`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise_threshold: Option<f32>,
    /// Samples every pixel takes before adaptive sampling tests it (None: `adaptive_min_samples()`'s default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_samples: Option<u32>,
    /// AOV layers written with the image (`src/aov.rs`); the film accumulates all three as
    /// soon as one is asked for. Empty: none (the film has no AOV region).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aovs: Vec<Aov>,
    /// The glTF scene rendered, by index (None: the file's default scene).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<usize>,
    /// The KHR_materials_variants variant rendered, by name (None: the default materials).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variant: Option<String>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            camera: None,
            width: 512,
            height: 512,
            max_depth: 8,
            seed: 0,
            strategy: Strategy::MisPower,
            env_map: None,
            env_color: None,
            env_strength: 1.0,
            tile: None,
            aperture: 0.0,
            focus_distance: None,
            sampler: SamplerKind::Sobol,
            light_sampler: LightSampler::Ris,
            clamp_direct: None,
            clamp_indirect: None,
            noise_threshold: None,
            min_samples: None,
            aovs: Vec::new(),
            scene: None,
            variant: None,
        }
    }
}

impl Settings {
    /// Whether the estimate is biased on purpose (firefly clamping).
    pub fn biased(&self) -> bool {
        self.clamp_direct.is_some() || self.clamp_indirect.is_some()
    }

    /// Whether pixels stop sampling on their own (adaptive sampling).
    pub fn adaptive(&self) -> bool {
        self.noise_threshold.is_some()
    }

    /// The film these settings accumulate into: adaptive sampling's regions, the AOVs.
    pub fn film_layout(&self) -> crate::film::FilmLayout {
        crate::film::FilmLayout { adaptive: self.adaptive(), aovs: !self.aovs.is_empty() }
    }

    /// Samples each pixel takes before its first convergence test: as set, else
    /// `DEFAULT_MIN_SAMPLES`; rounded up to a whole number of test steps.
    pub fn adaptive_min_samples(&self) -> u32 {
        let step = ADAPTIVE_STEP;
        self.min_samples.unwrap_or(DEFAULT_MIN_SAMPLES).clamp(step, 1 << 20).next_multiple_of(step)
    }

    /// The window rendered: the tile, or the whole image.
    pub fn window(&self) -> Tile {
        self.tile.unwrap_or(Tile { x: 0, y: 0, width: self.width, height: self.height })
    }

    /// Refuses settings no render can honour, naming the setting.
    pub fn validate(&self) -> Result<(), Error> {
        let (w, h) = (self.width, self.height);
        if w == 0 || h == 0 || w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE {
            return Err(Error::Limit(format!("image size {w}x{h} is outside 1..={MAX_IMAGE_SIDE} per side")));
        }
        let t = self.window();
        if !t.fits(w, h) {
            return Err(Error::Input(format!(
                "tile {},{},{},{} does not fit in the {w}x{h} image",
                t.x, t.y, t.width, t.height
            )));
        }
        let film_bytes = crate::film::Film::bytes(t.width, t.height, self.film_layout());
        if film_bytes > MAX_FILM_BYTES {
            return Err(Error::Limit(format!(
                "a {}x{} film needs {film_bytes} bytes, above veach's limit of {MAX_FILM_BYTES} bytes; render tiles (--tile)",
                t.width, t.height
            )));
        }
        if !self.aperture.is_finite() || self.aperture < 0.0 {
            return Err(Error::Input(format!("aperture {}: expected a finite radius ≥ 0", self.aperture)));
        }
        if let Some(d) = self.focus_distance
            && !(d.is_finite() && d > 0.0)
        {
            return Err(Error::Input(format!("focus distance {d}: expected a finite distance > 0")));
        }
        if !self.env_strength.is_finite() || self.env_strength < 0.0 {
            return Err(Error::Input(format!(
                "environment strength {}: expected a finite value ≥ 0",
                self.env_strength
            )));
        }
        for (name, c) in [("direct clamp", self.clamp_direct), ("indirect clamp", self.clamp_indirect)] {
            if let Some(c) = c
                && !(c.is_finite() && c > 0.0)
            {
                return Err(Error::Input(format!("{name} {c}: expected a finite limit > 0")));
            }
        }
        if let Some(t) = self.noise_threshold
            && !(t.is_finite() && t > 0.0)
        {
            return Err(Error::Input(format!("noise threshold {t}: expected a finite value > 0")));
        }
        if let Some(n) = self.min_samples
            && n > 1 << 20
        {
            return Err(Error::Input(format!("min samples {n}: expected at most {}", 1 << 20)));
        }
        if let Some(c) = self.env_color
            && !c.iter().all(|v| v.is_finite() && *v >= 0.0)
        {
            return Err(Error::Input(format!("environment color {c:?}: expected finite values ≥ 0")));
        }
        Ok(())
    }

    /// Where the environment comes from over a scene whose own is `scene` and which has
    /// (`scene_has_lights`) or has not an emissive surface or punctual light.
    pub fn environment_source(&self, scene: &crate::scene::Environment, scene_has_lights: bool) -> EnvironmentSource {
        EnvironmentSource::choose(self.env_map.is_some() || self.env_color.is_some(), scene, scene_has_lights)
    }

    /// The environment these settings ask for over a scene whose own is `scene`: a map
    /// (loaded here) tinted by the color, a color, the scene's, or the studio when the scene
    /// has no light of any kind; each scaled by the strength.
    pub fn environment(
        &self,
        scene: &crate::scene::Environment,
        scene_has_lights: bool,
    ) -> Result<crate::scene::Environment, Error> {
        let color = self.env_color.map(Vec3::from);
        let mut env = match (&self.env_map, self.environment_source(scene, scene_has_lights)) {
            (Some(path), _) => crate::scene::Environment {
                map: Some(std::sync::Arc::new(crate::scene::EnvironmentMap::load(path)?)),
                radiance: color.unwrap_or(Vec3::ONE),
            },
            (None, EnvironmentSource::Studio) => crate::scene::Environment::studio(),
            (None, _) => {
                crate::scene::Environment { map: scene.map.clone(), radiance: color.unwrap_or(scene.radiance) }
            }
        };
        env.radiance *= self.env_strength;
        Ok(env)
    }
}
