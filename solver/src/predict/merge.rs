//! Merging near-identical consecutive passes (docs/spec/predict.md §3.2, "successive lines ... may
//! be merged", §0051): long finishing programs repeat the same cut pass after
//! pass, so only some of them are simulated and the others carry the result of the nearest
//! simulated one, with a bound on how much that can differ from simulating them.
//!
//! Two consecutive passes are *similar* when they run on from each other with the same feed,
//! spindle speed and sense, their lengths and directions agree within the tolerance τ (the
//! direction times R, the far side of the ball), and they see the same neighbourhood within τ:
//! the nearby motion relative to the ball centre (the pieces of T1 and T2 the prediction uses,
//! piece by piece) and the stock's top over the ball's square (81 heights relative to the ball
//! centre). Box, plane and height-grid stocks have a top; on cylinder and mesh stocks nothing is
//! merged.
//!
//! In a run of similar passes the ends and every [`STRIDE`]-th pass are simulated. Between two
//! neighbouring simulated passes a and b the passes are merged when both are `ok` with the same
//! flags and |e_a − e_b| ≤ τ; otherwise the middle one is simulated too, and so on down to
//! neighbours. A merged pass copies the nearer simulated pass (position along the pass, the
//! generation point and normal relative to its own ball centre, the errors) and reports
//! `merge_bound` = |e_a − e_b| + 2·r, r = (Δ/R)·(max |dδ/dθ| + |D|) + (how far e_D moves over
//! the rotation angles ψ_c takes within Δ): its error lies between e_a and e_b when the error
//! changes monotonically over the gap, up to the resolution r of each of the two predictions, the
//! one carried over and the one simulating the pass would give (the generation point is found to
//! about one sample spacing Δ, see [`Resolution`]; where it falls on the sample grid changes from
//! pass to pass, and with it ψ_c and the deflection there). The
//! similar neighbourhoods make that the expected case: a local feature between them changes the
//! neighbourhood and ends the run. It is not a proof for every input: a feature smaller than the
//! 81-point stock pattern, or an error that rises and falls back between two simulated passes,
//! can escape it.

use super::answer::PassStatus;
use super::job::Job;
use super::passes::PathModel;
use super::pipeline::Outcome;
use super::scene::{self, Piece, Scratch, Side};
use crate::geometry::Vec3;
use crate::stock::StockModel;

/// Simulated passes are at most this many passes apart in a run.
pub(crate) const STRIDE: usize = 16;
/// Stock heights per side of the ball's square.
const HEIGHTS: usize = 9;

/// What a pass sees, relative to its ball centre at the middle of the pass.
#[derive(Debug, Clone, Default)]
pub(crate) struct Neighbourhood {
    pieces: Vec<(Vec3, Vec3, Side)>,
    /// Stock top minus the centre's z at the pattern points (`NaN` outside the footprint).
    tops: Vec<f64>,
    length: f64,
    direction: Vec3,
    conditions: [f64; 3],
}

/// The stock's top over (x, y) for the stocks that are height fields (`NaN` outside the
/// footprint); `None` for the others.
fn top(stock: &StockModel, x: f64, y: f64) -> Option<f64> {
    let inside = |lo: [f64; 2], hi: [f64; 2]| x > lo[0] && x < hi[0] && y > lo[1] && y < hi[1];
    match stock {
        StockModel::Box { lo, hi } => Some(if inside([lo.x, lo.y], [hi.x, hi.y]) { hi.z } else { f64::NAN }),
        StockModel::Plane { point, normal, lo, hi } => Some(if inside(*lo, *hi) {
            point.z - ((x - point.x) * normal.x + (y - point.y) * normal.y) / normal.z
        } else {
            f64::NAN
        }),
        StockModel::Grid(grid) => Some(grid.top_at(x, y).unwrap_or(f64::NAN)),
        StockModel::Cylinder { .. } | StockModel::Mesh(_) => None,
    }
}

/// The stock's bottom, if any.
fn bottom(stock: &StockModel) -> f64 {
    match stock {
        StockModel::Box { lo, .. } => lo.z,
        StockModel::Grid(grid) => grid.bottom(),
        _ => f64::NEG_INFINITY,
    }
}

/// The neighbourhood of pass `index`, `None` where merging does not apply (a stock without a
/// top, an empty pass).
pub(crate) fn neighbourhood(
    job: &Job,
    path: &PathModel,
    index: usize,
    scratch: &mut Scratch,
    out: &mut Neighbourhood,
) -> bool {
    let radius = job.radius;
    let pass = path.passes[index];
    let segment = path.segments[pass.segment];
    if segment.length <= 0.0 {
        return false;
    }
    let (start, end) = path.ends(pass.segment);
    let direction = (end - start) / segment.length;
    let centre = start + 0.5 * segment.length * direction;
    let source = pass.source;
    let tooth_feed = source.feed / (source.spindle_rpm * job.flutes as f64);
    let mut pieces: Vec<Piece> = Vec::new();
    scene::gather(
        path,
        &scene::Query {
            centre,
            sigma: segment.sigma + 0.5 * segment.length,
            gap: job.tooth_feed_gap * tooth_feed,
            radius,
            reach: 2.0 * radius,
            any_view: false,
            order: scene::PieceOrder::Path,
            stock_top: f64::INFINITY,
        },
        scratch,
        &mut pieces,
    );
    out.pieces.clear();
    out.pieces.extend(pieces.iter().map(|p| (p.a - centre, p.b - centre, p.side)));
    out.tops.clear();
    for j in 0..HEIGHTS {
        for i in 0..HEIGHTS {
            let offset = |k: usize| radius * (2.0 * k as f64 / (HEIGHTS - 1) as f64 - 1.0);
            let Some(height) = top(&job.stock, centre.x + offset(i), centre.y + offset(j)) else {
                return false;
            };
            out.tops.push(height - centre.z);
        }
    }
    // A bottom more than 2R below the centre is out of the ball's reach.
    out.tops.push((bottom(&job.stock) - centre.z).max(-2.0 * radius));
    out.length = segment.length;
    out.direction = direction;
    out.conditions = [source.feed, source.spindle_rpm, source.rotation_sign];
    true
}

/// Whether pass `b` (= `a` + 1) runs on from `a` and sees the same neighbourhood within
/// `tolerance`.
pub(crate) fn similar(
    path: &PathModel,
    a: usize,
    first: &Neighbourhood,
    second: &Neighbourhood,
    radius: f64,
    tolerance: f64,
) -> bool {
    let (sa, sb) = (path.passes[a].segment, path.passes[a + 1].segment);
    if sb != sa + 1 || path.segments[sb].start_node != path.segments[sa].end_node {
        return false;
    }
    let close = |p: &Vec3, q: &Vec3| (p - q).amax() <= tolerance;
    first.conditions == second.conditions
        && (first.length - second.length).abs() <= tolerance
        && radius * (first.direction - second.direction).amax() <= tolerance
        && first.pieces.len() == second.pieces.len()
        && first.pieces.iter().zip(&second.pieces).all(|(p, q)| p.2 == q.2 && close(&p.0, &q.0) && close(&p.1, &q.1))
        && first.tops.len() == second.tops.len()
        && first
            .tops
            .iter()
            .zip(&second.tops)
            .all(|(p, q)| (p.is_nan() && q.is_nan()) || (!p.is_nan() && !q.is_nan() && (p - q).abs() <= tolerance))
}

/// How finely one prediction resolves the error: the generation point is located to about one
/// sample spacing Δ (the pixel), so θ_c and the normal to about Δ/R, and e to about
/// (Δ/R)·(max |dδ/dθ| + |D|) plus how far e_D moves over the rotation angles that spans (each
/// simulated pass's `deflection_spread`). Passes whose neighbourhoods agree within τ ≤ Δ can
/// differ by that much even when the error does not change along the run (coordinates rounded
/// by the post).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Resolution {
    /// Δ/R, rad.
    pub(crate) angle: f64,
    /// Largest |dδ/dθ| of the shape-error table, mm/rad.
    pub(crate) shape_slope: f64,
}

impl Resolution {
    pub(crate) fn new(job: &Job) -> Self {
        let shape_slope = job
            .shape_error
            .windows(2)
            .map(|w| (w[1].error - w[0].error).abs() / (w[1].angle_deg - w[0].angle_deg).to_radians())
            .filter(|s| s.is_finite())
            .fold(0.0, f64::max);
        Self { angle: 2.0 / f64::from(job.resolution), shape_slope }
    }
}

/// Whether the passes between two simulated ones can take their results, and the bound on the
/// difference: the spread |e_a − e_b| plus the resolution of each of the two predictions.
fn agree(a: &Outcome, b: &Outcome, tolerance: f64, resolution: Resolution) -> Option<f64> {
    if a.status != PassStatus::Ok || b.status != PassStatus::Ok || a.flags != b.flags {
        return None;
    }
    let spread = (a.error? - b.error?).abs();
    let deflection = |o: &Outcome| o.deflection.map_or(0.0, |d| d[0].hypot(d[1]));
    let deflection_spread = |o: &Outcome| o.deflection_spread.unwrap_or(0.0);
    let floor = resolution.angle * (resolution.shape_slope + deflection(a).max(deflection(b)))
        + deflection_spread(a).max(deflection_spread(b));
    (spread <= tolerance).then_some(spread + 2.0 * floor)
}

/// Simulates the passes `indices` (consecutive pass indices; `links[k]` joins `indices[k]` and
/// the next one) with merging: `simulate` predicts a batch of passes in order. Returns the
/// outcomes in order and the number of merged passes.
pub(crate) fn run(
    path: &PathModel,
    indices: &[usize],
    links: &[bool],
    tolerance: f64,
    resolution: Resolution,
    mut simulate: impl FnMut(&[usize]) -> Option<Vec<Outcome>>,
) -> Option<(Vec<Outcome>, usize)> {
    let count = indices.len();
    // Runs of linked passes, as positions [first, last] in `indices`.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut first = 0;
    for k in 0..count {
        if links.get(k).is_none_or(|linked| !linked) {
            runs.push((first, k));
            first = k + 1;
        }
    }
    let mut outcomes: Vec<Option<Outcome>> = vec![None; count];
    let mut batch: Vec<usize> = Vec::new();
    for &(first, last) in &runs {
        batch.extend((first..=last).step_by(STRIDE));
        if (last - first) % STRIDE != 0 {
            batch.push(last);
        }
    }
    // Simulate, then the middles of the gaps whose ends disagree, down to neighbours.
    while !batch.is_empty() {
        let passes: Vec<usize> = batch.iter().map(|&k| indices[k]).collect();
        for (k, outcome) in batch.iter().zip(simulate(&passes)?) {
            outcomes[*k] = Some(outcome);
        }
        batch.clear();
        for &(first, last) in &runs {
            let mut a = first;
            for b in first + 1..=last {
                let Some(ends) = outcomes[b].as_ref() else { continue };
                let start = outcomes[a].as_ref().expect("a run's simulated passes come in order");
                if b > a + 1 && agree(start, ends, tolerance, resolution).is_none() {
                    batch.push((a + b) / 2);
                }
                a = b;
            }
        }
    }
    // Fill the agreeing gaps from the nearer end.
    let mut merged = 0;
    for &(first, last) in &runs {
        let mut a = first;
        for b in first + 1..=last {
            if outcomes[b].is_none() {
                continue;
            }
            if b > a + 1 {
                let (start, end) = (outcomes[a].clone()?, outcomes[b].clone()?);
                let bound = agree(&start, &end, tolerance, resolution)?;
                for k in a + 1..b {
                    let (source, from) = if k - a <= b - k { (&start, a) } else { (&end, b) };
                    outcomes[k] = Some(moved(path, source, indices[from], indices[k], bound));
                    merged += 1;
                }
            }
            a = b;
        }
    }
    Some((outcomes.into_iter().collect::<Option<Vec<_>>>()?, merged))
}

/// The outcome of simulated pass `from` carried over to pass `to`: the same position along the
/// pass, the generation point and normal relative to the ball centre, the same errors.
fn moved(path: &PathModel, source: &Outcome, from: usize, to: usize, bound: f64) -> Outcome {
    let mut outcome = source.clone();
    let segment = path.passes[to].segment;
    let (start, end) = path.ends(segment);
    let length = path.segments[segment].length;
    if let (Some(s), Some(old)) = (source.position, source.centre) {
        let centre = start + s.min(length) / length * (end - start);
        outcome.centre = Some(centre);
        outcome.point = source.point.map(|p| p - old + centre);
    }
    outcome.history = None;
    outcome.merged_with = Some(from);
    outcome.merge_bound = Some(bound);
    outcome
}
