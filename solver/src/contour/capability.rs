//! Contour milling as a capability (the seam of engineering.md): `POST /api/v1/contour`, job
//! operation `contour`; and the loops added to a path made elsewhere (`POST
//! /api/v1/contour/loops`, docs/spec/contour.md §3.4), which answers JSON only and is no job operation.

use crate::error::ErrorCode;
use serde::{Deserialize, Serialize};

use super::answer::{ArcSpan, ContourMove};
use super::detect::{self, DetectMode, MaterialSide, PathLoopAnswer, PathLoopRequest};
use super::request::MAX_MOVES;
use super::solve::LayerMoves;
use super::{ContourRequest, ContourSolution, CornerLoop};
use crate::capability::{
    Capability, Control, Endpoint, OutputOptions, Part, PartSink, PartSource, Purpose, Refs, Resolved, Run, Sizing,
    Split,
};
use crate::error::{SolverError, Warning};
use crate::machine::MachineProfile;
use crate::tool::{Tool, ToolRef};
use crate::verify::Verification;
use crate::verify::own::{self, OwnModel, Prism};

/// Most moves in a JSON answer (about 35 MB of JSON). A G-code program and a job may hold up to
/// the solver's own limit, [`MAX_MOVES`].
pub const MAX_JSON_MOVES: usize = 500_000;

/// The contour capability.
#[derive(Debug, Clone, Copy)]
pub struct ContourCapability;

/// The contour answer: the tool used and the solver's result.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourAnswer {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// The machine the request named, as registered: its block time (and margin, minimum chord
    /// error) chorded the arcs, its dialect is the G-code default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// Layers with their moves, corners, passes, summary and warnings.
    #[serde(flatten)]
    pub result: ContourSolution,
    /// The program cut on the contour's own model (docs/spec/verify.md §9): the stock band and
    /// the part prism. Absent when the request turns verification off, and for tilted walls
    /// (no 3-axis program).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<Verification>,
}

/// Most bytes of one move in memory: the move, its boxed axis (tilted walls) and at most one arc
/// span.
const MOVE_BYTES: u64 = (std::mem::size_of::<ContourMove>() + AXIS_BYTES + std::mem::size_of::<ArcSpan>()) as u64;

/// Bytes of a move's boxed tool axis.
const AXIS_BYTES: usize = std::mem::size_of::<[f64; 3]>();

/// Most bytes one move takes as JSON: `{"kind":"rapid","to":[x,y,z],"feed":f,"axis":[a,b,c]},`
/// with its seven numbers at their longest (24 characters; checked by
/// `move_json_is_within_its_bound`).
const MOVE_JSON_BYTES: u64 = 256;

/// Most bytes one move takes in a program: one `G01`/`G02` line with three coordinates and an
/// arc centre of up to `-1000000.0000` (the coordinate range) and a feed word.
const MOVE_PROGRAM_BYTES: u64 = 128;

/// Most bytes of one corner's or pass's report as JSON (its loop, relief, material, warnings).
const REPORT_BYTES: u64 = 16 * 1024;

/// Most bytes of an answer besides its moves and reports: tool, machine, summary.
const ANSWER_BYTES: u64 = 256 * 1024;

/// Most bytes one move takes for `purpose` (see [`layer_bytes`]): in memory and as JSON, in
/// memory and as a program line, or for a job as JSON and a program line.
fn move_bound(purpose: Purpose) -> u64 {
    match purpose {
        Purpose::Json => MOVE_BYTES + MOVE_JSON_BYTES,
        Purpose::Program => MOVE_BYTES + MOVE_PROGRAM_BYTES,
        Purpose::Job => MOVE_JSON_BYTES + MOVE_PROGRAM_BYTES,
    }
}

/// The bytes the layer made is charged for `purpose`, what the answer's delivery is later
/// checked on, counted as it is built: for JSON its moves in memory and their JSON as written
/// (counted, not kept); for a program its moves in memory (the program itself is checked whole
/// once written); for a job the JSON it stores (the program is checked beside it once written:
/// the moves' memory is not counted, as the stored result and program are what a job's budget
/// holds).
fn layer_bytes(layer: &LayerMoves, purpose: Purpose) -> u64 {
    let axes = layer.moves.iter().filter(|step| step.axis.is_some()).count();
    let memory = (layer.moves.len() * std::mem::size_of::<ContourMove>()
        + axes * AXIS_BYTES
        + layer.arcs.len() * std::mem::size_of::<ArcSpan>()) as u64;
    let json = || crate::capability::json_bytes(&layer.moves) + LAYER_JSON_BYTES;
    match purpose {
        Purpose::Json => memory + json(),
        Purpose::Program => memory,
        Purpose::Job => json(),
    }
}

/// Most bytes of a layer's JSON besides its moves: `{"z":…,"moves":[…]},`.
const LAYER_JSON_BYTES: u64 = 64;

impl Capability for ContourCapability {
    const NAME: &'static str = "contour";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Layered contour milling: the tool-centre path of every layer with corner loops at \
            protruding corners and optional relief at inside corners.",
        description: "Returns the layers' moves, the corners with their actions and the material left or cut \
            (JSON, at most 500 000 moves), or with `Accept: text/x-gcode` / `?format=gcode` a \
            complete program (up to the solver's limit of 6 000 000 moves; dialect from `?dialect=`, \
            else the named machine's, else Fanuc). With `block_time_ms` or a `machine` the arcs are \
            chorded by the block-time rule and the summary reports the blocks.",
        not_found: "Unknown tool number or machine",
        refused: "Impossible contour or over a limit (codes in docs/spec/contour.md §5; `E_TOO_MANY_MOVES` for \
            answers over the move limit); `E_TIMEOUT` over the synchronous time limit: submit a job; `E_TOO_LARGE_ANSWER` when the answer would not fit the answer budget",
    };
    type Request = ContourRequest;
    type Answer = ContourAnswer;
    type Tool = Tool;

    fn refs(request: &ContourRequest) -> Refs<'_> {
        Refs { tool: Some(&request.tool), machine: request.machine.as_deref(), material: None }
    }

    /// The move cap of the answer ([`MAX_JSON_MOVES`] for JSON, else [`MAX_MOVES`]) at
    /// `move_bound` each, and the corners' and passes' reports.
    fn answer_bound(request: &ContourRequest, _context: &Resolved<Tool>, purpose: Purpose) -> Option<u64> {
        if request.drawing.is_some() {
            // The polygon's length is known once the drawing is read: the answer is counted.
            return None;
        }
        let max_moves = if purpose == Purpose::Json { MAX_JSON_MOVES } else { MAX_MOVES };
        let passes = request.passes.as_ref().map_or(1, Vec::len) as u64;
        let reports = (request.contour.len() as u64).saturating_add(passes).saturating_mul(REPORT_BYTES);
        Some(
            (max_moves as u64)
                .saturating_mul(move_bound(purpose))
                .saturating_add(reports)
                .saturating_add(ANSWER_BYTES)
                .saturating_add(own::VERIFICATION_BYTES),
        )
    }

    /// A JSON answer holds at most [`MAX_JSON_MOVES`] moves; a program or a job up to [`MAX_MOVES`].
    /// Each layer's moves are charged to the run's budget as the layer is made.
    fn solve(request: &ContourRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<ContourAnswer, SolverError> {
        let read;
        let request = match request.from_upload(run.upload)? {
            Some(drawn) => {
                read = drawn;
                &read
            }
            None => request,
        };
        let max_moves = if run.purpose == Purpose::Json { MAX_JSON_MOVES } else { MAX_MOVES };
        verification_grid(request, &context.tool)?;
        let charge = |layer: &LayerMoves, done: usize, count: usize| {
            run.charge_unit(done, count, ANSWER_BYTES, || layer_bytes(layer, run.purpose))
        };
        let result = super::solve::solve_charged(
            request,
            &context.tool,
            context.machine.as_ref(),
            max_moves,
            run.control,
            charge,
        );
        let result = if run.purpose == Purpose::Json { result.map_err(json_limit_advice)? } else { result? };
        verified(
            request,
            ContourAnswer { tool: context.tool, machine: context.machine, result, verification: None },
            run,
        )
    }

    fn set_cut_resolution(request: &mut ContourRequest, resolution: f64) {
        request.verification.get_or_insert_with(Default::default).resolution = Some(resolution);
    }

    /// The stock block less what the program (with its verification's header comments) cut, up to
    /// `upto_line`, against the part prism.
    fn cut_stock(
        request: &ContourRequest,
        context: Resolved<Tool>,
        upto_line: Option<usize>,
        units: crate::units::Units,
        run: &Run<'_>,
    ) -> Result<Option<Vec<u8>>, SolverError> {
        let answer = Self::solve(request, context, run)?;
        let read;
        let request = match request.from_upload(run.upload)? {
            Some(drawn) => {
                read = drawn;
                &read
            }
            None => request,
        };
        let Some((model, grid, limits)) = own_model(request, &answer)? else {
            return Ok(None);
        };
        let program = own::program::<ContourCapability>(request, &answer, run)?;
        own::cut_stock_glb(
            &model,
            grid,
            &program,
            &[(None, &answer.tool)],
            limits,
            own::StockAsk { upto_line, units },
            run,
        )
        .map(Some)
    }

    /// Ranges of layers of about `sizing.part_seconds` each (`parts`): a job's contour only,
    /// which may hold up to [`MAX_MOVES`] moves.
    fn split(request: &ContourRequest, context: &Resolved<Tool>, sizing: &Sizing) -> Option<Split> {
        if request.drawing.is_some() {
            // Solved whole, where a drawing without its file is refused.
            return None;
        }
        super::parts::split(request, &context.tool, context.machine.as_ref(), sizing)
    }

    /// The moves of the layers of `part`.
    fn solve_part(
        request: &ContourRequest,
        context: Resolved<Tool>,
        part: &Part,
        run: &Run<'_>,
        sink: &mut impl PartSink,
    ) -> Result<(), SolverError> {
        super::parts::solve_part(request, &context.tool, context.machine.as_ref(), part, run.control, sink)
    }

    /// Every layer's moves, answered as `solve` answers a job.
    fn finish(
        request: &ContourRequest,
        context: Resolved<Tool>,
        parts: &mut impl PartSource,
        run: &Run<'_>,
    ) -> Result<ContourAnswer, SolverError> {
        verification_grid(request, &context.tool)?;
        let result = super::parts::finish(request, &context.tool, context.machine.as_ref(), parts, run.control)?;
        verified(
            request,
            ContourAnswer { tool: context.tool, machine: context.machine, result, verification: None },
            run,
        )
    }

    fn program(
        request: &ContourRequest,
        answer: &ContourAnswer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError> {
        let mut post = output.post(answer.machine.as_ref(), &answer.tool);
        post.plunge_feed = request.plunge_feed.or(post.plunge_feed);
        super::program::program_controlled(&answer.result, &post, control)
    }

    fn units(request: &ContourRequest) -> Option<crate::units::Units> {
        request.units
    }

    fn scale_request(request: &mut ContourRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        crate::units::Scale::scale(request, scaling);
        Ok(())
    }

    fn scale_answer(answer: &mut ContourAnswer, scaling: crate::units::Scaling) {
        crate::units::Scale::scale(answer, scaling);
    }

    fn machine(answer: &ContourAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }

    /// The layers' moves, nearly all of a large answer, written by hand (`wire`): the same
    /// bytes as serde's.
    fn to_json(answer: ContourAnswer) -> serde_json::Result<Vec<u8>> {
        super::wire::to_json(answer)
    }

    /// Keeps a stored result within [`MAX_JSON_MOVES`]: from the first layer that would pass the
    /// limit on, layers keep their `z` but lose their moves, and `W_MOVES_NOT_STORED` says so
    /// (the program, written before, has every move).
    fn for_storage(answer: &mut ContourAnswer) {
        let total = answer.result.summary.moves;
        if total <= MAX_JSON_MOVES {
            return;
        }
        let mut kept = 0;
        let mut first_dropped = None;
        for (index, layer) in answer.result.layers.iter_mut().enumerate() {
            if first_dropped.is_some() || kept + layer.moves.len() > MAX_JSON_MOVES {
                first_dropped.get_or_insert(index);
                layer.moves = Vec::new();
            } else {
                kept += layer.moves.len();
            }
        }
        if let Some(first) = first_dropped {
            let layers = answer.result.layers.len();
            answer.result.warnings.push(Warning::new(
                "W_MOVES_NOT_STORED",
                format!(
                    "the answer has {total} moves, more than the {MAX_JSON_MOVES} a stored JSON result holds: layers \
                     {first} to {} are listed without their moves; the G-code program has every move",
                    layers - 1
                ),
            ));
        }
    }
}

/// The contour's own model (docs/spec/verify.md §9.2): the part prism of the outline from a floor
/// under `depths.bottom` up to `depths.top`, its walls moved out by the last pass's allowance and
/// the relief discs (`reliefs`) cut out; the stock adds the band `stock_allowance` wide beyond the
/// outline (without it, the band the first pass cuts: its allowance plus the tool radius).
fn prism(request: &ContourRequest, tool: &Tool, reliefs: Vec<[f64; 2]>, wall_tolerance: f64) -> Prism {
    let allowances: Vec<f64> =
        request.passes.as_ref().map_or_else(|| vec![0.0], |passes| passes.iter().map(|pass| pass.allowance).collect());
    let first = allowances.first().copied().unwrap_or(0.0);
    let finish = allowances.last().copied().unwrap_or(0.0);
    Prism {
        outline: own::outline(&request.contour),
        material_inside: request.side == super::Side::Outside,
        top: request.depths.top,
        bottom: request.depths.bottom,
        stock: request.stock_allowance.unwrap_or(first + tool.radius).max(finish),
        finish,
        reliefs: own::outline(&reliefs),
        relief_radius: tool.radius,
        reach: tool.radius,
        wall_tolerance,
    }
}

/// The grid of the verification, checked before any work: a resolution over the memory limit is
/// refused up front.
fn verification_grid(request: &ContourRequest, tool: &Tool) -> Result<Option<own::Grid>, SolverError> {
    let options = request.verification.unwrap_or_default();
    // A request the solve's validation refuses is refused there, naming its field, not here by
    // the size of a grid over an outline out of range.
    let in_range = |value: f64| value.abs() <= crate::validate::MAX_COORDINATE;
    if !options.enabled
        || request.contour.is_empty()
        || !request.contour.iter().flatten().all(|value| in_range(*value))
        || !tool.radius.is_finite()
        || tool.radius <= 0.0
    {
        return Ok(None);
    }
    let model = prism(request, tool, Vec::new(), 0.0);
    own::grid(model.footprint(), tool, &options).map(Some)
}

/// `answer` with its program cut on the contour's own model: its `verification`, and the
/// warnings and header comments of what that found.
fn verified(request: &ContourRequest, mut answer: ContourAnswer, run: &Run<'_>) -> Result<ContourAnswer, SolverError> {
    let Some((model, grid, limits)) = own_model(request, &answer)? else {
        return Ok(answer);
    };
    let program = own::program::<ContourCapability>(request, &answer, run)?;
    let mut verification = own::verify(&model, grid, &program, &answer.tool, limits, run)?;
    own::report(&mut verification, &mut answer.result.warnings, &mut answer.result.description);
    answer.verification = Some(verification);
    Ok(answer)
}

/// The model `answer`'s program is cut on, its grid and its limits; `None` without a
/// verification (turned off, tilted walls).
fn own_model(
    request: &ContourRequest,
    answer: &ContourAnswer,
) -> Result<Option<(Prism, own::Grid, own::Limits)>, SolverError> {
    let Some(grid) = verification_grid(request, &answer.tool)? else {
        return Ok(None);
    };
    if answer.result.tilted {
        return Ok(None);
    }
    let reliefs = answer.result.corners.iter().filter_map(|corner| corner.relief.as_ref()).map(|relief| relief.target);
    let wall_tolerance = answer.result.summary.tolerance + own::OWN_TOLERANCE;
    let model = prism(request, &answer.tool, reliefs.collect(), wall_tolerance);
    let limits =
        own::Limits { tolerance: own::OWN_TOLERANCE, allowance: crate::verify::DEFAULT_ALLOWANCE, wall_tolerance };
    Ok(Some((model, grid, limits)))
}

/// A JSON answer over [`MAX_JSON_MOVES`] gets the advice to ask for G-code or submit a job.
fn json_limit_advice(error: SolverError) -> SolverError {
    if error.code() != ErrorCode::TooManyMoves {
        return error;
    }
    let advice = format!(
        "{} (a JSON answer holds at most {MAX_JSON_MOVES} moves; ask for G-code with Accept: text/x-gcode or \
         ?format=gcode, or submit a job (POST /api/v1/jobs), which allow up to {MAX_MOVES} moves)",
        error.message(),
    );
    let field = error.field().map(str::to_owned);
    let advised = SolverError::new(error.code(), advice);
    match field {
        Some(field) => advised.at(field),
        None => advised,
    }
}

/// `POST /api/v1/contour/loops`: a closed tool-centre path made elsewhere, whose corners get
/// loops (docs/spec/contour.md §3.4, claims 8–10).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct LoopsRequest {
    /// A registered tool number or an inline tool; its `radius` sizes the loops.
    pub tool: ToolRef,
    /// The closed path `[[x, y], ...]` of the tool centre in travel order (the last point need
    /// not repeat the first; at most 200 000 points).
    pub path: Vec<[f64; 2]>,
    /// `left` (default) or `right` of travel: where the material lies.
    #[serde(default)]
    pub material_side: MaterialSide,
    /// `turn_angle` (default), `patent_curvature` (claim 8) or `patent_delta_l` (claim 9).
    #[serde(default)]
    pub detect: DetectMode,
    /// Threshold of the mode: ψ_min in degrees for `turn_angle` (default 10), κ_th in 1/mm for
    /// `patent_curvature` (default 1/tool radius), λ_th for `patent_delta_l` (default sin 5°).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
    /// Loop style and sizing, as for contours.
    #[serde(default)]
    pub corner_loop: CornerLoop,
    /// Chord tolerance of loop arcs, mm (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
}

/// The looped path: the tool used and the solver's result.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct LoopsAnswer {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// Detection measures per point, the looped path and the claim-10 check.
    #[serde(flatten)]
    pub result: PathLoopAnswer,
}

impl LoopsRequest {
    /// The tool it refers to.
    pub fn refs(&self) -> Refs<'_> {
        Refs { tool: Some(&self.tool), machine: None, material: None }
    }

    /// Adds loops to the path with the resolved tool; at most [`MAX_JSON_MOVES`] moves.
    ///
    /// # Errors
    /// `E_INPUT` for a bad tool or numbers, the path errors of [`detect::loop_path_within`], and
    /// `E_CANCELLED` once `control`'s cancel flag is set.
    pub fn solve(&self, tool: Tool, control: Control<'_>) -> Result<LoopsAnswer, SolverError> {
        tool.validate("tool.")?;
        let path_request = PathLoopRequest {
            path: self.path.clone(),
            material_side: self.material_side,
            detect: self.detect,
            threshold: self.threshold,
            tool_radius: tool.radius,
            corner_loop: self.corner_loop.clone(),
            tolerance: self.tolerance,
        };
        let result = detect::loop_path_within(&path_request, MAX_JSON_MOVES, control)?;
        Ok(LoopsAnswer { tool, result })
    }
}

#[cfg(test)]
mod budget_tests {
    use super::*;
    use crate::contour::answer::MoveKind;

    #[test]
    fn move_json_is_within_its_bound() {
        // The longest number serde writes (ryu) in every field, the longest kind.
        let longest = -2.225_073_858_507_201_4e-308;
        let step = ContourMove {
            kind: MoveKind::Rapid,
            to: [longest; 3],
            feed: Some(longest),
            axis: Some(Box::new([longest; 3])),
        };
        // With the comma that separates it from the next move.
        let json = serde_json::to_vec(&step).unwrap().len() as u64 + 1;
        assert!(json <= MOVE_JSON_BYTES, "{json} bytes");
    }

    /// A 600-gon of `layers` layers of 0.1 mm, some 606 moves each.
    fn polygon(layers: f64) -> ContourRequest {
        let contour: Vec<[f64; 2]> = (0..600)
            .map(|k| {
                let angle = std::f64::consts::TAU * f64::from(k) / 600.0;
                [30.0 * angle.cos(), 30.0 * angle.sin()]
            })
            .collect();
        serde_json::from_value(serde_json::json!({
            "tool": {"kind": "flat", "radius": 3}, "contour": contour, "side": "outside",
            "depths": {"top": 0, "bottom": -layers * 0.1, "step": 0.1}, "feed": 800
        }))
        .unwrap()
    }

    fn context(request: &ContourRequest) -> Resolved<Tool> {
        let ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() }
    }

    #[test]
    fn layers_over_the_budget_are_refused_a_layer_past_it() {
        let request = polygon(400.0);
        for purpose in [Purpose::Json, Purpose::Program, Purpose::Job] {
            let budget = crate::capability::AnswerBudget::new(1 << 20);
            let run = Run { budget: Some(&budget), purpose, ..Run::default() };
            let error = ContourCapability::solve(&request, context(&request), &run).unwrap_err();
            assert_eq!(error.code(), ErrorCode::TooLargeAnswer, "{purpose:?}: {error}");
            let layer = 700 * move_bound(purpose) + ANSWER_BYTES;
            assert!(budget.used() <= budget.limit() + layer, "{purpose:?}: {} charged", budget.used());
        }
    }

    #[test]
    fn the_bound_and_the_charges_cover_what_is_built() {
        let request = polygon(10.0);
        let context = context(&request);
        let answer = ContourCapability::solve(&request, context.clone(), &Run::default()).unwrap();
        let moves: u64 = answer.result.layers.iter().map(|layer| layer.moves.len() as u64).sum();
        let json = serde_json::to_vec(&answer).unwrap().len() as u64;
        let program = crate::capability::program::<ContourCapability>(
            &request,
            &answer,
            &OutputOptions::default(),
            Control::default(),
        )
        .unwrap()
        .len() as u64;
        let memory = moves * std::mem::size_of::<ContourMove>() as u64;
        // What each purpose is charged: the answer's JSON and its moves, the moves of a program,
        // the JSON a job stores.
        for (purpose, built, delivered) in [
            (Purpose::Json, memory + json, json),
            (Purpose::Program, memory, program),
            (Purpose::Job, json, json + program),
        ] {
            let budget = crate::capability::AnswerBudget::new(u64::MAX);
            let run = Run { budget: Some(&budget), purpose, ..Run::default() };
            ContourCapability::solve(&request, context.clone(), &run).unwrap();
            assert!(built <= budget.used(), "{purpose:?}: {built} built, {} charged", budget.used());
            // The bound covers the charges and what is delivered.
            let bound = ContourCapability::answer_bound(&request, &context, purpose).unwrap();
            assert!(
                budget.used().max(delivered) <= bound,
                "{purpose:?}: {} charged over the bound {bound}",
                budget.used()
            );
        }
        // A JSON answer at its move cap fits the default budget: counted only under a smaller one.
        assert!(ContourCapability::answer_bound(&request, &context, Purpose::Json).unwrap() < 512 << 20);
    }
}

#[cfg(test)]
mod verification_tests {
    use super::*;
    use crate::verify::{FindingKind, VerificationOptions};

    /// The arrow island of `examples/contour-arrow.toml`.
    fn arrow() -> ContourRequest {
        serde_json::from_value(serde_json::json!({
            "tool": {"kind": "flat", "radius": 3, "number": 3},
            "contour": [[0, 10], [40, 10], [40, 0], [80, 25], [40, 50], [40, 40], [0, 40]],
            "side": "outside", "depths": {"top": 0, "bottom": -9, "step": 3},
            "corner_loop": {"style": "arc"}, "inside_corner_relief": "dogbone",
            "feed": 800, "loop_feed": 2000, "stock_allowance": 0.5, "spindle_rpm": 8000,
            "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}]
        }))
        .unwrap()
    }

    fn context(request: &ContourRequest) -> Resolved<Tool> {
        let ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() }
    }

    fn fanuc(request: &ContourRequest, answer: &ContourAnswer) -> String {
        let output = OutputOptions { dialect: Some(crate::gcode::Dialect::Fanuc), ..OutputOptions::default() };
        crate::capability::program::<ContourCapability>(request, answer, &output, Control::default()).unwrap()
    }

    #[test]
    fn the_arrow_cuts_clean_on_its_own_model() {
        let request = arrow();
        let answer = ContourCapability::solve(&request, context(&request), &Run::default()).unwrap();
        let verification = answer.verification.as_ref().expect("verified");
        assert!(verification.ok, "{:#?}", verification.findings);
        assert!(verification.removed_volume_mm3 > 0.0);
        assert!(answer.result.warnings.iter().all(|warning| !warning.code.starts_with("W_VERIFY")));
        assert!(!fanuc(&request, &answer).contains("WARNING"));
    }

    #[test]
    fn verification_can_be_turned_off_and_a_grid_too_fine_is_refused_up_front() {
        let mut request = arrow();
        request.verification = Some(VerificationOptions { enabled: false, resolution: None });
        let answer = ContourCapability::solve(&request, context(&request), &Run::default()).unwrap();
        assert!(answer.verification.is_none());
        assert!(!serde_json::to_string(&answer).unwrap().contains("verification"));
        request.verification = Some(VerificationOptions { enabled: true, resolution: Some(0.001) });
        let error = ContourCapability::solve(&request, context(&request), &Run::default()).unwrap_err();
        assert_eq!((error.code(), error.field()), (ErrorCode::GridMemory, Some("verification.resolution")));
    }

    /// Every move of the finishing pass of the middle layer pushed 0.5 mm into the island (a tool
    /// radius offset too large): gouges, warned, in the header, at lines of the program written.
    #[test]
    fn a_path_pushed_into_the_part_gouges() {
        let request = arrow();
        let context = context(&request);
        let mut request_off = request.clone();
        request_off.verification = Some(VerificationOptions { enabled: false, resolution: None });
        let mut answer = ContourCapability::solve(&request_off, context.clone(), &Run::default()).unwrap();
        let centre = [45.0, 25.0];
        let layer = &mut answer.result.layers[1];
        let from = layer.moves.len() / 2;
        for step in &mut layer.moves[from..] {
            let (dx, dy) = (centre[0] - step.to[0], centre[1] - step.to[1]);
            let length = dx.hypot(dy);
            step.to[0] += 0.5 * dx / length;
            step.to[1] += 0.5 * dy / length;
        }
        layer.arcs.clear();
        let unverified = fanuc(&request, &answer);
        let answer = verified(&request, answer, &Run::default()).unwrap();
        let verification = answer.verification.as_ref().unwrap();
        assert!(!verification.ok);
        let gouges: Vec<_> =
            verification.findings.iter().filter(|finding| finding.kind == FindingKind::Gouge).collect();
        assert!(!gouges.is_empty(), "{:#?}", verification.findings);
        assert!(answer.result.warnings.iter().any(|warning| warning.code == "W_VERIFY_GOUGE"));
        // Fanuc comments are upper case.
        let program = fanuc(&request, &answer);
        assert!(program.contains("(WARNING VERIFICATION FOUND"), "{program}");
        let first = gouges[0].line.unwrap();
        assert!(program.contains(&format!("(WARNING GOUGE AT LINE {first}: ")), "{program}");
        // The finding's line is the move of the program the answer writes: the same text as in
        // the program before the comments were added, a feed move at the gouge's height.
        let lines: Vec<&str> = program.lines().collect();
        let before: Vec<&str> = unverified.lines().collect();
        let added = lines.len() - before.len();
        assert!(added >= 2);
        for gouge in gouges {
            let line = gouge.line.unwrap();
            assert_eq!(lines[line - 1], before[line - 1 - added]);
            assert!(lines[line - 1].starts_with("G01") || lines[line - 1].contains("X"), "{}", lines[line - 1]);
            assert!(gouge.position[2] >= -6.0 - 1e-9, "{gouge:?}");
        }
    }
}
