//! A contour job split into ranges of layers (docs/spec/contour.md §3.9.1, layers): every part
//! validates the request and plans the first layer again, makes the moves of its layers, and
//! hands them on; the finish step plans the first layer once more and answers from every layer's
//! moves in order, as one solve does (the corner reports, passes and warnings come from the
//! first layer, the summary, blocks and cycle time from all the moves).

use serde::{Deserialize, Serialize};

use super::request::MAX_MOVES;
use super::solve::{LayerMoves, Prepared};
use super::{ContourRequest, ContourSolution};
use crate::capability::{Control, Part, PartSink, PartSource, Sizing, Split};
use crate::error::{ErrorCode, SolverError};
use crate::machine::MachineProfile;
use crate::tool::Tool;

/// Core-seconds to plan one corner of one pass of a layer (offsets, corner actions, gouge and
/// stock checks): measured 2.5·10⁻⁵ and 2.8·10⁻⁵ on stars of 100 and 400 corners, two passes,
/// tilted walls (every layer planned), less the layers' moves (docs/guide/performance.md, "Split cost models",
/// `tests/load/cost_model.rs`).
const PLAN_SECONDS: f64 = 2.7e-5;
/// Core-seconds to make one move of a layer from its plan (chording, leads, links): measured
/// 2.1·10⁻⁶ on the same stars, 100 layers.
const MOVE_SECONDS: f64 = 2.1e-6;
/// Core-seconds per move of the finish step (summing, blocks, cycle time, the answer serialised
/// and the program written): measured 3.4·10⁻⁶.
const FINISH_MOVE_SECONDS: f64 = 3.4e-6;

/// The layers of `request` in ranges of about `sizing.part_seconds`; `None` for a refused
/// request (solving it whole reports why) or one part's worth.
pub(crate) fn split(
    request: &ContourRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    sizing: &Sizing,
) -> Option<Split> {
    let prepared = Prepared::new(request, tool, machine, MAX_MOVES, Control::default()).ok()?;
    let plan = (prepared.corners() * prepared.job.passes.len()) as f64 * PLAN_SECONDS;
    let moves = prepared.moves_per_layer() as f64 * MOVE_SECONDS;
    // A tilted wall plans every layer; otherwise each layer repeats the first one's plan.
    let layer = if prepared.job.tilt.is_some() { plan + moves } else { moves };
    let count = prepared.job.layers.len();
    let finish = plan + count as f64 * prepared.moves_per_layer() as f64 * FINISH_MOVE_SECONDS;
    Split::even(0..count, layer, plan, finish, sizing)
}

/// The moves of the layers of `part`.
///
/// # Errors
/// As [`super::solve_with`].
pub(crate) fn solve_part(
    request: &ContourRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    part: &Part,
    control: Control<'_>,
    sink: &mut impl PartSink,
) -> Result<(), SolverError> {
    let prepared = Prepared::new(request, tool, machine, MAX_MOVES, control)?;
    if part.units.end > prepared.job.layers.len() {
        return Err(mismatch(format!("layers {:?} of {}", part.units, prepared.job.layers.len())));
    }
    let layers = prepared.layers(part.units.clone(), control)?;
    sink.put(&PartLayers { from: part.units.start, layers })
}

/// Every part's layers in order, answered as [`super::solve_with`] answers.
///
/// # Errors
/// As [`super::solve_with`]; `E_INTERNAL` when the parts do not make up the request's layers.
pub(crate) fn finish(
    request: &ContourRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    parts: &mut impl PartSource,
    control: Control<'_>,
) -> Result<ContourSolution, SolverError> {
    let prepared = Prepared::new(request, tool, machine, MAX_MOVES, control)?;
    let mut layers = Vec::with_capacity(prepared.job.layers.len());
    let mut read = 0;
    while let Some(part) = parts.next_part::<PartLayers>() {
        let part = part?;
        if part.from != layers.len() {
            return Err(mismatch(format!("a part starts at layer {}, not {}", part.from, layers.len())));
        }
        layers.extend(part.layers);
        read += 1;
        control.report(read, parts.count());
        control.check()?;
    }
    if layers.len() != prepared.job.layers.len() {
        return Err(mismatch(format!("{} layers of {}", layers.len(), prepared.job.layers.len())));
    }
    prepared.answer(machine, MAX_MOVES, layers, control)
}

/// What a part hands on: its first layer's index and its layers' moves.
#[derive(Debug, Serialize, Deserialize)]
struct PartLayers {
    from: usize,
    layers: Vec<LayerMoves>,
}

fn mismatch(detail: String) -> SolverError {
    SolverError::new(ErrorCode::Internal, format!("the parts do not belong to this contour: {detail}"))
}
