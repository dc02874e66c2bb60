//! The progressive render loop shared by `veach render`, embedders and the tests: samples in
//! chunks sized to a target time, with a sample and time budget, cancellation and a callback
//! after every chunk (progress bars, checkpoints, convergence measurements).

use crate::{Error, Renderer};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Samples per chunk at most: enough to amortise a GPU submission, few enough to stay
/// responsive.
pub const MAX_CHUNK: u32 = 64;

/// Wall time one chunk aims for: responsive to cancellation, few round trips.
pub const CHUNK_SECONDS: f64 = 0.25;

/// How long to render and when to stop.
#[derive(Clone, Copy, Debug, Default)]
pub struct Budget<'a> {
    /// Stop once this much render time is spent (None: render every sample).
    pub time: Option<Duration>,
    /// Set (from a signal handler or another thread) to stop after the chunk in flight.
    pub cancel: Option<&'a AtomicBool>,
    /// Chunks end at every power of two of samples done (for convergence measurements).
    pub stop_at_powers_of_two: bool,
}

/// Where a progressive render stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Samples per pixel accumulated (of this job's range).
    pub done: u32,
    /// Samples per pixel asked for.
    pub total: u32,
    /// Render time so far, callbacks excluded.
    pub seconds: f64,
    /// With adaptive sampling, the fraction of pixels that stopped (the render ends at 1).
    pub converged: Option<f64>,
}

impl Progress {
    /// Every sample taken, or every pixel converged.
    pub fn finished(&self) -> bool {
        self.done >= self.total || self.converged.is_some_and(|c| c >= 1.0)
    }
}

/// What the callback tells the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    Continue,
    Stop,
}

/// Renders sample indices `first + done .. first + total` into `renderer`'s film (which holds
/// the first `done`), calling `after_chunk` after each chunk; its time is not render time.
/// Returns where it stopped: all samples (or every pixel converged), the time budget, a
/// cancel or the callback.
pub fn render_progressive(
    renderer: &mut Renderer,
    first: u32,
    done: u32,
    total: u32,
    budget: Budget<'_>,
    after_chunk: &mut dyn FnMut(&mut Renderer, Progress) -> Result<Control, Error>,
) -> Result<Progress, Error> {
    if first.checked_add(total).is_none() {
        return Err(Error::Input(format!("sample indices {first}+{total} overflow")));
    }
    let t0 = Instant::now();
    let mut outside = Duration::ZERO;
    let mut progress =
        Progress { done: done.min(total), total, seconds: 0.0, converged: renderer.converged_fraction()? };
    let mut chunk = 1u32;
    let cancelled = || budget.cancel.is_some_and(|c| c.load(Ordering::SeqCst));
    let out_of_time = |p: &Progress| budget.time.is_some_and(|t| p.seconds >= t.as_secs_f64());
    while !progress.finished() && !cancelled() && !out_of_time(&progress) {
        let mut n = chunk.min(total - progress.done);
        if budget.stop_at_powers_of_two {
            n = n.min((progress.done + 1).next_power_of_two() - progress.done);
        }
        let t = Instant::now();
        renderer.render_samples(first + progress.done, n)?;
        progress.done += n;
        progress.converged = renderer.converged_fraction()?;
        let secs = t.elapsed().as_secs_f64().max(1e-6);
        chunk = ((n as f64 * CHUNK_SECONDS / secs) as u32).clamp(1, MAX_CHUNK);
        progress.seconds = (t0.elapsed() - outside).as_secs_f64();
        let t = Instant::now();
        let control = after_chunk(renderer, progress)?;
        outside += t.elapsed();
        if control == Control::Stop {
            break;
        }
    }
    progress.seconds = (t0.elapsed() - outside).as_secs_f64();
    Ok(progress)
}
