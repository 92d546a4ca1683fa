//! Engagement analysis as a capability (the seam of engineering.md; docs/spec/api.md, Engagement;
//! docs/spec/engagement.md §3): `POST /api/v1/engagement`, job operation `engagement`.

use crate::validate::Measure;
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
use crate::verify::Verification;
use crate::verify::own::{self, Extrusion};

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
    /// The program of the request's `candidate` cut on the plan-view stock extruded
    /// (docs/spec/verify.md §9.2): rapids through material, neck, shank and holder contact and
    /// the air share; the request gives no finished shape, so no gouge or material left. Absent
    /// when the request turns verification off or the answer has no program (no a_p).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<Verification>,
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
        let grid = verification_grid(request, &context.tool)?;
        let result = super::solve_in(
            request,
            &context.tool,
            context.machine.as_ref(),
            &physics(request, &context),
            run.control,
        )?;
        let answer = respond(request, context, result);
        charge_samples(&answer, run)?;
        verified(request, grid, answer, run)
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
        let grid = verification_grid(request, &context.tool)?;
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
        let answer = respond(request, context, EngagementSolution::Comparison(Comparison { candidates }));
        verified(request, grid, answer, run)
    }

    fn set_cut_resolution(request: &mut EngagementRequest, resolution: f64) {
        request.verification.get_or_insert_with(Default::default).resolution = Some(resolution);
    }

    /// The plan-view stock extruded less what the candidate's program (with its verification's
    /// header comments) cut, up to `upto_line`, coloured by what it cut (there is no part).
    fn cut_stock(
        request: &EngagementRequest,
        context: Resolved<Tool>,
        upto_line: Option<usize>,
        units: crate::units::Units,
        run: &Run<'_>,
    ) -> Result<Option<Vec<u8>>, SolverError> {
        let grid = verification_grid(request, &context.tool)?;
        let answer = Self::solve(request, context, run)?;
        let Some((model, grid)) = own_model(request, grid, &answer)? else {
            return Ok(None);
        };
        let ask = own::StockAsk { upto_line, units };
        own::partless_cut_stock::<EngagementCapability>(&model, grid, request, &answer, &answer.tool, ask, run)
    }

    /// The candidate asked for is the one verified: its program is the one written.
    fn set_programmed(request: &mut EngagementRequest, output: &OutputOptions) {
        if output.candidate.is_some() {
            request.candidate = output.candidate;
        }
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
        crate::validate::positive("plunge_feed", feed, Measure::Feed)?;
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
        verification: None,
    }
}

/// The xy rectangle of the plan-view stock as the request gives it (its outlines' points, or the
/// bitmap's cells), `None` for a stock the solve refuses (which names its field).
fn stock_extent(stock: &Stock) -> Option<([f64; 2], [f64; 2])> {
    let mut points: Vec<[f64; 2]> = Vec::new();
    match (&stock.polygon, &stock.polygons, &stock.bitmap) {
        (Some(polygon), None, None) => points.extend(polygon.iter().copied()),
        (None, Some(polygons), None) => {
            points.extend(polygons.iter().flat_map(|polygon| polygon.outer.iter().copied()))
        }
        (None, None, Some(bitmap)) => {
            let [x, y] = bitmap.origin;
            points.push([x, y]);
            points.push([x + bitmap.cell * f64::from(bitmap.width), y + bitmap.cell * f64::from(bitmap.height)]);
        }
        _ => return None,
    }
    let in_range = |value: f64| value.is_finite() && value.abs() <= crate::validate::MAX_COORDINATE;
    if points.is_empty() || !points.iter().flatten().all(|value| in_range(*value)) {
        return None;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for [x, y] in points {
        lo = [lo[0].min(x), lo[1].min(y)];
        hi = [hi[0].max(x), hi[1].max(y)];
    }
    (hi[0] > lo[0] && hi[1] > lo[1]).then_some((lo, hi))
}

/// The stock's xy extent and the verification's grid over it.
type StockGrid = (([f64; 2], [f64; 2]), own::Grid);

/// The grid of the verification over the stock's extent, checked before any work (whether or
/// not the answer will have a program): a resolution over the memory limit is refused up front.
fn verification_grid(request: &EngagementRequest, tool: &Tool) -> Result<Option<StockGrid>, SolverError> {
    let options = request.verification.unwrap_or_default();
    if !options.enabled || !tool.radius.is_finite() || tool.radius <= 0.0 {
        return Ok(None);
    }
    let Some(extent) = stock_extent(&request.stock) else {
        return Ok(None);
    };
    Ok(Some((extent, own::grid(extent, tool, &options)?)))
}

/// The model the program of the request's candidate is cut on: the plan-view stock extruded
/// from 1 mm under the cut up to `stock_top_z` (earlier cuts removed), and its grid; `None`
/// without a verification or a program.
fn own_model(
    request: &EngagementRequest,
    grid: Option<StockGrid>,
    answer: &EngagementAnswer,
) -> Result<Option<(Extrusion, own::Grid)>, SolverError> {
    let Some(((lo, hi), grid)) = grid else {
        return Ok(None);
    };
    let index = request.candidate.unwrap_or(0);
    let Some(post) = answer.result.candidates().get(index).map(|candidate| &candidate.post) else {
        return Ok(None);
    };
    if post.axial_depth.is_none() {
        // No a_p: no program.
        return Ok(None);
    }
    let top = post.stock_top_z;
    let context = Resolved {
        tool: answer.tool.clone(),
        machine: answer.machine.clone(),
        material: answer.material.clone(),
        other_tools: Vec::new(),
    };
    let region = request.validate(&context.tool, context.machine.as_ref(), &physics(request, &context))?.region;
    let earlier = request.stock.previous_cuts.len();
    let model = Extrusion {
        lo,
        hi,
        top,
        inside: Box::new(move |x, y| region.contains(super::P2::new(x, y), &mut 0)),
        description: format!(
            "stock: the plan-view stock{} extruded from 1 mm under the program's lowest tip up to height {top:.3} mm; part: \
             none (the request gives no finished shape), so only rapids through material, neck, shank and holder \
             contact and the air share are checked",
            if earlier > 0 { format!(" less its {earlier} earlier cut(s)") } else { String::new() }
        ),
    };
    Ok(Some((model, grid)))
}

/// `answer` with the program of the request's candidate cut on its model ([`own_model`]): its
/// `verification`, and the warnings and program header comments of what that found, on that
/// candidate.
fn verified(
    request: &EngagementRequest,
    grid: Option<StockGrid>,
    mut answer: EngagementAnswer,
    run: &Run<'_>,
) -> Result<EngagementAnswer, SolverError> {
    let Some((model, grid)) = own_model(request, grid, &answer)? else {
        return Ok(answer);
    };
    let index = request.candidate.unwrap_or(0);
    let program = own::program::<EngagementCapability>(request, &answer, run)?;
    let mut verification = own::verify(&model, grid, &program, &answer.tool, own::Limits::WITHOUT_PART, run)?;
    let candidate = match &mut answer.result {
        EngagementSolution::Single(result) => result.as_mut(),
        EngagementSolution::Comparison(comparison) => &mut comparison.candidates[index],
    };
    own::report(&mut verification, &mut candidate.warnings, &mut candidate.post.description);
    answer.verification = Some(verification);
    Ok(answer)
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
            feed_field: job.feed_mode.field(),
            max_spindle_rpm: job.machine_speed,
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

#[cfg(test)]
mod verification_tests {
    use super::*;
    use crate::tool::ToolRef;
    use crate::verify::{FindingKind, VerificationOptions};

    /// The docs/spec/api.md example, 2 mm deep; `tool` changes the tool.
    fn request(tool: serde_json::Value) -> (EngagementRequest, Resolved<Tool>) {
        let request: EngagementRequest = serde_json::from_value(serde_json::json!({
            "tool": tool, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
            "path": [[-10, 20], [70, 20]], "spindle_rpm": 3000, "feed_per_tooth": 0.05, "axial_depth": 2
        }))
        .unwrap();
        let ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        let context = Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
        (request, context)
    }

    fn fanuc(request: &EngagementRequest, answer: &EngagementAnswer) -> String {
        let output = OutputOptions { dialect: Some(crate::gcode::Dialect::Fanuc), ..OutputOptions::default() };
        crate::capability::program::<EngagementCapability>(request, answer, &output, Control::default()).unwrap()
    }

    #[test]
    fn the_slot_cuts_clean_on_the_stock_extruded() {
        let (request, context) = request(serde_json::json!({"kind": "flat", "radius": 5}));
        let answer = EngagementCapability::solve(&request, context, &Run::default()).unwrap();
        let verification = answer.verification.as_ref().expect("verified");
        assert!(verification.ok, "{verification:#?}");
        // The slot: 60 long, 10 wide, 2 deep, within the grid's cells.
        let removed = verification.removed_volume_mm3;
        assert!((removed / 1200.0 - 1.0).abs() < 0.03, "{removed}");
        assert!(!fanuc(&request, &answer).contains("WARNING"));
    }

    #[test]
    fn verification_can_be_turned_off_and_a_grid_too_fine_is_refused_up_front() {
        let (mut request, context) = request(serde_json::json!({"kind": "flat", "radius": 5}));
        request.verification = Some(VerificationOptions { enabled: false, resolution: None });
        let answer = EngagementCapability::solve(&request, context.clone(), &Run::default()).unwrap();
        assert!(answer.verification.is_none());
        request.verification = Some(VerificationOptions { enabled: true, resolution: Some(0.001) });
        let error = EngagementCapability::solve(&request, context.clone(), &Run::default()).unwrap_err();
        assert_eq!((error.code(), error.field()), (ErrorCode::GridMemory, Some("verification.resolution")));
        // Without a_p there is no program to verify.
        request.verification = None;
        request.axial_depth = None;
        let answer = EngagementCapability::solve(&request, context, &Run::default()).unwrap();
        assert!(answer.verification.is_none());
    }

    /// The numbers of a block (its line number, `+` signs and words' letters left out): `G01
    /// X70.0000 Y20.0000 Z-2.0000 F300` and `7 L X+70.0000 Y+20.0000 Z-2.0000 R0 F300` both give
    /// the point 70, 20, -2 first.
    fn point_of(block: &str) -> Vec<f64> {
        block
            .split_ascii_whitespace()
            .filter(|word| matches!(word.as_bytes().first(), Some(b'X' | b'Y' | b'Z')))
            .filter_map(|word| word[1..].parse().ok())
            .collect()
    }

    /// A warning in any post's program names the line of that program where the move is, the
    /// same move the Fanuc program's warning names (grbl has no `%` line, Heidenhain ISO and
    /// Klartext number their blocks, Haas's smoothing adds a line).
    #[test]
    fn every_posts_warnings_name_its_own_lines() {
        let (request, context) = request(serde_json::json!({"kind": "flat", "radius": 5, "stickout": 1.5}));
        let mut answer = EngagementCapability::solve(&request, context, &Run::default()).unwrap();
        let at_lines = |program: &str| -> Vec<usize> {
            program.lines().filter_map(|line| line.split_once(" AT LINE ")?.1.split_once(':')?.0.parse().ok()).collect()
        };
        let named = |program: &str| -> Vec<Vec<f64>> {
            let lines: Vec<&str> = program.lines().collect();
            at_lines(program).iter().map(|line| point_of(lines[line - 1])).collect()
        };
        for smoothing in [None, Some(2)] {
            answer.machine = Some(
                serde_json::from_value(
                    serde_json::json!({"block_time_ms": 2, "max_feed": 10000, "haas_smoothing": smoothing}),
                )
                .unwrap(),
            );
            let fanuc = fanuc(&request, &answer);
            let expected = named(&fanuc);
            assert!(expected.len() >= 2 && expected.iter().all(|point| !point.is_empty()), "{fanuc}");
            for dialect in crate::gcode::Dialect::ALL {
                let output = OutputOptions { dialect: Some(dialect), ..OutputOptions::default() };
                let program =
                    crate::capability::program::<EngagementCapability>(&request, &answer, &output, Control::default())
                        .unwrap();
                assert_eq!(named(&program), expected, "{dialect:?}:\n{program}");
            }
        }
    }

    /// A tool held 1.5 mm above its tip cutting 2 deep: the holder runs through the stock, found
    /// on the cutting move, warned, and in the program's header.
    #[test]
    fn a_holder_too_close_to_the_tip_touches_the_stock() {
        let (request, context) = request(serde_json::json!({"kind": "flat", "radius": 5, "stickout": 1.5}));
        let answer = EngagementCapability::solve(&request, context, &Run::default()).unwrap();
        let verification = answer.verification.as_ref().unwrap();
        assert!(!verification.ok);
        let holder: Vec<_> =
            verification.findings.iter().filter(|finding| finding.kind == FindingKind::HolderContact).collect();
        assert!(!holder.is_empty(), "{:#?}", verification.findings);
        let EngagementSolution::Single(result) = &answer.result else { unreachable!("one path") };
        assert!(result.warnings.iter().any(|warning| warning.code == "W_VERIFY_HOLDER_CONTACT"));
        let program = fanuc(&request, &answer);
        let lines: Vec<&str> = program.lines().collect();
        let line = holder[0].line.unwrap();
        assert!(program.contains(&format!("(WARNING HOLDER CONTACT AT LINE {line}: ")), "{program}");
        // 0.5 mm deep (the holder's face 1.5 above the tip at Z-2, the stock's top at 0), on the
        // plunge, the cut and the retract: moves of the program.
        for finding in &holder {
            assert!((finding.depth - 0.5).abs() < 1e-9, "{finding:?}");
            assert!(lines[finding.line.unwrap() - 1].starts_with("G0"), "{program}");
        }
        assert!(holder.iter().any(|finding| lines[finding.line.unwrap() - 1].starts_with("G01 X70.")), "{program}");
    }
}
