//! `Job`: a render as saved in every EXR veach writes (scene, settings, sample range), and the
//! rules by which saved renders resume and merge.

use crate::Error;
use crate::film::Film;
use crate::settings::{Settings, Tile};
use std::path::{Path, PathBuf};

/// Everything that defines a render: resumable from, and mergeable with, other parts.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Job {
    pub scene: PathBuf,
    #[serde(flatten)]
    pub settings: Settings,
    /// Sample indices `sample_start .. sample_end` make up this render.
    pub sample_start: u32,
    pub sample_end: u32,
}

impl Job {
    /// The window rendered: the tile, or the whole image.
    pub fn window(&self) -> Tile {
        self.settings.window()
    }

    /// Samples per pixel this job asks for.
    pub fn spp(&self) -> u32 {
        self.sample_end.saturating_sub(self.sample_start)
    }

    /// Refuses a job no render can honour (a hostile or damaged file's metadata included).
    pub fn validate(&self) -> Result<(), Error> {
        self.settings.validate()?;
        if self.sample_end <= self.sample_start {
            return Err(Error::Input(format!("sample range {}..{} is empty", self.sample_start, self.sample_end)));
        }
        Ok(())
    }

    /// Whether parts of `self` and `other` belong to one image: everything that changes the
    /// image must agree (the window and the sample range may differ). Names what differs.
    pub fn compatible_with(&self, other: &Job) -> Result<(), String> {
        if self.scene != other.scene {
            return Err(format!("the scene differs ({} vs {})", self.scene.display(), other.scene.display()));
        }
        let (a, b) = (&self.settings, &other.settings);
        let bits = |c: Option<f32>| c.map(f32::to_bits);
        let checks: [(&str, bool); 19] = [
            ("camera", a.camera == b.camera),
            ("image size", (a.width, a.height) == (b.width, b.height)),
            ("max depth", a.max_depth == b.max_depth),
            ("seed", a.seed == b.seed),
            ("strategy", a.strategy == b.strategy),
            ("sampler", a.sampler == b.sampler),
            ("light sampler", a.light_sampler == b.light_sampler),
            ("environment map", a.env_map == b.env_map),
            ("environment color", a.env_color == b.env_color),
            ("environment strength", a.env_strength.to_bits() == b.env_strength.to_bits()),
            ("aperture", a.aperture.to_bits() == b.aperture.to_bits()),
            ("focus distance", bits(a.focus_distance) == bits(b.focus_distance)),
            ("direct clamp", bits(a.clamp_direct) == bits(b.clamp_direct)),
            ("indirect clamp", bits(a.clamp_indirect) == bits(b.clamp_indirect)),
            ("noise threshold", bits(a.noise_threshold) == bits(b.noise_threshold)),
            ("adaptive min samples", a.adaptive_min_samples() == b.adaptive_min_samples()),
            ("AOV layers", a.aovs == b.aovs),
            ("glTF scene", a.scene == b.scene),
            ("material variant", a.variant == b.variant),
        ];
        match checks.iter().find(|(_, same)| !same) {
            Some((what, _)) => Err(format!("the {what} differs")),
            None => Ok(()),
        }
    }
}

/// One saved part of a render: its film, its job and the file it came from (for messages).
pub struct Part {
    pub film: Film,
    pub job: Job,
    pub path: PathBuf,
}

/// Merges parts of one render (disjoint sample ranges, tiles, or both) into the film of the
/// whole image, exactly; pixels no part rendered stay empty. Refuses parts of other renders,
/// and parts whose samples overlap in a pixel.
pub fn merge(parts: &[Part]) -> Result<(Film, Job), Error> {
    let Some(first) = parts.first() else {
        return Err(Error::Input("nothing to merge".into()));
    };
    first.job.validate().map_err(|e| Error::Input(format!("{}: {e}", first.path.display())))?;
    let mut job = first.job.clone();
    let (w, h) = (job.settings.width, job.settings.height);
    let layout = crate::film::FilmLayout { adaptive: false, aovs: !job.settings.aovs.is_empty() };
    let mut merged = Film::with_layout(w, h, layout);
    let mut seen: Vec<(Tile, u32, u32, &Path)> = Vec::new();
    for part in parts {
        if part.job.settings.adaptive() {
            return Err(Error::Input(format!(
                "{}: an adaptive render (--noise-threshold) cannot be merged: each pixel stopped where its \
                 own samples converged, so parts do not add up to one render; resume it instead (--resume)",
                part.path.display()
            )));
        }
        part.job.validate().map_err(|e| Error::Input(format!("{}: {e}", part.path.display())))?;
        first.job.compatible_with(&part.job).map_err(|e| {
            Error::Input(format!("{}: not a part of the render of {}: {e}", part.path.display(), first.path.display()))
        })?;
        let window = part.job.window();
        let samples = part.film.samples();
        let (start, end) = (part.job.sample_start, part.job.sample_start.saturating_add(samples));
        for (t, s, e, other) in &seen {
            if t.overlaps(&window) && *s < end && start < *e {
                return Err(Error::Input(format!(
                    "{}: its samples {start}..{end} overlap those of {} in the same pixels",
                    part.path.display(),
                    other.display()
                )));
            }
        }
        for (t, _, _, other) in &seen {
            if t.overlaps(&window) && *t != window {
                return Err(Error::Input(format!(
                    "{}: its tile overlaps that of {} without being the same tile",
                    part.path.display(),
                    other.display()
                )));
            }
        }
        seen.push((window, start, end, &part.path));
        merged
            .merge_at(&part.film, window.x, window.y)
            .map_err(|e| Error::Input(format!("{}: {e}", part.path.display())))?;
    }
    // Every tile's samples must make one range, the same for all tiles: a resumed render
    // continues after the range its job records, so a gap (0..2 and 4..6 recorded as 0..6)
    // would take samples 4 and 5 twice.
    let mut range: Option<(u32, u32)> = None;
    let mut tiles: Vec<Tile> = Vec::new();
    for s in &seen {
        if !tiles.contains(&s.0) {
            tiles.push(s.0);
        }
    }
    for tile in tiles {
        let mut ranges: Vec<(u32, u32, &Path)> = seen.iter().filter(|s| s.0 == tile).map(|s| (s.1, s.2, s.3)).collect();
        ranges.sort_unstable_by_key(|r| r.0);
        for pair in ranges.windows(2) {
            if pair[0].1 != pair[1].0 {
                return Err(Error::Input(format!(
                    "{}: samples {}..{} leave a gap after {}'s {}..{}; merge the missing range too",
                    pair[1].2.display(),
                    pair[1].0,
                    pair[1].1,
                    pair[0].2.display(),
                    pair[0].0,
                    pair[0].1
                )));
            }
        }
        let (first, last) = (ranges[0], ranges[ranges.len() - 1]);
        match range {
            None => range = Some((first.0, last.1)),
            Some(r) if r != (first.0, last.1) => {
                return Err(Error::Input(format!(
                    "{}: its tile has samples {}..{}, another tile {}..{}: every tile must have the same samples",
                    last.2.display(),
                    first.0,
                    last.1,
                    r.0,
                    r.1
                )));
            }
            Some(_) => {}
        }
    }
    if let Some((start, end)) = range {
        (job.sample_start, job.sample_end) = (start, end);
    }
    // The merged film covers the whole image.
    job.settings.tile = None;
    Ok((merged, job))
}
