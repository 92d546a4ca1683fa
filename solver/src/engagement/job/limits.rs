//! The work limits of a validated request (docs/spec/engagement.md §9 `E_GRID_MEMORY`,
//! `E_WORK_LIMIT`, `E_TOO_MANY_SAMPLES`): the dots engine's grid over each candidate and its
//! memory, the rows it scans and the chords of earlier cuts it rasterises, and the exact engine's
//! edge tests against a bitmap stock.

use super::super::bbox_tree::BBox;
use super::super::request::Engine;
use super::super::segments::Route;
use super::super::stock::Base;
use super::super::{MAX_BITMAP_CROSSINGS, MAX_CHORDS, MAX_DOT_ROWS, MAX_GRID_DOTS, P2};
use super::Job;
use crate::error::{ErrorCode, SolverError};

/// Refuses a job whose engine would do more work than its limits allow; `total_samples` and
/// `section_radii` as the candidates' validation counted them.
pub(super) fn check_work(job: &Job, total_samples: f64, section_radii: f64) -> Result<(), SolverError> {
    let (region, radius, step) = (&job.region, job.radius, job.step);
    if let Some(g) = job.grid {
        // The dots engine rasterises earlier cuts' arcs as chords within g/100.
        let chords: f64 =
            region.cuts.iter().flat_map(|cut| cut.shapes.iter()).map(|shape| shape.chord_count(g / 100.0)).sum();
        if chords > MAX_CHORDS {
            return Err(SolverError::new(
                ErrorCode::WorkLimit,
                format!(
                    "the earlier cuts' arcs need {chords:.2e} chords at grid {g} mm; the limit is {MAX_CHORDS:.0e}: use a larger grid or engine \"exact\""
                ),
            )
            .at("stock.previous_cuts"));
        }
    }
    if let (Some(g), Some(stock_box)) = (job.grid, region.bbox()) {
        let mut rows = 0.0;
        for candidate in &job.candidates {
            let height = check_grid(&candidate.route, stock_box, region.anchor(), radius, g)?;
            // Each sample scans the grid rows across the tool.
            rows += candidate.route.station_count(step) * (2.0 * radius / g).min(height);
        }
        if rows > MAX_DOT_ROWS {
            return Err(SolverError::new(
                ErrorCode::WorkLimit,
                format!(
                    "the dots engine would scan about {rows:.2e} grid rows (samples × rows across the tool); the limit is {MAX_DOT_ROWS:.0e}: use a larger grid or step, or engine \"exact\""
                ),
            )
            .at("grid"));
        }
    }
    if let (Engine::Exact, Base::Bitmap(bitmap)) = (job.engine, &region.base) {
        // Every sample intersects the circle with about 8R/cell cell edges, and the height
        // sections of a rounded end their own circles.
        let work = total_samples * 8.0 * (radius + section_radii) / bitmap.cell;
        if work > MAX_BITMAP_CROSSINGS {
            return Err(SolverError::new(
                ErrorCode::TooManySamples,
                format!(
                    "a bitmap with cell {} mm seen by a tool of radius {radius} mm needs about {work:.2e} edge tests over the samples; the limit is {:.0e}: use a larger step, a coarser bitmap or engine \"dots\"",
                    bitmap.cell,
                    MAX_BITMAP_CROSSINGS
                ),
            )
            .at("step"));
        }
    }
    Ok(())
}

/// The dot grid of a candidate: the stock's box cut to where the tool can reach, in cells of
/// `grid`; refused past [`MAX_GRID_DOTS`] (docs/spec/engagement.md §9 `W_GRID_MEMORY`: refuse).
/// Dots sit at `anchor` + (i + ½, j + ½)·`grid` (the bitmap's origin, so its cells and the dots
/// line up).
pub(crate) fn grid_extent(
    route: &Route,
    stock_box: BBox,
    anchor: P2,
    radius: f64,
    grid: f64,
) -> Option<(P2, u64, u64)> {
    let reach = route.bbox()?.grown(radius * (1.0 + 1e-9) + grid);
    let area = reach.intersection(&stock_box.grown(grid))?;
    let origin = P2::new(
        anchor.x + ((area.min.x - anchor.x) / grid).floor() * grid,
        anchor.y + ((area.min.y - anchor.y) / grid).floor() * grid,
    );
    let width = ((area.max.x - origin.x) / grid).ceil().max(1.0);
    let height = ((area.max.y - origin.y) / grid).ceil().max(1.0);
    // Saturating: sizes far past the limit are refused by the caller anyway.
    Some((origin, width.min(1e18) as u64, height.min(1e18) as u64))
}

/// Refuses a grid past the memory limit; the grid's height in rows otherwise.
fn check_grid(route: &Route, stock_box: BBox, anchor: P2, radius: f64, grid: f64) -> Result<f64, SolverError> {
    if let Some((_, width, height)) = grid_extent(route, stock_box, anchor, radius, grid) {
        let dots = (width as f64) * (height as f64);
        if dots > MAX_GRID_DOTS as f64 {
            return Err(SolverError::new(
                ErrorCode::GridMemory,
                format!(
                    "the dot grid would need {dots:.3e} dots ({width} × {height} at grid {grid} mm, {:.0} MB); the limit is {MAX_GRID_DOTS} dots ({} MB): use a larger grid",
                    dots / 8.0 / 1e6,
                    MAX_GRID_DOTS / 8 / 1_000_000
                ),
            )
            .at("grid"));
        }
        return Ok(height as f64);
    }
    Ok(0.0)
}
