//! Verification as a capability (the seam of docs/architecture.md; docs/spec/verify.md §1, §5):
//! `POST /api/v1/verify`, job operation `verify`. It answers findings, not a program.

use serde::Serialize;

use super::job::Found;
use super::request::VerifyRequest;
use super::simulate::{self, Cut, MAX_FINDINGS};
use crate::capability::{Capability, Control, Endpoint, OtherTool, OutputOptions, Purpose, Refs, Resolved, Run};
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
    /// The findings, volumes, times and removal per block.
    #[serde(flatten)]
    pub cut: Cut,
}

/// Bytes of JSON one block's removal record takes at most.
const BLOCK_BYTES: u64 = 200;
/// Bytes of JSON one finding takes at most.
const FINDING_BYTES: u64 = 300;

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
        let found = Found { material: context.material.as_ref(), machine: context.machine.as_ref() };
        let job = request.validate(&context.other_tools, found, run.upload, run.control)?;
        let cut = simulate::cut(&job, run)?;
        Ok(VerifyAnswer { tools: context.other_tools, cut })
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
