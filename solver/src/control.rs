//! Progress reporting and cancellation of a long run: the `Control` every solver loop, program
//! writer and G-code reader checks (docs/spec/api.md, Errors).

use std::sync::atomic::AtomicBool;

use crate::error::SolverError;
use crate::error_code::ErrorCode;

/// Progress reporting and cancellation for long runs.
#[derive(Clone, Copy, Default)]
pub struct Control<'a> {
    /// Called with the fraction done (0–1), from worker threads, about every 0.5 %.
    pub progress: Option<&'a (dyn Fn(f64) + Sync)>,
    /// Set to stop: the run ends with `E_CANCELLED`.
    pub cancel: Option<&'a AtomicBool>,
}

impl Control<'_> {
    /// `Err(E_CANCELLED)` once the cancel flag is set. The solvers call it once per unit of work
    /// (a block, a centre, a layer, a sample row), so a timed-out or abandoned request frees its
    /// solver slot within milliseconds instead of running to the end.
    ///
    /// # Errors
    /// `E_CANCELLED` when cancelled.
    pub fn check(&self) -> Result<(), SolverError> {
        if self.cancelled() {
            return Err(SolverError::new(ErrorCode::Cancelled, "the computation was cancelled"));
        }
        Ok(())
    }

    /// [`Control::check`] at every 1 024th of many small units of work (an edge, a corner, a
    /// move), `index` counting them: often enough to stop within milliseconds, rarely enough that
    /// the flag's load costs nothing.
    ///
    /// # Errors
    /// `E_CANCELLED` when cancelled and `index` is a multiple of 1 024.
    pub fn check_at(&self, index: usize) -> Result<(), SolverError> {
        if index.is_multiple_of(1024) { self.check() } else { Ok(()) }
    }

    /// Whether the cancel flag is set.
    #[must_use]
    pub fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|flag| flag.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// Reports `done` of `total` units of work (a layer, a block, a sample) finished, only every
    /// `total / 200` units so a per-sample call stays cheap.
    pub fn report(&self, done: usize, total: usize) {
        let Some(progress) = self.progress else { return };
        if total == 0 {
            return;
        }
        let every = (total / 200).max(1);
        if done.is_multiple_of(every) || done >= total {
            progress((done as f64 / total as f64).min(1.0));
        }
    }

    /// Reports the fraction done where the work is not counted in units (along a curve).
    pub fn report_fraction(&self, fraction: f64) {
        if let Some(progress) = self.progress {
            progress(fraction.clamp(0.0, 1.0));
        }
    }

    /// Runs `work` as part `index` of `count` equal parts of this run: its progress 0–1 is
    /// reported as `(index + fraction) / count` (the candidates of a comparison, say).
    pub fn part<T>(&self, index: usize, count: usize, work: impl FnOnce(Control<'_>) -> T) -> T {
        let Some(progress) = self.progress else { return work(*self) };
        let scaled = move |fraction: f64| progress((index as f64 + fraction) / count.max(1) as f64);
        work(Control { progress: Some(&scaled), cancel: self.cancel })
    }
}

impl std::fmt::Debug for Control<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Control").field("progress", &self.progress.is_some()).field("cancel", &self.cancel).finish()
    }
}
