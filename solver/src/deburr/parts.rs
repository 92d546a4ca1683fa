//! A several-loop deburr job split into ranges of its loops (docs/spec/deburr.md §6.3, §7: several
//! holes visited in a short order): every part solves the loops of its range, one per hole and edge in
//! request order, and hands them on; the finish step places the holes again (cheap: no loop is
//! solved) and makes what depends on every loop, as one solve does: the grouping by tool and
//! turn, the visiting order (nearest neighbour and 2-opt over all loops of a group), the `M00`
//! turns and the cycle time.

use serde::{Deserialize, Serialize};

use super::capability::{DeburrAnswer, arrange, hole_answer, inner_tool, solve_loop};
use super::request::{HoleShape, Method};
use super::{Deburr, DeburrRequest};
use crate::capability::{Part, PartSink, PartSource, Resolved, Run, Sizing, Split};
use crate::error::{ErrorCode, SolverError};
use crate::tool::Tool;

/// Core-seconds of one loop besides its points (validation, profile, leads, checks) and per
/// point, by method: fitted to loops of 32, 64 and 164 points (tangent 0.33, 0.83 and 2.0 ms;
/// exact 1.2, 2.0 and 3.0 ms; docs/guide/performance.md, "Split cost models", `tests/load/cost_model.rs`).
const TANGENT_LOOP_SECONDS: f64 = 5.0e-5;
/// See [`TANGENT_LOOP_SECONDS`].
const EXACT_LOOP_SECONDS: f64 = 7.0e-4;
/// See [`TANGENT_LOOP_SECONDS`].
const TANGENT_POINT_SECONDS: f64 = 1.25e-5;
/// See [`TANGENT_LOOP_SECONDS`].
const EXACT_POINT_SECONDS: f64 = 1.4e-5;
/// Core-seconds of the finish step per pair of loops (the visiting order's travel matrix) and per
/// point (cycle time, the answer serialised and the program written): 60 loops of 1 920 and
/// 9 840 points took 0.03 and 0.09 s.
const FINISH_PAIR_SECONDS: f64 = 4.0e-6;
/// See [`FINISH_PAIR_SECONDS`].
const FINISH_POINT_SECONDS: f64 = 7.5e-6;

/// The loops of a several-loop request in ranges of about `sizing.part_seconds`; `None` for a
/// single loop, a refused request (solving it whole reports why) or one part's worth.
pub(crate) fn split(request: &DeburrRequest, sizing: &Sizing) -> Option<Split> {
    if !request.is_several() {
        return None;
    }
    let placements = request.placements().ok()?;
    let points: Vec<f64> = placements.iter().map(|placement| estimated_points(&placement.request)).collect();
    let costs: Vec<f64> = placements.iter().zip(&points).map(|(p, &n)| loop_seconds(&p.request, n)).collect();
    let count = costs.len();
    let finish = (count * count) as f64 * FINISH_PAIR_SECONDS + points.iter().sum::<f64>() * FINISH_POINT_SECONDS;
    // Placing the holes is all a part repeats besides its loops: no setup worth counting.
    let mean = costs.iter().sum::<f64>() / count.max(1) as f64;
    let mut split = Split::even(0..count, mean, 0.0, finish, sizing)?;
    for part in &mut split.parts {
        part.seconds = costs[part.units.clone()].iter().sum();
    }
    Some(split)
}

/// The loops of `part`, solved as one solve solves each.
///
/// # Errors
/// As the whole solve, for the loops of the part; `E_INTERNAL` for a range outside the loops.
pub(crate) fn solve_part(
    request: &DeburrRequest,
    context: &Resolved<Tool>,
    part: &Part,
    run: &Run<'_>,
    sink: &mut impl PartSink,
) -> Result<(), SolverError> {
    let placements = request.placements()?;
    let count = placements.len();
    let placements =
        placements.get(part.units.clone()).ok_or_else(|| mismatch(format!("loops {:?} of {count}", part.units)))?;
    let inner_tool = inner_tool(request, context);
    let mut loops = Vec::with_capacity(placements.len());
    for (index, placement) in placements.iter().enumerate() {
        run.control.check()?;
        run.control.report(index, placements.len());
        loops.push(PartLoop::from(solve_loop(placement, context, inner_tool.as_ref(), run)?));
    }
    sink.put(&PartLoops { from: part.units.start, loops })
}

/// Every part's loops in request order, arranged as one solve arranges them.
///
/// # Errors
/// As the whole solve's placing of the holes; `E_INTERNAL` when the parts do not make up the
/// request's loops.
pub(crate) fn finish(
    request: &DeburrRequest,
    context: Resolved<Tool>,
    parts: &mut impl PartSource,
    run: &Run<'_>,
) -> Result<DeburrAnswer, SolverError> {
    let mut placements = request.placements()?.into_iter();
    let count = placements.len();
    let mut loops = Vec::with_capacity(count);
    let mut read = 0;
    while let Some(part) = parts.next_part::<PartLoops>() {
        let part = part?;
        if part.from != loops.len() {
            return Err(mismatch(format!("a part starts at loop {}, not {}", part.from, loops.len())));
        }
        for result in part.loops {
            let placement = placements.next().ok_or_else(|| mismatch(format!("more than {count} loops")))?;
            let result = result.into();
            super::capability::charge_loop(run, &result, loops.len(), count)?;
            loops.push(hole_answer(placement, result));
        }
        read += 1;
        run.control.report(read, parts.count());
        run.control.check()?;
    }
    if loops.len() != count || loops.is_empty() {
        return Err(mismatch(format!("{} loops of {count}", loops.len())));
    }
    let inner_tool = inner_tool(request, &context);
    Ok(arrange(context, inner_tool, loops))
}

/// The points of a loop, estimated as those of a round hole of its radius at its tolerance:
/// chords of sagitta TA on a circle of radius r are √(8·r·TA) long; a slot or rounded rectangle
/// adds its straight sides, a point at each end.
fn estimated_points(request: &DeburrRequest) -> f64 {
    let Some(hole) = &request.hole else { return 0.0 };
    let tolerance = request.tolerance.unwrap_or(super::request::DEFAULT_TOLERANCE).max(1e-6);
    let radius = hole.size("hole").map_or(0.0, |size| size.radius()).abs().max(1e-3);
    let arcs = std::f64::consts::TAU * radius / (8.0 * radius * tolerance).sqrt();
    let sides = match hole.shape {
        HoleShape::Round => 0.0,
        HoleShape::Slot => 4.0,
        HoleShape::RoundedRect => 8.0,
    };
    (arcs + sides).ceil()
}

/// The estimated core-seconds of a loop of `points` points.
fn loop_seconds(request: &DeburrRequest, points: f64) -> f64 {
    match request.method {
        Method::Tangent => TANGENT_LOOP_SECONDS + points * TANGENT_POINT_SECONDS,
        Method::Exact => EXACT_LOOP_SECONDS + points * EXACT_POINT_SECONDS,
    }
}

/// What a part hands on: its first loop's index and its loops.
#[derive(Debug, Serialize, Deserialize)]
struct PartLoops {
    from: usize,
    loops: Vec<PartLoop>,
}

/// A loop as a part hands it on: the answer's fields and those the program needs besides.
#[derive(Debug, Serialize, Deserialize)]
struct PartLoop {
    result: Deburr,
    /// Why its program cannot be written: code, field, message.
    blocker: Option<(ErrorCode, Option<String>, String)>,
    description: Vec<String>,
    ball_radius: f64,
}

impl From<Deburr> for PartLoop {
    fn from(mut result: Deburr) -> Self {
        let blocker = result
            .program_blocker
            .take()
            .map(|error| (error.code(), error.field().map(str::to_owned), error.message().to_owned()));
        let description = std::mem::take(&mut result.description);
        Self { ball_radius: result.ball_radius, result, blocker, description }
    }
}

impl From<PartLoop> for Deburr {
    fn from(part: PartLoop) -> Self {
        let PartLoop { mut result, blocker, description, ball_radius } = part;
        result.program_blocker = blocker.map(|(code, field, message)| {
            let error = SolverError::new(code, message);
            match field {
                Some(field) => error.at(field),
                None => error,
            }
        });
        result.description = description;
        result.ball_radius = ball_radius;
        result
    }
}

/// `E_INTERNAL`: the parts handed to the finish step are not this request's.
fn mismatch(detail: String) -> SolverError {
    SolverError::new(ErrorCode::Internal, format!("the parts do not belong to this deburring: {detail}"))
}
