//! An engagement request validated into a [`Job`] before any heavy work (docs/spec/engagement.md §9
//! `E_INPUT`, `E_PATH`, and the size limits): paths read into routes, the stock into a region.

use crate::error::ErrorCode;

use super::arcs::SpindleDirection;
use super::bbox_tree::BBox;
use super::force::ForceModel;
use super::heights::{CORNER_BANDS, Loads};
use super::kienzle::SinPower;
use super::limits::natural_frequencies;
use super::outline::Outline;
use super::request::{
    Direction, EngagementRequest, Engine, FeedBasis, PathInput, PathSegments, Representative, SegmentInput, Stock,
};
use super::segments::{Route, Shape};
use super::stock::{Base, Bitmap, Cut, Region, decode_base64};
use super::{
    DEFAULT_BURR_DISENGAGE_DEG, DEFAULT_CHIPPING_DISENGAGE_DEG, MAX_CANDIDATES, MAX_CHORDS, MAX_DOT_ROWS, MAX_FLUTES,
    MAX_GRID_DOTS, MAX_SAMPLES, MAX_SEGMENTS, MAX_STOCK_VERTICES, P2,
};
use crate::error::{SolverError, Warning};
use crate::gcode::reader::{MoveKind, Plane, ReadOptions, read as read_program};
use crate::machine::{BlockRule, MachineProfile, RuleSettings, SpindleLimits};
use crate::material::{DEFAULT_RADIAL_RATIO, Kienzle};
use crate::planar::signed_area;
use crate::tool::{Tool, ToolKind};
use crate::validate::{self, finite, non_negative, positive, positive_at_most};

/// How the flute counts share the feed (docs/spec/engagement.md §2.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FeedMode {
    /// Constant f_z (mm/tooth).
    PerTooth(f64),
    /// Constant V_f (mm/min).
    Rate(f64),
}

/// A validated feed plan request.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PlanJob {
    pub target: f64,
    pub max_feed: f64,
    pub flute_count: u32,
    pub basis: FeedBasis,
    pub tolerance: f64,
    pub min_block_length: f64,
}

/// One validated candidate path.
#[derive(Debug, Clone)]
pub(crate) struct CandidateJob {
    pub name: Option<String>,
    pub route: Route,
    pub warnings: Vec<Warning>,
    /// a_p of this path: its own, else the request's, else from its Z under the stock top.
    pub axial_depth: Option<f64>,
    /// The Z of the tool tip when a_p came from it (the program cuts there).
    pub cut_z: Option<f64>,
    /// Kienzle's force model at this path's a_p, with `kienzle` (or `material`).
    pub force: Option<ForceModel>,
}

/// A validated request: every number finite and in range, the geometry built.
#[derive(Debug, Clone)]
pub(crate) struct Job {
    pub radius: f64,
    pub flute_counts: Vec<u32>,
    pub tool_flutes: u32,
    pub spindle_rpm: f64,
    pub feed_mode: FeedMode,
    pub thickness_limit: Option<f64>,
    pub time_limit: Option<f64>,
    pub representative: Representative,
    pub direction: SpindleDirection,
    pub engine: Engine,
    pub step: f64,
    pub grid: Option<f64>,
    pub burr_disengage: f64,
    pub chipping_disengage: f64,
    pub radial_depth_min: Option<f64>,
    pub radial_depth_max: Option<f64>,
    pub spike_threshold: Option<f64>,
    pub min_feed_per_tooth: Option<f64>,
    pub stock_top_z: f64,
    pub clearance: f64,
    pub plan: Option<PlanJob>,
    /// The block-time rule of the program, at the nominal feed of the tool's flute count.
    pub rule: Option<BlockRule>,
    /// Apply the arc-feed correction on arcs of the path.
    pub arc_feed: bool,
    /// The machine's spindle limits (checked only with a force model).
    pub spindle: SpindleLimits,
    /// The tool's natural frequencies, Hz, and their directions.
    pub natural: Vec<(f64, &'static str)>,
    pub contact_dots: bool,
    pub region: Region,
    /// Warnings of the stock and the machine, for every candidate.
    pub shared_warnings: Vec<Warning>,
    pub candidates: Vec<CandidateJob>,
    pub single: bool,
}

impl FeedMode {
    /// f_z,k for `flutes` teeth at `spindle_rpm`.
    pub(crate) fn feed_per_tooth(self, flutes: u32, spindle_rpm: f64) -> f64 {
        match self {
            Self::PerTooth(fz) => fz,
            Self::Rate(vf) => vf / (f64::from(flutes) * spindle_rpm),
        }
    }

    /// V_f,k for `flutes` teeth at `spindle_rpm`, mm/min.
    pub(crate) fn feed(self, flutes: u32, spindle_rpm: f64) -> f64 {
        match self {
            Self::PerTooth(fz) => f64::from(flutes) * fz * spindle_rpm,
            Self::Rate(vf) => vf,
        }
    }
}

pub use crate::validate::MAX_COORDINATE;

fn point(field: &str, p: [f64; 2]) -> Result<P2, SolverError> {
    let [x, y] = validate::point(field, p, MAX_COORDINATE)?;
    Ok(P2::new(x, y))
}

/// `value` must be positive and at most `limit`.
fn bounded(field: &str, value: f64, limit: f64) -> Result<f64, SolverError> {
    positive_at_most(field, value, limit)
}

fn optional(
    field: &str,
    value: Option<f64>,
    check: fn(&str, f64) -> Result<f64, SolverError>,
) -> Result<Option<f64>, SolverError> {
    value.map(|v| check(field, v)).transpose()
}

fn too_large(field: &str, what: &str, count: usize, limit: usize) -> SolverError {
    SolverError::new(ErrorCode::TooLarge, format!("{what}: {count} exceeds the limit of {limit}")).at(field)
}

/// A path's pieces, zero-length ones dropped with a warning (docs/spec/engagement.md §2.3).
pub(crate) fn read_path(input: &PathInput, field: &str, warnings: &mut Vec<Warning>) -> Result<Route, SolverError> {
    read_path_levels(input, field, warnings, &mut Vec::new())
}

/// [`read_path`], adding to `levels` the Z (mm) and line of both ends of every XY feed move of
/// a G-code path whose Z is known.
fn read_path_levels(
    input: &PathInput,
    field: &str,
    warnings: &mut Vec<Warning>,
    levels: &mut Vec<(f64, usize)>,
) -> Result<Route, SolverError> {
    let mut shapes: Vec<(Shape, bool, usize)> = Vec::new();
    let mut dropped = Vec::new();
    match input {
        PathInput::Points(points) => {
            if points.len() > MAX_SEGMENTS + 1 {
                return Err(too_large(field, "path points", points.len(), MAX_SEGMENTS + 1));
            }
            let mut previous: Option<P2> = None;
            for (index, p) in points.iter().enumerate() {
                let here = point(&format!("{field}[{index}]"), *p)?;
                if let Some(from) = previous {
                    let shape = Shape::Line { from, to: here };
                    if shape.length() <= 1e-9 {
                        dropped.push(format!("{field}[{index}]"));
                    } else {
                        shapes.push((shape, false, index - 1));
                    }
                }
                previous = Some(here);
            }
        }
        PathInput::Segments(PathSegments { gcode: Some(text), start, segments }) => {
            if start.is_some() || segments.is_some() {
                return Err(SolverError::new(
                    ErrorCode::Path,
                    "give the path as gcode or as start and segments, not both",
                )
                .at(format!("{field}.gcode")));
            }
            read_gcode_path(text, &format!("{field}.gcode"), &mut shapes, &mut dropped, levels)?;
        }
        PathInput::Segments(program) => {
            let start = program.start.ok_or_else(|| {
                SolverError::new(ErrorCode::Path, "the path needs a start point [x, y]").at(format!("{field}.start"))
            })?;
            let segments = program.segments.as_ref().ok_or_else(|| {
                SolverError::new(ErrorCode::Path, "the path needs segments").at(format!("{field}.segments"))
            })?;
            if segments.len() > MAX_SEGMENTS {
                return Err(too_large(&format!("{field}.segments"), "path segments", segments.len(), MAX_SEGMENTS));
            }
            let mut from = point(&format!("{field}.start"), start)?;
            for (index, segment) in segments.iter().enumerate() {
                let here = format!("{field}.segments[{index}]");
                match segment {
                    SegmentInput::Line { to, rapid } => {
                        let to = point(&format!("{here}.to"), *to)?;
                        let shape = Shape::Line { from, to };
                        if shape.length() <= 1e-9 {
                            dropped.push(here);
                        } else {
                            shapes.push((shape, *rapid, index));
                        }
                        from = to;
                    }
                    SegmentInput::Arc { to, center, dir } => {
                        let to = point(&format!("{here}.to"), *to)?;
                        let centre = point(&format!("{here}.center"), *center)?;
                        shapes.push((
                            arc_shape(from, to, centre, *dir == Direction::Cw, 0, &format!("{here}.center"))?,
                            false,
                            index,
                        ));
                        from = to;
                    }
                }
            }
        }
    }
    if shapes.is_empty() {
        return Err(SolverError::new(
            ErrorCode::Path,
            "the path is empty: it needs at least one move of non-zero length",
        )
        .at(field));
    }
    if let Some(first) = dropped.first() {
        warnings.push(Warning::new(
            "W_SEGMENT_ZERO",
            format!("{} zero-length segment(s) dropped (first: {first})", dropped.len()),
        ));
    }
    Ok(Route::new(shapes))
}

/// The arc from `from` to `to` about `centre` (a full turn when they coincide), plus
/// `extra_turns`; refused when the centre is not equidistant from both ends.
fn arc_shape(
    from: P2,
    to: P2,
    centre: P2,
    clockwise: bool,
    extra_turns: u32,
    field: &str,
) -> Result<Shape, SolverError> {
    let (r0, r1) = ((from - centre).norm(), (to - centre).norm());
    if r0 <= 1e-9 {
        return Err(SolverError::new(ErrorCode::Path, "the arc centre coincides with its start point").at(field));
    }
    if (r0 - r1).abs() > 1e-6 * r0.max(r1) {
        return Err(SolverError::new(
            ErrorCode::Path,
            format!("the arc centre is {r0:.6} mm from the start point but {r1:.6} mm from the end point"),
        )
        .at(field));
    }
    let start_angle = (from.y - centre.y).atan2(from.x - centre.x);
    let end_angle = (to.y - centre.y).atan2(to.x - centre.x);
    let turn = std::f64::consts::TAU;
    let full = (to - from).norm() <= 1e-9 * r0.max(1.0);
    let sweep = match (clockwise, full) {
        (_, true) => turn,
        (false, false) => (end_angle - start_angle).rem_euclid(turn),
        (true, false) => (start_angle - end_angle).rem_euclid(turn),
    } + turn * f64::from(extra_turns);
    let sweep = if clockwise { -sweep } else { sweep };
    Ok(Shape::Arc { centre, radius: r0, start: start_angle, sweep })
}

/// The XY moves of a G-code program (read by the shared reader) as path pieces, each numbered by
/// its program line (the samples' `segment`). Moves before the first fully known XY position are
/// skipped (the tool's position is unknown there); pure Z moves have no length in the plane and
/// are dropped like other zero-length segments.
fn read_gcode_path(
    text: &str,
    field: &str,
    shapes: &mut Vec<(Shape, bool, usize)>,
    dropped: &mut Vec<String>,
    levels: &mut Vec<(f64, usize)>,
) -> Result<(), SolverError> {
    let program = read_program(text, field, &ReadOptions { max_lines: MAX_SEGMENTS, ..ReadOptions::default() })?;
    for step in &program.moves {
        let (Some(fx), Some(fy), Some(tx), Some(ty)) = (step.from[0], step.from[1], step.to[0], step.to[1]) else {
            continue;
        };
        let (from, to) = (P2::new(fx, fy), P2::new(tx, ty));
        let here = format!("{field} (line {})", step.line);
        let (shape, rapid) = match step.kind {
            MoveKind::Rapid => (Shape::Line { from, to }, true),
            MoveKind::Linear => (Shape::Line { from, to }, false),
            MoveKind::Arc { centre, clockwise, extra_turns } => {
                if step.modal.plane != Plane::Xy {
                    return Err(SolverError::new(
                        ErrorCode::Path,
                        format!("line {}: arcs must be in the XY plane (G17) for an engagement path", step.line),
                    )
                    .at(field));
                }
                (arc_shape(from, to, P2::new(centre[0], centre[1]), clockwise, extra_turns, field)?, false)
            }
        };
        if shape.length() <= 1e-9 {
            dropped.push(here);
        } else {
            if !rapid {
                levels.extend([step.from[2], step.to[2]].into_iter().flatten().map(|z| (z, step.line)));
            }
            shapes.push((shape, rapid, step.line));
        }
    }
    Ok(())
}

/// A ring of distinct points (closing repeat and consecutive duplicates removed).
fn read_ring(field: &str, points: &[[f64; 2]]) -> Result<Vec<P2>, SolverError> {
    let mut ring: Vec<P2> = Vec::with_capacity(points.len());
    for (index, p) in points.iter().enumerate() {
        let q = point(&format!("{field}[{index}]"), *p)?;
        if ring.last().is_none_or(|last| (q - last).norm() > 1e-12) {
            ring.push(q);
        }
    }
    while ring.len() > 1 && ring.first().zip(ring.last()).is_some_and(|(a, b)| (a - b).norm() <= 1e-12) {
        ring.pop();
    }
    if ring.len() < 3 {
        return Err(SolverError::new(
            ErrorCode::Stock,
            format!("a stock ring needs at least 3 distinct points (got {})", ring.len()),
        )
        .at(field));
    }
    Ok(ring)
}

/// The stock; `radius` (the tool's) sizes the index of the outline's edges.
fn read_stock(stock: &Stock, radius: f64, warnings: &mut Vec<Warning>) -> Result<(Region, Vec<String>), SolverError> {
    let given =
        [stock.polygon.is_some(), stock.polygons.is_some(), stock.bitmap.is_some()].iter().filter(|g| **g).count();
    if given != 1 {
        return Err(SolverError::input("stock", "give exactly one of stock.polygon, stock.polygons or stock.bitmap"));
    }
    if !stock.holes.is_empty() && stock.polygon.is_none() {
        return Err(SolverError::input(
            "stock.holes",
            "holes belong to stock.polygon; with stock.polygons give each region's holes",
        ));
    }
    let base = if let Some(bitmap) = &stock.bitmap {
        let origin = point("stock.bitmap.origin", bitmap.origin)?;
        let cell = bounded("stock.bitmap.cell", bitmap.cell, MAX_COORDINATE)?;
        if bitmap.width == 0 || bitmap.height == 0 {
            return Err(SolverError::input("stock.bitmap.width", "the bitmap needs at least one row and one column"));
        }
        let cells = u64::from(bitmap.width) * u64::from(bitmap.height);
        if cells > MAX_GRID_DOTS {
            return Err(SolverError::new(
                ErrorCode::GridMemory,
                format!("the bitmap has {cells} cells; the limit is {MAX_GRID_DOTS}"),
            )
            .at("stock.bitmap"));
        }
        let bytes = decode_base64(&bitmap.data).ok_or_else(|| {
            SolverError::new(ErrorCode::Stock, "stock.bitmap.data is not valid base64").at("stock.bitmap.data")
        })?;
        let needed = cells.div_ceil(8);
        if bytes.len() as u64 != needed {
            return Err(SolverError::new(
                ErrorCode::Stock,
                format!(
                    "stock.bitmap.data holds {} bytes; {} × {} cells need {needed}",
                    bytes.len(),
                    bitmap.width,
                    bitmap.height
                ),
            )
            .at("stock.bitmap.data"));
        }
        if bytes.iter().all(|b| *b == 0) {
            warnings.push(Warning::new("W_STOCK_EMPTY", "the bitmap holds no material"));
        }
        Base::Bitmap(Bitmap { origin, cell, width: bitmap.width as usize, height: bitmap.height as usize, bytes })
    } else {
        let mut rings = Vec::new();
        let mut fields = Vec::new();
        let mut vertices = 0_usize;
        let mut add = |field: String, points: &[[f64; 2]]| -> Result<(), SolverError> {
            vertices += points.len();
            if vertices > MAX_STOCK_VERTICES {
                return Err(too_large("stock", "stock vertices", vertices, MAX_STOCK_VERTICES));
            }
            rings.push(read_ring(&field, points)?);
            fields.push(field);
            Ok(())
        };
        if let Some(outline) = &stock.polygon {
            add("stock.polygon".to_owned(), outline)?;
            for (index, hole) in stock.holes.iter().enumerate() {
                add(format!("stock.holes[{index}]"), hole)?;
            }
        }
        if let Some(polygons) = &stock.polygons {
            if polygons.is_empty() {
                return Err(SolverError::new(ErrorCode::Stock, "stock.polygons is empty").at("stock.polygons"));
            }
            for (index, polygon) in polygons.iter().enumerate() {
                add(format!("stock.polygons[{index}].outer"), &polygon.outer)?;
                for (hole_index, hole) in polygon.holes.iter().enumerate() {
                    add(format!("stock.polygons[{index}].holes[{hole_index}]"), hole)?;
                }
            }
        }
        let outline = Outline::new(rings, radius);
        let crossing = outline.first_crossing().map_err(|_| {
            SolverError::new(
                ErrorCode::TooLarge,
                "the stock outline crowds too many edges into the same place to check it for crossings",
            )
            .at("stock")
        })?;
        if let Some(((ring_a, vertex_a), (ring_b, vertex_b))) = crossing {
            let name = |ring: usize| fields.get(ring).cloned().unwrap_or_else(|| "stock".to_owned());
            let message = if ring_a == ring_b {
                format!(
                    "the stock outline crosses itself: edges from vertex {vertex_a} and vertex {vertex_b} of {} meet",
                    name(ring_a)
                )
            } else {
                format!(
                    "stock rings cross or touch: {}[{vertex_a}] and {}[{vertex_b}] (overlapping regions would cancel under the even-odd rule)",
                    name(ring_a),
                    name(ring_b)
                )
            };
            return Err(SolverError::new(ErrorCode::Stock, message).at(format!("{}[{vertex_a}]", name(ring_a))));
        }
        // After the crossing test, so a bow tie is reported as crossing, not as flat.
        for (ring, field) in outline.rings().iter().zip(&fields) {
            if signed_area(ring).abs() <= 1e-12 {
                return Err(SolverError::new(ErrorCode::Stock, "the stock ring has zero area").at(field.clone()));
            }
        }
        Base::Polygons(outline)
    };
    let mut cuts = Vec::new();
    let mut cut_fields = Vec::new();
    for (index, previous) in stock.previous_cuts.iter().enumerate() {
        let field = format!("stock.previous_cuts[{index}]");
        let radius = bounded(&format!("{field}.radius"), previous.radius, MAX_COORDINATE)?;
        let route = read_path(&previous.path, &format!("{field}.path"), warnings)?;
        let shapes = route.pieces.iter().filter(|p| !p.rapid).map(|p| p.shape).collect();
        cuts.push(Cut::new(shapes, radius));
        cut_fields.push(field);
    }
    Ok((Region { base, cuts }, cut_fields))
}

impl EngagementRequest {
    /// Validates the request against `tool` (already resolved from `self.tool`).
    /// Checks every field, with `machine` resolved from `self.machine`.
    pub(crate) fn validate(
        &self,
        tool: &Tool,
        machine: Option<&MachineProfile>,
        physics: &Physics,
    ) -> Result<Job, SolverError> {
        tool.validate("tool.")?;
        let radius = bounded("tool.radius", tool.radius, MAX_COORDINATE)?;
        let spindle_rpm = bounded("spindle_rpm", self.spindle_rpm, 1e6)?;
        let feed_mode = match (self.feed_per_tooth, self.feed) {
            (Some(fz), None) => FeedMode::PerTooth(bounded("feed_per_tooth", fz, 1e3)?),
            (None, Some(vf)) => FeedMode::Rate(bounded("feed", vf, 1e7)?),
            (Some(_), Some(_)) => {
                return Err(SolverError::input(
                    "feed",
                    "give feed_per_tooth (constant f_z) or feed (constant V_f), not both",
                ));
            }
            (None, None) => {
                return Err(SolverError::input(
                    "feed_per_tooth",
                    "feed_per_tooth (mm/tooth) or feed (mm/min) is required",
                ));
            }
        };
        let flute_counts = match &self.flute_counts {
            None => vec![tool.flutes],
            Some(counts) => {
                if counts.is_empty() {
                    return Err(SolverError::input("flute_counts", "flute_counts needs at least one flute count"));
                }
                if counts.len() > MAX_FLUTES as usize {
                    return Err(too_large("flute_counts", "flute counts", counts.len(), MAX_FLUTES as usize));
                }
                for (index, k) in counts.iter().enumerate() {
                    let field = format!("flute_counts[{index}]");
                    if !(1..=MAX_FLUTES).contains(k) {
                        return Err(SolverError::input(
                            field,
                            format!("a flute count must be 1 to {MAX_FLUTES} (got {k})"),
                        ));
                    }
                    if counts[..index].contains(k) {
                        return Err(SolverError::input(field, format!("flute count {k} is listed twice")));
                    }
                }
                counts.clone()
            }
        };
        let thickness_limit = optional("thickness_limit", self.thickness_limit, positive)?;
        let time_limit = optional("time_limit_s", self.time_limit_s, positive)?;
        let step = match self.step {
            Some(step) => bounded("step", step, MAX_COORDINATE)?,
            None => 2.0 * radius / 50.0,
        };
        let grid = match (self.engine, self.grid) {
            (Engine::Exact, Some(_)) => {
                return Err(SolverError::input("grid", "grid applies only to engine \"dots\""));
            }
            (Engine::Exact, None) => None,
            (Engine::Dots, Some(g)) => Some(bounded("grid", g, MAX_COORDINATE)?),
            (Engine::Dots, None) => Some(match &self.stock.bitmap {
                Some(bitmap) if bitmap.cell.is_finite() && bitmap.cell > 0.0 => bitmap.cell,
                _ => 2.0 * radius / 200.0,
            }),
        };
        let angle = |field: &str, value: Option<f64>, default: f64| -> Result<f64, SolverError> {
            let v = finite(field, value.unwrap_or(default))?;
            if (0.0..=180.0).contains(&v) {
                Ok(v)
            } else {
                Err(SolverError::input(field, format!("{field} must be in [0, 180] (got {v})")))
            }
        };
        let burr_disengage = angle("burr_disengage_deg", self.burr_disengage_deg, DEFAULT_BURR_DISENGAGE_DEG)?;
        let chipping_disengage =
            angle("chipping_disengage_deg", self.chipping_disengage_deg, DEFAULT_CHIPPING_DISENGAGE_DEG)?;
        let radial_depth_min = optional("radial_depth_min", self.radial_depth_min, non_negative)?;
        let radial_depth_max = optional("radial_depth_max", self.radial_depth_max, positive)?;
        if let (Some(low), Some(high)) = (radial_depth_min, radial_depth_max)
            && low > high
        {
            return Err(SolverError::input(
                "radial_depth_min",
                format!("radial_depth_min {low} exceeds radial_depth_max {high}"),
            ));
        }
        let spike_threshold = optional("spike_threshold_deg", self.spike_threshold_deg, positive)?;
        let min_feed_per_tooth = optional("min_feed_per_tooth", self.min_feed_per_tooth, positive)?;
        let axial_depth = self.axial_depth.map(|d| bounded("axial_depth", d, MAX_COORDINATE)).transpose()?;
        let (kienzle, spindle) = self.kienzle(physics)?;
        // A Z in the plane of the coordinates.
        let z_value = |field: &str, z: f64| -> Result<f64, SolverError> {
            let z = finite(field, z)?;
            if z.abs() > MAX_COORDINATE {
                return Err(SolverError::input(field, format!("{field} must lie within ±{MAX_COORDINATE} mm")));
            }
            Ok(z)
        };
        let stock_top_z = z_value("stock_top_z", self.stock_top_z.unwrap_or(0.0))?;
        let clearance = bounded("clearance", self.clearance.unwrap_or(5.0), MAX_COORDINATE)?;
        // Warnings of the whole request, repeated in every candidate's answer.
        let mut shared_warnings = Vec::new();
        let plan = self
            .feed_plan
            .as_ref()
            .map(|plan| -> Result<PlanJob, SolverError> {
                let target = bounded("feed_plan.target_thickness", plan.target_thickness, 1e3)?;
                let max_feed = plan.max_feed.or(machine.map(|m| m.max_feed)).ok_or_else(|| {
                    SolverError::input(
                        "feed_plan.max_feed",
                        "feed_plan.max_feed (mm/min) is required unless the request names a machine",
                    )
                })?;
                let max_feed = bounded("feed_plan.max_feed", max_feed, 1e7)?;
                if let Some(machine) = machine
                    && max_feed > machine.max_feed
                {
                    shared_warnings.push(Warning::new(
                        "W_FEED_ABOVE_MACHINE_MAX",
                        format!(
                            "feed_plan.max_feed {max_feed} mm/min is above the machine's max_feed {} mm/min: the \
                             control will not reach it",
                            machine.max_feed
                        ),
                    ));
                }
                let flute_count = plan.flute_count.unwrap_or(tool.flutes);
                if !(1..=MAX_FLUTES).contains(&flute_count) {
                    return Err(SolverError::input(
                        "feed_plan.flute_count",
                        format!("a flute count must be 1 to {MAX_FLUTES} (got {flute_count})"),
                    ));
                }
                let tolerance = non_negative("feed_plan.tolerance", plan.tolerance.unwrap_or(0.05))?;
                let min_block_length =
                    non_negative("feed_plan.min_block_length", plan.min_block_length.unwrap_or(0.5))?;
                Ok(PlanJob { target, max_feed, flute_count, basis: plan.basis, tolerance, min_block_length })
            })
            .transpose()?;

        let rule = if self.block_time_ms.is_some() || machine.is_some() {
            let feed = feed_mode.feed(tool.flutes, spindle_rpm);
            let settings =
                RuleSettings { feed: Some(feed), block_time_ms: self.block_time_ms, ..RuleSettings::default() };
            let (rule, warnings) = BlockRule::resolve(&settings, machine)?;
            shared_warnings.extend(warnings);
            Some(rule)
        } else {
            None
        };
        let (region, _) = read_stock(&self.stock, radius, &mut shared_warnings)?;

        let cut_z = self.cut_z.map(|z| z_value("cut_z", z)).transpose()?;
        // Where a G-code path's own Z counts: only with an explicit stock top.
        let top_given = self.stock_top_z.is_some();
        // (name, path, its field, the field prefix of its own a_p and cut_z, those values)
        type Input<'a> = (Option<String>, &'a PathInput, String, String, Option<f64>, Option<f64>);
        let inputs: Vec<Input<'_>> = match (&self.path, &self.paths) {
            (Some(path), None) => vec![(None, path, "path".to_owned(), String::new(), None, None)],
            (None, Some(paths)) => {
                if paths.is_empty() {
                    return Err(SolverError::new(ErrorCode::Path, "paths is empty").at("paths"));
                }
                if paths.len() > MAX_CANDIDATES {
                    return Err(too_large("paths", "candidate paths", paths.len(), MAX_CANDIDATES));
                }
                paths
                    .iter()
                    .enumerate()
                    .map(|(i, c)| {
                        (
                            c.name.clone(),
                            &c.path,
                            format!("paths[{i}].path"),
                            format!("paths[{i}]."),
                            c.axial_depth,
                            c.cut_z,
                        )
                    })
                    .collect()
            }
            (Some(_), Some(_)) => {
                return Err(SolverError::input("paths", "give path or paths, not both"));
            }
            (None, None) => {
                return Err(SolverError::new(ErrorCode::Path, "the request needs a path").at("path"));
            }
        };
        let mut candidates = Vec::with_capacity(inputs.len());
        let mut total_samples = 0.0;
        let mut section_radii = 0.0_f64;
        for (name, input, field, prefix, own_depth, own_cut_z) in inputs {
            let own_depth =
                own_depth.map(|d| bounded(&format!("{prefix}axial_depth"), d, MAX_COORDINATE)).transpose()?;
            let own_cut_z = own_cut_z.map(|z| z_value(&format!("{prefix}cut_z"), z)).transpose()?;
            let mut warnings = Vec::new();
            let mut levels = Vec::new();
            let route = read_path_levels(input, &field, &mut warnings, &mut levels)?;
            let explicit = own_depth
                .map(|d| (d, format!("{prefix}axial_depth")))
                .or_else(|| axial_depth.map(|d| (d, "axial_depth".to_owned())));
            let level = if own_cut_z.is_some() || cut_z.is_some() || !top_given {
                None
            } else {
                program_level(&levels, &format!("{field}.gcode"), explicit.is_none(), &mut warnings)
            };
            let height = own_cut_z
                .map(|z| (z, format!("{prefix}cut_z")))
                .or_else(|| cut_z.map(|z| (z, "cut_z".to_owned())))
                .or(level);
            let (depth, path_z) = path_depth(explicit, height, stock_top_z, tool, &mut warnings)?;
            let force = kienzle.map(|values| force_model(&values, tool, depth, self.spindle_direction)).transpose()?;
            if force.as_ref().is_some_and(ForceModel::rounded) {
                // The sections of a rounded end: about one circle per band edge.
                section_radii = (CORNER_BANDS + 1) as f64 * radius;
            }
            total_samples += route.station_count(step);
            if total_samples > MAX_SAMPLES as f64 {
                return Err(SolverError::new(
                    ErrorCode::TooManySamples,
                    format!(
                        "the path(s) would need about {total_samples:.0} samples at step {step} mm; the limit is {MAX_SAMPLES}: use a larger step"
                    ),
                )
                .at("step"));
            }
            candidates.push(CandidateJob { name, route, warnings, axial_depth: depth, cut_z: path_z, force });
        }
        if let Some(g) = grid {
            // The dots engine rasterises earlier cuts' arcs as chords within g/100.
            let chords: f64 =
                region.cuts.iter().flat_map(|cut| cut.shapes.iter()).map(|shape| shape.chord_count(g / 100.0)).sum();
            if chords > MAX_CHORDS {
                return Err(SolverError::new(
                    ErrorCode::WorkLimit,
                    format!(
                        "the earlier cuts' arcs need {chords:.2e} chords at grid {g} mm; the limit is {MAX_CHORDS:.0e}: use a larger grid or engine \"exact\""
                    ),
                )
                .at("stock.previous_cuts"));
            }
        }
        if let (Some(g), Some(stock_box)) = (grid, region.bbox()) {
            let mut rows = 0.0;
            for candidate in &candidates {
                let height = check_grid(&candidate.route, stock_box, region.anchor(), radius, g)?;
                // Each sample scans the grid rows across the tool.
                rows += candidate.route.station_count(step) * (2.0 * radius / g).min(height);
            }
            if rows > MAX_DOT_ROWS {
                return Err(SolverError::new(
                    ErrorCode::WorkLimit,
                    format!(
                        "the dots engine would scan about {rows:.2e} grid rows (samples × rows across the tool); the limit is {MAX_DOT_ROWS:.0e}: use a larger grid or step, or engine \"exact\""
                    ),
                )
                .at("grid"));
            }
        }
        if let (Engine::Exact, Base::Bitmap(bitmap)) = (self.engine, &region.base) {
            // Every sample intersects the circle with about 8R/cell cell edges, and the height
            // sections of a rounded end their own circles.
            let work = total_samples * 8.0 * (radius + section_radii) / bitmap.cell;
            if work > super::MAX_BITMAP_CROSSINGS {
                return Err(SolverError::new(
                    ErrorCode::TooManySamples,
                    format!(
                        "a bitmap with cell {} mm seen by a tool of radius {radius} mm needs about {work:.2e} edge tests over the samples; the limit is {:.0e}: use a larger step, a coarser bitmap or engine \"dots\"",
                        bitmap.cell,
                        super::MAX_BITMAP_CROSSINGS
                    ),
                )
                .at("step"));
            }
        }
        Ok(Job {
            radius,
            flute_counts,
            tool_flutes: tool.flutes,
            spindle_rpm,
            feed_mode,
            thickness_limit,
            time_limit,
            representative: self.representative,
            direction: self.spindle_direction,
            engine: self.engine,
            step,
            grid,
            burr_disengage,
            chipping_disengage,
            radial_depth_min,
            radial_depth_max,
            spike_threshold,
            min_feed_per_tooth,
            stock_top_z,
            clearance,
            plan,
            rule,
            arc_feed: self.arc_feed_correction,
            spindle,
            natural: natural_frequencies(tool),
            contact_dots: self.contact_dots,
            region,
            shared_warnings,
            candidates,
            single: self.path.is_some(),
        })
    }
}

impl EngagementRequest {
    /// The Kienzle values from `kienzle` or the resolved `material`, and the spindle limits.
    fn kienzle(&self, physics: &Physics) -> Result<(Option<Kienzle>, SpindleLimits), SolverError> {
        physics.spindle.validate()?;
        let kienzle = match (&self.kienzle, &self.material) {
            (Some(_), Some(_)) => {
                return Err(SolverError::input("material", "give material or kienzle, not both"));
            }
            (Some(values), None) => {
                values.validate("kienzle.")?;
                Some(*values)
            }
            (None, Some(name)) => {
                let values = physics.material.ok_or_else(|| {
                    SolverError::input(
                        "material",
                        format!("material {name:?} is not known here: give its Kienzle values as `kienzle` (kc11, mc)"),
                    )
                })?;
                values.validate("material.")?;
                Some(values)
            }
            (None, None) => None,
        };
        Ok((kienzle, physics.spindle))
    }
}

/// Kienzle's force model for a path cut `axial_depth` deep.
///
/// # Errors
/// `E_INPUT` at `axial_depth` without a depth: a_p is the chip width.
fn force_model(
    kienzle: &Kienzle,
    tool: &Tool,
    axial_depth: Option<f64>,
    direction: SpindleDirection,
) -> Result<ForceModel, SolverError> {
    let axial_depth = axial_depth.ok_or_else(|| {
        SolverError::input(
            "axial_depth",
            "axial_depth (mm) is required with kienzle or material (or paths[i].axial_depth for every path), or the path's Z under the stock top (cut_z, with stock_top_z, default 0): a_p is the chip width",
        )
    })?;
    // Λ = 2·a_p·tan λ / D (docs/spec/engagement.md §11 item 5), radians.
    let helix_tan = tool.helix_deg.map_or(0.0, |helix| helix.to_radians().tan());
    let lag = axial_depth * helix_tan / tool.radius;
    let (table, table_next) = (SinPower::new(1.0 - kienzle.mc), SinPower::new(2.0 - kienzle.mc));
    let corner_radius = match tool.kind {
        ToolKind::Flat => 0.0,
        ToolKind::Ball => tool.radius,
        ToolKind::Bull => tool.corner_radius.unwrap_or(0.0).min(tool.radius),
    };
    let (force_width, torque_width) =
        ForceModel::end_widths(&table, &table_next, tool.radius, corner_radius, axial_depth);
    Ok(ForceModel {
        kc11: kienzle.kc11,
        mc: kienzle.mc,
        axial_depth,
        force_width,
        torque_width,
        lag_deg: lag.to_degrees(),
        radius: tool.radius,
        corner_radius,
        helix_tan,
        loads: (corner_radius > 0.0 && axial_depth > 0.0).then(|| Box::new(Loads::new(1.0 - kienzle.mc))),
        direction,
        radial_ratio: kienzle.radial_ratio.unwrap_or(DEFAULT_RADIAL_RATIO),
        table,
        table_next,
    })
}

/// The one Z level of a G-code path's XY feed moves, with its field, for a_p from the stock
/// height (only when no explicit a_p wins: `wanted`); several levels give `W_AXIAL_DEPTH` and
/// none.
fn program_level(
    levels: &[(f64, usize)],
    field: &str,
    wanted: bool,
    warnings: &mut Vec<Warning>,
) -> Option<(f64, String)> {
    let (&(first, line), rest) = levels.split_first()?;
    let other = rest.iter().find(|(z, _)| (z - first).abs() > 1e-6);
    match other {
        None => Some((first, format!("{field} (Z of its feed moves, line {line})"))),
        Some((z, other_line)) => {
            if wanted {
                warnings.push(Warning::new(
                    "W_AXIAL_DEPTH",
                    format!(
                        "the program's XY feed moves run at several Z levels (Z {first} at line {line}, Z {z} at line {other_line}): no a_p from the stock height; the 2-D model takes one level per path, so give axial_depth or cut_z, or each level as its own entry of paths"
                    ),
                ));
            }
            None
        }
    }
}

/// a_p of one path and the Z it runs at when a_p came from it: the explicit axial depth
/// (`explicit`, with its field) wins; else `top` − the path's Z (`height`, with its field),
/// 0 at or above the top. Both warn where they disagree; an a_p beyond the tool's flute length
/// is refused at the field that set it.
fn path_depth(
    explicit: Option<(f64, String)>,
    height: Option<(f64, String)>,
    top: f64,
    tool: &Tool,
    warnings: &mut Vec<Warning>,
) -> Result<(Option<f64>, Option<f64>), SolverError> {
    let reach = |depth: f64, field: &str, how: &str| -> Result<(), SolverError> {
        match tool.flute_length {
            Some(length) if depth > length => Err(SolverError::input(
                field,
                format!(
                    "{how} a_p = {depth} mm, more than the tool's flute_length {length} mm: the shank would cut (check the path's Z and the stock top)"
                ),
            )),
            _ => Ok(()),
        }
    };
    if let Some((depth, field)) = explicit {
        if let Some((z, z_field)) = &height
            && ((top - z).max(0.0) - depth).abs() > 1e-9
        {
            warnings.push(Warning::new(
                "W_AXIAL_DEPTH",
                format!(
                    "{field} = {depth} mm is used; the path's Z {z} ({z_field}) under the stock top {top} would give a_p = {} mm",
                    (top - z).max(0.0)
                ),
            ));
        }
        reach(depth, &field, &format!("{field} gives"))?;
        return Ok((Some(depth), None));
    }
    let Some((z, field)) = height else {
        return Ok((None, None));
    };
    let depth = top - z;
    if depth <= 0.0 {
        warnings.push(Warning::new(
            "W_AXIAL_DEPTH",
            format!(
                "the tool tip runs at Z {z} ({field}), at or above the stock top {top}: a_p = 0, the path cuts no chip (torque, power and removal rate are 0)"
            ),
        ));
        return Ok((Some(0.0), Some(z)));
    }
    let field_name = field.split(' ').next().unwrap_or(&field).to_owned();
    reach(depth, &field_name, &format!("the stock top {top} less the path's Z {z} ({field}) gives"))?;
    Ok((Some(depth), Some(z)))
}

/// What the server resolves for an engagement request besides the tool and the machine: the
/// Kienzle values of the request's `material` and the spindle limits of its machine.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Physics {
    /// Kienzle values of the stored material the request names.
    pub material: Option<Kienzle>,
    /// The machine profile's spindle power and torque.
    pub spindle: SpindleLimits,
}

/// The dot grid of a candidate: the stock's box cut to where the tool can reach, in cells of
/// `grid`; refused past [`MAX_GRID_DOTS`] (docs/spec/engagement.md §9 `W_GRID_MEMORY`: refuse).
/// Dots sit at `anchor` + (i + ½, j + ½)·`grid` (the bitmap's origin, so its cells and the dots
/// line up).
pub(crate) fn grid_extent(
    route: &Route,
    stock_box: BBox,
    anchor: P2,
    radius: f64,
    grid: f64,
) -> Option<(P2, u64, u64)> {
    let reach = route.bbox()?.grown(radius * (1.0 + 1e-9) + grid);
    let area = reach.intersection(&stock_box.grown(grid))?;
    let origin = P2::new(
        anchor.x + ((area.min.x - anchor.x) / grid).floor() * grid,
        anchor.y + ((area.min.y - anchor.y) / grid).floor() * grid,
    );
    let width = ((area.max.x - origin.x) / grid).ceil().max(1.0);
    let height = ((area.max.y - origin.y) / grid).ceil().max(1.0);
    // Saturating: sizes far past the limit are refused by the caller anyway.
    Some((origin, width.min(1e18) as u64, height.min(1e18) as u64))
}

/// Refuses a grid past the memory limit; the grid's height in rows otherwise.
fn check_grid(route: &Route, stock_box: BBox, anchor: P2, radius: f64, grid: f64) -> Result<f64, SolverError> {
    if let Some((_, width, height)) = grid_extent(route, stock_box, anchor, radius, grid) {
        let dots = (width as f64) * (height as f64);
        if dots > MAX_GRID_DOTS as f64 {
            return Err(SolverError::new(
                ErrorCode::GridMemory,
                format!(
                    "the dot grid would need {dots:.3e} dots ({width} × {height} at grid {grid} mm, {:.0} MB); the limit is {MAX_GRID_DOTS} dots ({} MB): use a larger grid",
                    dots / 8.0 / 1e6,
                    MAX_GRID_DOTS / 8 / 1_000_000
                ),
            )
            .at("grid"));
        }
        return Ok(height as f64);
    }
    Ok(0.0)
}
