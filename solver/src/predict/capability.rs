//! Error prediction as a capability (the seam of engineering.md): `POST /api/v1/predict`, job
//! operation `predict`. The STL file of a `mesh` stock comes as the run's upload.

use serde::Serialize;

use super::{PathInput, Predict, PredictRequest, ProgramOptions, Stock};
use crate::capability::{Capability, Endpoint, OutputOptions, Refs, Resolved, Run};
use crate::error::SolverError;
use crate::gcode::{Reference, ToolCall};
use crate::machine::MachineProfile;
use crate::tool::Tool;

/// The predict capability.
#[derive(Debug, Clone, Copy)]
pub struct PredictCapability;

/// How long the prediction took (only with `?timings=true`, and in job results: equal requests
/// otherwise give byte-identical answers). Also sent as the `Server-Timing` header.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Timings {
    /// Wall time of the prediction and correction, ms.
    pub solve_ms: f64,
    /// Passes predicted (those in `pass_range`, every round).
    pub passes: usize,
    /// Passes predicted per second of wall time.
    pub passes_per_s: f64,
}

/// The prediction answer: the tool used and the solver's result.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PredictAnswer {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// Per-pass predictions, summary and warnings.
    #[serde(flatten)]
    pub result: Predict,
    /// Timings, when asked for (`?timings=true`) and in job results.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timings: Option<Timings>,
}

impl Capability for PredictCapability {
    const NAME: &'static str = "predict";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Predicts the machining error of a ball-end-mill finishing path and corrects the path.",
        description: "Returns one record per pass (error along the surface normal, contact angle, generation \
            point, normal, flags, corrected end point), a summary with the worst passes and warnings \
            (JSON), or with `Accept: text/x-gcode` / `?format=gcode` the corrected program. The body \
            is JSON, or a form with the JSON in part `request` and the STL stock in part `stock`. \
            Long paths exceed the synchronous time limit (422 `E_TIMEOUT`): submit them as a job \
            (`operation = \"predict\"`).",
        not_found: "Unknown tool number",
        refused: "Impossible or over a limit: tool kind, no shape-error table, G-code errors with the \
            line, open mesh, resolution over the memory limit; `E_TIMEOUT` over the synchronous time \
            limit: submit a job",
    };
    type Request = PredictRequest;
    type Answer = PredictAnswer;
    type Tool = Tool;

    fn refs(request: &PredictRequest) -> Refs<'_> {
        Refs { tool: Some(&request.tool), machine: None, material: None }
    }

    fn check_output(request: &PredictRequest, output: &OutputOptions) -> Result<(), SolverError> {
        check_reference(request, output.reference)
    }

    /// A `mesh` stock needs the uploaded STL file, and an upload needs a `mesh` stock.
    fn solve(request: &PredictRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<PredictAnswer, SolverError> {
        match (&request.stock, run.upload) {
            (Stock::Mesh {}, None) => {
                return Err(SolverError::input(
                    "stock",
                    "a mesh stock needs its STL file: send multipart/form-data with the JSON in part `request` \
                     and the STL file in part `stock`",
                ));
            }
            (stock, Some(_)) if !matches!(stock, Stock::Mesh {}) => {
                return Err(SolverError::input(
                    "stock.kind",
                    "an STL file was uploaded but stock.kind is not \"mesh\"",
                ));
            }
            _ => {}
        }
        let result = super::solve_with(request, &context.tool, run.upload, &run.control)?;
        Ok(PredictAnswer { tool: context.tool, result, timings: None })
    }

    /// A G-code path is the input program with only the coordinates of moved end points changed
    /// (same lines, comments and modal words; the dialect does not apply); a `points` path becomes
    /// a complete program written for `output.reference` (the request's when not given).
    fn program(
        request: &PredictRequest,
        answer: &PredictAnswer,
        output: &OutputOptions,
    ) -> Result<String, SolverError> {
        check_reference(request, output.reference)?;
        let options = ProgramOptions { dialect: output.dialect_for(None), tool: ToolCall::for_tool(&answer.tool) };
        match (&request.path, output.reference) {
            (PathInput::Points { points }, Some(asked)) if asked != request.reference => {
                // Tip = centre − R·z: move the points to the other programmed point.
                let shift = if asked == Reference::Centre { answer.tool.radius } else { -answer.tool.radius };
                let mut converted = request.clone();
                converted.reference = asked;
                converted.path =
                    PathInput::Points { points: points.iter().map(|p| [p[0], p[1], p[2] + shift]).collect() };
                super::corrected_program(&converted, &answer.result, &options)
            }
            _ => super::corrected_program(request, &answer.result, &options),
        }
    }

    fn machine(_answer: &PredictAnswer) -> Option<&MachineProfile> {
        None
    }

    fn record_time(answer: &mut PredictAnswer, seconds: f64) {
        let rounds = answer.result.summary.rounds.len().max(1);
        let passes =
            answer.result.passes.iter().filter(|p| p.status != super::PassStatus::NotPredicted).count() * rounds;
        answer.timings = Some(Timings {
            solve_ms: (seconds * 1e4).round() / 10.0,
            passes,
            passes_per_s: if seconds > 0.0 { (passes as f64 / seconds).round() } else { 0.0 },
        });
    }
}

/// A G-code path is written back with its own programmed point: another one is refused.
fn check_reference(request: &PredictRequest, reference: Option<Reference>) -> Result<(), SolverError> {
    match (&request.path, reference) {
        (PathInput::Gcode { .. }, Some(asked)) if asked != request.reference => Err(SolverError::input(
            "reference",
            format!(
                "a G-code path is written back with its own programmed point (the request's reference, {}); \
                 leave ?reference out or ask for {}",
                request.reference.as_str(),
                request.reference.as_str()
            ),
        )),
        _ => Ok(()),
    }
}
