//! Engagement analysis as a capability (the seam of engineering.md; docs/spec/api.md, Engagement;
//! docs/spec/engagement.md §3): `POST /api/v1/engagement`, job operation `engagement`.

use serde::{Deserialize, Serialize};

use super::answer::{Comparison, PathEngagement, PostData, RouteData};
use super::job::Job;
use super::request::Engine;
use super::{EngagementRequest, EngagementSolution, Stock};
use crate::capability::{
    Capability, Control, Endpoint, OutputOptions, Part, PartSink, PartSource, Purpose, Refs, Resolved, Run, Sizing,
    Split,
};
use crate::error::{ErrorCode, SolverError};
use crate::gcode::SpindleDirection;
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
pub struct EngagementAnswer {
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
    /// change) and its parts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_time: Option<crate::machine::cycle::CycleTime>,
    /// Samples, flute counts and recommendation (or `candidates`, one such result per path).
    #[serde(flatten)]
    pub result: EngagementSolution,
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
            `E_TOO_MANY_SAMPLES`, `E_GRID_MEMORY`, `E_WORK_LIMIT` (docs/spec/engagement.md §9); `E_TIMEOUT` \
            over the synchronous time limit: submit a job; `E_TOO_LARGE_ANSWER` when the answer would not fit the answer budget",
    };
    type Request = EngagementRequest;
    type Answer = EngagementAnswer;
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
    ) -> Result<EngagementAnswer, SolverError> {
        check_plunge_feed(request)?;
        let result = super::solve_in(
            request,
            &context.tool,
            context.machine.as_ref(),
            &physics(request, &context),
            run.control,
        )?;
        let answer = respond(request, context, result);
        charge_samples(&answer, run)?;
        Ok(answer)
    }

    /// The candidate paths of a request with `paths`, in runs of about `sizing.part_seconds`
    /// (see `cost`); a request with one `path`, or a refused one, is solved whole.
    fn split(request: &EngagementRequest, context: &Resolved<Tool>, sizing: &Sizing) -> Option<Split> {
        if request.paths.as_ref().is_none_or(|paths| paths.len() < 2) || check_plunge_feed(request).is_err() {
            return None;
        }
        let job = request.validate(&context.tool, context.machine.as_ref(), &physics(request, context)).ok()?;
        if job.single {
            return None;
        }
        let costs: Vec<f64> = job.candidates.iter().map(|candidate| cost(&job, &candidate.route)).collect();
        let total: f64 = costs.iter().sum();
        let count = ((total / sizing.part_seconds).round() as usize).clamp(1, sizing.max_parts.max(1)).min(costs.len());
        if count < 2 {
            return None;
        }
        // Consecutive candidates, `count` parts: a new one once the running cost passes the next
        // share, or when each candidate left must make a part of its own.
        let share = total / count as f64;
        let mut parts = Vec::with_capacity(count);
        let (mut start, mut sum) = (0, 0.0);
        for (index, seconds) in costs.iter().enumerate() {
            sum += seconds;
            let parts_after = count.saturating_sub(parts.len() + 1);
            let candidates_after = costs.len() - index - 1;
            if candidates_after == 0
                || candidates_after == parts_after
                || (parts_after > 0 && sum >= share * (parts.len() + 1) as f64)
            {
                let seconds = costs[start..=index].iter().sum();
                parts.push(Part { units: start..index + 1, seconds });
                start = index + 1;
            }
        }
        (parts.len() >= 2).then_some(Split { parts, finish_seconds: FINISH_SECONDS })
    }

    /// Evaluates the candidate paths of `part` as [`super::solve_in`] does each one, and hands on
    /// their results with what their programs need beyond the route.
    fn solve_part(
        request: &EngagementRequest,
        context: Resolved<Tool>,
        part: &Part,
        run: &Run<'_>,
        sink: &mut impl PartSink,
    ) -> Result<(), SolverError> {
        check_plunge_feed(request)?;
        let job = request.validate(&context.tool, context.machine.as_ref(), &physics(request, &context))?;
        let candidates = job.candidates.get(part.units.clone()).ok_or_else(|| mismatch("the part's candidates"))?;
        let mut results = Vec::with_capacity(candidates.len());
        for (index, candidate) in candidates.iter().enumerate() {
            let mut result = run.control.part(index, candidates.len(), |part| {
                super::evaluate::evaluate(&job, candidate, &context.tool, part)
            })?;
            if let Some((blocks, warnings)) = super::program::blocks(&result, run.control)? {
                result.blocks = Some(blocks);
                result.warnings.extend(warnings);
            }
            let post = PartPost::from(&result.post);
            results.push(PartCandidate { result, post });
        }
        sink.put(&results)
    }

    /// The candidates' results in order, their post data rebuilt, answered as `solve` answers.
    fn finish(
        request: &EngagementRequest,
        context: Resolved<Tool>,
        parts: &mut impl PartSource,
        run: &Run<'_>,
    ) -> Result<EngagementAnswer, SolverError> {
        check_plunge_feed(request)?;
        let job = request.validate(&context.tool, context.machine.as_ref(), &physics(request, &context))?;
        let mut candidates = Vec::with_capacity(job.candidates.len());
        while let Some(part) = parts.next_part::<Vec<PartCandidate>>() {
            for PartCandidate { mut result, post } in part? {
                let route = &job.candidates.get(candidates.len()).ok_or_else(|| mismatch("more candidates"))?.route;
                result.post = post.into_post(route, &job);
                candidates.push(result);
            }
            run.control.check()?;
        }
        if job.single || candidates.len() != job.candidates.len() {
            return Err(mismatch("fewer candidates"));
        }
        Ok(respond(request, context, EngagementSolution::Comparison(Comparison { candidates })))
    }

    /// The program of one path: `output.candidate`, else the request's `candidate`, else 0.
    fn program(
        request: &EngagementRequest,
        answer: &EngagementAnswer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError> {
        control.check()?;
        let mut post = output.post(answer.machine.as_ref(), &answer.tool);
        post.plunge_feed = request.plunge_feed.or(post.plunge_feed);
        let candidate = output.candidate.or(request.candidate).unwrap_or(0);
        super::program(&answer.result, candidate, &post)
    }

    fn units(request: &EngagementRequest) -> Option<crate::units::Units> {
        request.units
    }

    fn scale_request(request: &mut EngagementRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        crate::units::Scale::scale(request, scaling);
        Ok(())
    }

    fn scale_answer(answer: &mut EngagementAnswer, scaling: crate::units::Scaling) {
        crate::units::Scale::scale(answer, scaling);
    }

    fn machine(answer: &EngagementAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }

    fn to_json(answer: EngagementAnswer) -> serde_json::Result<Vec<u8>> {
        super::wire::to_json(answer)
    }
}

/// Charges the answer's samples, nearly all of a large answer, to the run's budget before any of
/// their JSON is written: their memory, and for a JSON answer or a job their JSON at the size
/// the writer reserves for it ([`super::wire`]).
fn charge_samples(answer: &EngagementAnswer, run: &Run<'_>) -> Result<(), SolverError> {
    run.charge_unit(1, 1, 0, || {
        let candidates: &[PathEngagement] = match &answer.result {
            EngagementSolution::Single(result) => std::slice::from_ref(result.as_ref()),
            EngagementSolution::Comparison(comparison) => &comparison.candidates,
        };
        let samples = candidates.iter().flat_map(|candidate| &candidate.samples);
        let memory = std::mem::size_of::<super::answer::EngagementSample>() as u64;
        match run.purpose {
            Purpose::Program => samples.map(|_| memory).sum(),
            Purpose::Json | Purpose::Job => samples.map(|sample| memory + super::wire::estimate(sample) as u64).sum(),
        }
    })
}

/// A plunge feed, when given, must be positive.
fn check_plunge_feed(request: &EngagementRequest) -> Result<(), SolverError> {
    if let Some(feed) = request.plunge_feed {
        crate::validate::positive("plunge_feed", feed)?;
    }
    Ok(())
}

/// The cutting physics the server resolved: the material's Kienzle values and the machine's
/// spindle at the request's speed.
fn physics(request: &EngagementRequest, context: &Resolved<Tool>) -> super::Physics {
    super::Physics {
        material: context.material.as_ref().map(Material::kienzle),
        spindle: context.machine.as_ref().map(|m| m.spindle_at(request.spindle_rpm)).unwrap_or_default(),
    }
}

/// The answer to `request` around the solver's `result`: the tool, machine, material and stock
/// it was judged with, and the cycle time of the programmed candidate.
fn respond(request: &EngagementRequest, context: Resolved<Tool>, result: EngagementSolution) -> EngagementAnswer {
    let cycle_time = context.machine.as_ref().and_then(MachineProfile::dynamics).and_then(|dynamics| {
        let plunge =
            request.plunge_feed.or(context.tool.plunge_feed).or(context.machine.as_ref().and_then(|m| m.plunge_feed));
        super::program::cycle_time(&result, request.candidate.unwrap_or(0), &dynamics, plunge)
    });
    EngagementAnswer {
        cycle_time,
        tool: context.tool,
        machine: context.machine,
        material: context.material,
        stock: request.stock.clone(),
        thickness_limit: request.thickness_limit,
        time_limit_s: request.time_limit_s,
        result,
    }
}

fn mismatch(what: &str) -> SolverError {
    SolverError::new(ErrorCode::Internal, format!("the parts do not belong to this engagement request: {what}"))
}

/// Core-seconds per sample, per flute count evaluated (`tests/load/cost_model.rs`, section `engagement`,
/// the exact engine with Kienzle forces, one thread: 4.5 µs per sample with one flute count, 19 µs
/// with three).
const EXACT_SAMPLE_SECONDS: f64 = 6.0e-6;
/// Core-seconds per grid row the dots engine scans (the work limit's measure: 5·10⁸ rows, about
/// 25 s).
const DOT_ROW_SECONDS: f64 = 5.0e-8;
/// Core-seconds of the finish step: reading the parts back and answering.
const FINISH_SECONDS: f64 = 0.1;

/// The estimated core-seconds of one candidate path: its samples, and with the dots engine the
/// grid rows each scans.
fn cost(job: &Job, route: &super::segments::Route) -> f64 {
    let samples = route.station_count(job.step);
    let contact = match (job.engine, job.grid) {
        (Engine::Dots, Some(cell)) => samples * (2.0 * job.radius / cell) * DOT_ROW_SECONDS,
        _ => 0.0,
    };
    contact + samples * EXACT_SAMPLE_SECONDS * job.flute_counts.len().max(1) as f64
}

/// One candidate's result as a part hands it on.
#[derive(Debug, Serialize, Deserialize)]
struct PartCandidate {
    result: PathEngagement,
    post: PartPost,
}

/// What a candidate's program needs beyond its route and the request's settings (which the
/// finish step reads from the request again).
#[derive(Debug, Serialize, Deserialize)]
struct PartPost {
    nominal_feed: f64,
    spindle_rpm: f64,
    spindle_direction: SpindleDirection,
    axial_depth: Option<f64>,
    /// The tip's Z when a_p came from it (parts stored before it carry none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cut_z: Option<f64>,
    stock_top_z: f64,
    clearance: f64,
    tool_radius: f64,
    centre_height: f64,
    description: Vec<String>,
}

impl From<&PostData> for PartPost {
    fn from(post: &PostData) -> Self {
        Self {
            nominal_feed: post.nominal_feed,
            spindle_rpm: post.spindle_rpm,
            spindle_direction: post.spindle_direction,
            axial_depth: post.axial_depth,
            cut_z: post.cut_z,
            stock_top_z: post.stock_top_z,
            clearance: post.clearance,
            tool_radius: post.tool_radius,
            centre_height: post.centre_height,
            description: post.description.clone(),
        }
    }
}

impl PartPost {
    /// The post data `evaluate` built: these figures, the candidate's route and the request's
    /// block rule.
    fn into_post(self, route: &super::segments::Route, job: &Job) -> PostData {
        PostData {
            route: RouteData(route.clone()),
            nominal_feed: self.nominal_feed,
            spindle_rpm: self.spindle_rpm,
            spindle_direction: self.spindle_direction,
            rule: job.rule,
            axial_depth: self.axial_depth,
            cut_z: self.cut_z,
            stock_top_z: self.stock_top_z,
            clearance: self.clearance,
            tool_radius: self.tool_radius,
            centre_height: self.centre_height,
            description: self.description,
        }
    }
}
