//! What a render reports of itself (`veach render --stats-json`, Python's `Image.stats`): the
//! keys that follow from the job, the film, the engine and the render loop, built in one place
//! so that every way in reports them alike; each caller adds what only it knows.

use crate::{Film, Job, Progress, Renderer};

impl Progress {
    /// Why the render ended: "samples" (all taken), "converged" (adaptive sampling), "interrupt"
    /// (a signal or cancel: `interrupted`) or "time" (the budget).
    pub fn stopped_by(&self, interrupted: bool) -> &'static str {
        if self.done >= self.total {
            "samples"
        } else if self.converged.is_some_and(|c| c >= 1.0) {
            "converged"
        } else if interrupted {
            "interrupt"
        } else {
            "time"
        }
    }
}

/// The statistics of a render of `job` into `film` by `renderer`, stopped where `progress`
/// says (for the reason `stopped_by`), as a JSON object.
pub fn render_stats(
    job: &Job,
    film: &Film,
    renderer: &Renderer,
    progress: &Progress,
    stopped_by: &str,
) -> serde_json::Value {
    let s = &job.settings;
    serde_json::json!({
        "scene": job.scene.display().to_string(),
        "width": s.width,
        "height": s.height,
        "tile": s.tile,
        "spp": film.samples(),
        "spp_target": job.spp(),
        "mean_spp": film.mean_spp(),
        "noise_threshold": s.noise_threshold,
        "min_samples": s.adaptive().then(|| s.adaptive_min_samples()),
        "converged_fraction": film.converged_fraction(),
        "sample_start": job.sample_start,
        "stopped_by": stopped_by,
        "max_depth": s.max_depth,
        "seed": s.seed,
        "strategy": s.strategy,
        "sampler": s.sampler,
        "light_sampler": s.light_sampler,
        "environment": renderer.environment_source(),
        "clamp_direct": s.clamp_direct,
        "clamp_indirect": s.clamp_indirect,
        "biased": s.biased(),
        "aovs": s.aovs,
        "adapter": renderer.adapter_name(),
        "backend": format!("{:?}", renderer.backend()).to_lowercase(),
        "seconds_render": progress.seconds,
        "nonfinite_samples": film.nonfinite_samples(),
        "gpu_bytes": renderer.gpu_bytes(),
    })
}

/// Adds `more`'s keys to the object `stats`.
pub fn extend_stats(stats: &mut serde_json::Value, more: serde_json::Value) {
    if let (Some(all), serde_json::Value::Object(more)) = (stats.as_object_mut(), more) {
        all.extend(more);
    }
}
