//! Engagement analysis as a capability (the seam of engineering.md): `POST /api/v1/engagement`,
//! job operation `engagement`.

use serde::Serialize;

use super::{EngagementAnswer, EngagementRequest, Stock};
use crate::capability::{Capability, Endpoint, OutputOptions, Refs, Resolved, Run};
use crate::error::SolverError;
use crate::machine::MachineProfile;
use crate::material::Material;
use crate::tool::Tool;

/// The engagement capability.
#[derive(Debug, Clone, Copy)]
pub struct EngagementCapability;

/// The engagement answer: the tool used, the stock and limits it was judged against (so the
/// answer can be plotted on its own, as the page does for job results), and the solver's result
/// (one path's fields at the top level for a request with `path`, `candidates` for a request
/// with `paths`).
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct EngagementResponse {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// The machine the request named, as registered: its `max_feed` caps the feed plan unless
    /// `feed_plan.max_feed` is given, its dialect is the G-code default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// The work material the request named, as stored in the materials library: the Kienzle
    /// values the forces were computed with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub material: Option<Material>,
    /// The stock, as given.
    pub stock: Stock,
    /// T1 as given, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thickness_limit: Option<f64>,
    /// T2 as given, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_limit_s: Option<f64>,
    /// With a machine that has `max_accel` and an `axial_depth` (a program): the time the control
    /// would take for the program of the request's `candidate` path (trapezoidal feed profile,
    /// stops at sharp corners, the plunge at the plunge feed, rapids at `rapid_feed`, one tool
    /// change) and its parts (issue 15).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_time: Option<crate::machine::cycle::CycleTime>,
    /// Samples, flute counts and recommendation (or `candidates`, one such result per path).
    #[serde(flatten)]
    pub result: EngagementAnswer,
}

impl Capability for EngagementCapability {
    const NAME: &'static str = "engagement";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Analyses the tool–workpiece engagement along a tool path and recommends flute counts.",
        description: "Moves the tool's cutting circle along the path over the stock and returns, per sample, \
            the engaged arcs (tool angle: 90° ahead, 0° right, 180° left of travel), the radial \
            depth and the summed chip thickness of every candidate flute count; per flute count the \
            representative thicknesses, the machining time and whether it meets `thickness_limit` \
            and `time_limit_s`. `paths` compares several candidate paths side by side. With `Accept: \
            text/x-gcode` or `?format=gcode` (and `axial_depth`) it returns the program of one path \
            (`?candidate=`) at the feeds of `feed_plan` (chip-thinning compensation) or at the \
            nominal feed. A `machine` supplies `feed_plan.max_feed` and the dialect.",
        not_found: "Unknown tool number or machine",
        refused: "Impossible or over a limit: `E_INPUT`, `E_PATH`, `E_STOCK`, `E_TOO_LARGE`, \
            `E_TOO_MANY_SAMPLES`, `E_GRID_MEMORY`, `E_WORK_LIMIT` (engagement.md §9); `E_TIMEOUT` \
            over the synchronous time limit: submit a job",
    };
    type Request = EngagementRequest;
    type Answer = EngagementResponse;
    type Tool = Tool;

    fn refs(request: &EngagementRequest) -> Refs<'_> {
        // A request giving both `material` and `kienzle` is refused by the solver (422 at
        // `material`), whether or not the material exists, so the name is looked up only alone.
        let material = if request.kienzle.is_none() { request.material.as_deref() } else { None };
        Refs { tool: Some(&request.tool), machine: request.machine.as_deref(), material }
    }

    fn solve(
        request: &EngagementRequest,
        context: Resolved<Tool>,
        run: &Run<'_>,
    ) -> Result<EngagementResponse, SolverError> {
        if let Some(feed) = request.plunge_feed {
            crate::validate::positive("plunge_feed", feed)?;
        }
        let physics = super::Physics {
            material: context.material.as_ref().map(Material::kienzle),
            spindle: context.machine.as_ref().map(|m| m.spindle_at(request.spindle_rpm)).unwrap_or_default(),
        };
        let result = super::solve_in(request, &context.tool, context.machine.as_ref(), &physics, run.control)?;
        let cycle_time = context.machine.as_ref().and_then(MachineProfile::dynamics).and_then(|dynamics| {
            let plunge = request
                .plunge_feed
                .or(context.tool.plunge_feed)
                .or(context.machine.as_ref().and_then(|m| m.plunge_feed));
            super::program::cycle_time(&result, request.candidate.unwrap_or(0), &dynamics, plunge)
        });
        Ok(EngagementResponse {
            cycle_time,
            tool: context.tool,
            machine: context.machine,
            material: context.material,
            stock: request.stock.clone(),
            thickness_limit: request.thickness_limit,
            time_limit_s: request.time_limit_s,
            result,
        })
    }

    /// The program of one path: `output.candidate`, else the request's `candidate`, else 0.
    fn program(
        request: &EngagementRequest,
        answer: &EngagementResponse,
        output: &OutputOptions,
    ) -> Result<String, SolverError> {
        let mut post = output.post(answer.machine.as_ref(), &answer.tool);
        post.plunge_feed = request.plunge_feed.or(post.plunge_feed);
        let candidate = output.candidate.or(request.candidate).unwrap_or(0);
        super::program(&answer.result, candidate, &post)
    }

    fn machine(answer: &EngagementResponse) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }
}
