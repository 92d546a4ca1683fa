//! The dots engine's grid over a candidate (docs/spec/engagement.md §9 `E_GRID_MEMORY`): its
//! extent and the memory limit it is refused past.

use super::super::bbox_tree::BBox;
use super::super::segments::Route;
use super::super::{MAX_GRID_DOTS, P2};
use crate::error::{ErrorCode, SolverError};

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
pub(super) fn check_grid(
    route: &Route,
    stock_box: BBox,
    anchor: P2,
    radius: f64,
    grid: f64,
) -> Result<f64, SolverError> {
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
