//! Verification as a capability (the seam of docs/architecture.md; docs/spec/verify.md §1, §5):
//! `POST /api/v1/verify`, job operation `verify`. It answers findings, not a program.

use serde::Serialize;

use super::job::{Found, Job};
use super::request::VerifyRequest;
use super::simulate::{self, Cut, MAX_FINDINGS, PartCut};
use crate::capability::{
    Capability, Control, Endpoint, OtherTool, OutputOptions, Part, PartSink, PartSource, Purpose, Refs, Resolved, Run,
    Sizing, Split,
};
use crate::error::{ErrorCode, SolverError};
use crate::machine::MachineProfile;
use crate::tool::Tool;

/// The verify capability.
#[derive(Debug, Clone, Copy)]
pub struct VerifyCapability;

/// The answer: the tools as resolved, and what cutting the program found.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct VerifyAnswer {
    /// The tools, in the order of the request, as resolved from the table or given inline.
    pub tools: Vec<Tool>,
    /// Per tool that gives no `stickout` or no `holder_diameter`, the holder the cut assumed
    /// (docs/spec/verify.md §2 defaults), in a sentence: every holder contact found with it is
    /// only as real as it is. Absent when every tool gives both.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub assumed: Vec<String>,
    /// The findings, volumes, times and removal per block.
    #[serde(flatten)]
    pub cut: Cut,
}

impl VerifyAnswer {
    /// The answer of `cut` made with `tools`.
    pub(crate) fn new(tools: Vec<Tool>, cut: Cut) -> Self {
        let numbered: Vec<(Option<u32>, &Tool)> = tools.iter().map(|tool| (tool.number, tool)).collect();
        let assumed = super::own::assumed_holders(&numbered);
        Self { tools, assumed, cut }
    }
}

/// Bytes of JSON one block's removal record takes at most.
const BLOCK_BYTES: u64 = 200;
/// Bytes of JSON one finding takes at most.
const FINDING_BYTES: u64 = 300;

/// Core-seconds per ray of a cutter's footprint along a move (the rays a sweep looks at): the
/// 100 502-block raster of the verify bench, 1.26·10⁹ footprint rays, cut in six parts in 7.4 s
/// of one core besides what each part repeats (docs/guide/performance.md, "Split cost models").
const FOOTPRINT_RAY_SECONDS: f64 = 5.8e-9;
/// Core-seconds per ray to build the stock's (and again the part's) dexels of a strip.
const FIELD_RAY_SECONDS: f64 = 1.0e-8;
/// Core-seconds per move every part repeats: reading the program and planning each move
/// (measured 0.6 µs: 0.061 s for a strip of the raster no move reaches).
const SETUP_MOVE_SECONDS: f64 = 6.0e-7;
/// Core-seconds per move of the finish step: reading the program and the parts' records,
/// merging them, the findings and blocks (measured 0.9 µs), and writing the answer.
const FINISH_MOVE_SECONDS: f64 = 1.5e-6;

impl VerifyCapability {
    /// The request validated as a job holds it (no upload), with `context`'s tools, material
    /// and machine.
    fn job(request: &VerifyRequest, context: &Resolved<Option<Tool>>, run: &Run<'_>) -> Result<Job, SolverError> {
        let found = Found { material: context.material.as_ref(), machine: context.machine.as_ref() };
        request.validate(&context.other_tools, found, run.upload, run.control)
    }
}

impl Capability for VerifyCapability {
    const NAME: &'static str = "verify";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Verifies a G-code program by cutting it: a material-removal simulation.",
        description: "Cuts the program, move by move, out of the stock with the tools it calls (cutter, \
            neck, shank and holder) on a grid of z-dexels, and answers what it found, each at its G-code \
            line with a position and an amount: gouges into the part, material left outside it, rapid \
            moves through material, neck, shank or holder contact with the stock, feed moves in air \
            beyond a share of the cutting time, and with a material and machine blocks over the spindle's \
            power; with the volumes, cutting time and the removed volume, removal rate and (with a \
            material) spindle power of every block that cut (docs/spec/verify.md). The part and stock may \
            be STL files (`\"kind\": \"mesh\"`, sent as a multipart form). With `?format=glb` or an \
            `Accept` preferring `model/gltf-binary`: the cut stock as binary glTF, each vertex coloured \
            (gouge red, material left blue, within tolerance grey) and carrying its signed deviation from \
            the part in `_DEVIATION`, the JSON answer in `extras.verify`; `upto_line` cuts only the moves \
            up to that line (playback). It writes no program.",
        not_found: "A tool number in `tools` that is not in the tool table, or a `material` or `machine` not registered",
        refused: "The program as the reader refuses it (`E_GCODE_SYNTAX`, `E_GCODE_UNSUPPORTED`, ... with \
            the line), a bad tool, stock or part (`E_INPUT` naming the field), a move calling a tool \
            `tools` does not name, an open or inside-out STL file or a part outside the stock (at `part` \
            or `stock`), a block cutting without a spindle speed when `material` asks for its power, a \
            resolution whose dexels would exceed the memory limit \
            (`E_GRID_MEMORY` at `resolution`), a stock no tool reaches (`E_STOCK`); `E_TIMEOUT` over the \
            synchronous time limit: submit a job; `E_TOO_LARGE_ANSWER` over the answer budget",
    };
    type Request = VerifyRequest;
    type Answer = VerifyAnswer;
    type Tool = Option<Tool>;

    fn refs(request: &VerifyRequest) -> Refs<'_> {
        Refs { tool: None, machine: request.machine.as_deref(), material: request.material.as_deref() }
    }

    fn other_tools(request: &VerifyRequest) -> Vec<OtherTool<'_>> {
        request.tools.iter().map(|tool| OtherTool { field: "tools", tool }).collect()
    }

    fn solve(
        request: &VerifyRequest,
        context: Resolved<Option<Tool>>,
        run: &Run<'_>,
    ) -> Result<VerifyAnswer, SolverError> {
        let job = Self::job(request, &context, run)?;
        let cut = simulate::cut(&job, run)?;
        Ok(VerifyAnswer::new(context.other_tools, cut))
    }

    /// The stock as the request's program (up to `upto_line`) left it, against its part: the
    /// mesh of `?format=glb` (docs/spec/verify.md §8).
    fn cut_stock(
        request: &VerifyRequest,
        context: Resolved<Option<Tool>>,
        upto_line: Option<usize>,
        units: crate::units::Units,
        run: &Run<'_>,
    ) -> Result<Option<Vec<u8>>, SolverError> {
        let found = Found { material: context.material.as_ref(), machine: context.machine.as_ref() };
        super::cut_stock_glb(request, context.other_tools, found, upto_line, units, run).map(Some)
    }

    fn set_cut_resolution(request: &mut VerifyRequest, resolution: f64) {
        request.resolution = Some(resolution);
    }

    fn given_program(request: &VerifyRequest) -> Option<&str> {
        Some(&request.program)
    }

    /// Strips of the dexel grid's rows, in parts of about `sizing.part_seconds` by the rays the
    /// cutter's footprints cover on them (docs/spec/verify.md §5). Not split: a refused request
    /// (solving it whole reports why), one a job cannot carry (an STL file), a grid of one strip.
    fn split(request: &VerifyRequest, context: &Resolved<Option<Tool>>, sizing: &Sizing) -> Option<Split> {
        let job = Self::job(request, context, &Run::default()).ok()?;
        let footprints = simulate::strip_work(&job)?;
        let grid = job.grid;
        let fields = if job.part.is_some() { 2.0 } else { 1.0 };
        let work: Vec<f64> = footprints
            .iter()
            .enumerate()
            .map(|(strip, rays)| {
                let built = (grid.strip_rows(strip..strip + 1).len() * grid.nx) as f64 * fields;
                rays * FOOTPRINT_RAY_SECONDS + built * FIELD_RAY_SECONDS
            })
            .collect();
        let moves = job.program.moves.len() as f64;
        let setup = moves * SETUP_MOVE_SECONDS;
        let finish = moves * FINISH_MOVE_SECONDS;
        by_work(&work, setup, finish, sizing)
    }

    /// Cuts the program on the rays of the part's strips and hands on what each move did there.
    fn solve_part(
        request: &VerifyRequest,
        context: Resolved<Option<Tool>>,
        part: &Part,
        run: &Run<'_>,
        sink: &mut impl PartSink,
    ) -> Result<(), SolverError> {
        let job = Self::job(request, &context, run)?;
        if part.units.is_empty() || part.units.end > job.grid.strips() {
            return Err(SolverError::new(
                ErrorCode::Internal,
                format!("strips {:?} are not strips of this verification's {}", part.units, job.grid.strips()),
            ));
        }
        sink.put(&simulate::cut_part(&job, part.units.clone(), run)?)
    }

    /// Merges the parts' strips into the answer [`Capability::solve`] gives.
    fn finish(
        request: &VerifyRequest,
        context: Resolved<Option<Tool>>,
        parts: &mut impl PartSource,
        run: &Run<'_>,
    ) -> Result<VerifyAnswer, SolverError> {
        let job = Self::job(request, &context, run)?;
        let mut cuts = Vec::with_capacity(parts.count());
        while let Some(part) = parts.next_part::<PartCut>() {
            cuts.push(part?);
            run.control.check()?;
        }
        let cut = simulate::finish_parts(&job, &cuts, run)?;
        Ok(VerifyAnswer::new(context.other_tools, cut))
    }

    fn program(
        _request: &VerifyRequest,
        _answer: &VerifyAnswer,
        _output: &OutputOptions,
        _control: Control<'_>,
    ) -> Result<String, SolverError> {
        Err(SolverError::new(ErrorCode::NoProgram, "verify answers findings, not a program: ask for JSON"))
    }

    fn units(request: &VerifyRequest) -> Option<crate::units::Units> {
        request.units
    }

    fn scale_request(request: &mut VerifyRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        crate::units::Scale::scale(request, scaling);
        Ok(())
    }

    fn scale_answer(answer: &mut VerifyAnswer, scaling: crate::units::Scaling) {
        crate::units::Scale::scale(answer, scaling);
    }

    fn machine(_answer: &VerifyAnswer) -> Option<&MachineProfile> {
        None
    }

    /// Every block may remove material and every finding is capped, so the program's line count
    /// bounds the answer.
    fn answer_bound(request: &VerifyRequest, context: &Resolved<Option<Tool>>, _purpose: Purpose) -> Option<u64> {
        let lines = request.program.split('\n').count() as u64;
        let tools = crate::capability::json_bytes(&context.other_tools);
        Some(4096 + tools + lines * BLOCK_BYTES + MAX_FINDINGS as u64 * FINDING_BYTES)
    }
}

/// Consecutive strips of `work` core-seconds each cut into parts of about `sizing.part_seconds`
/// (at least ten times the `setup` every part repeats), each ending where the work before it
/// reaches its share; `None` when one part would do.
fn by_work(work: &[f64], setup: f64, finish: f64, sizing: &Sizing) -> Option<Split> {
    let mut prefix = Vec::with_capacity(work.len() + 1);
    prefix.push(0.0);
    for seconds in work {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + seconds);
    }
    let total = prefix.last().copied().unwrap_or(0.0);
    let per_part = sizing.part_seconds.max(10.0 * setup);
    if !(total.is_finite() && per_part > 0.0) {
        return None;
    }
    let count = ((total / per_part).round() as usize).clamp(1, sizing.max_parts.max(1)).min(work.len());
    if count < 2 {
        return None;
    }
    let mut bounds = vec![0];
    for k in 1..count {
        let share = total * k as f64 / count as f64;
        let at = prefix.partition_point(|&sum| sum < share);
        let previous = bounds.last().copied().unwrap_or(0);
        bounds.push(at.clamp(previous + 1, work.len() - (count - k)));
    }
    bounds.push(work.len());
    let parts = bounds
        .windows(2)
        .map(|pair| Part { units: pair[0]..pair[1], seconds: prefix[pair[1]] - prefix[pair[0]] + setup })
        .collect();
    Some(Split { parts, finish_seconds: finish })
}
