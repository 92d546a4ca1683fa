//! A prediction request validated into a [`Job`]: tool, stock, tool path (points or G-code read
//! into ball-centre passes), cutting conditions and method settings, with every limit checked
//! before any heavy work.

use super::force::CuttingCoefficients;
use super::passes::{PassSource, PathBuilder, PathModel};
use crate::capability::Control;
use crate::error::{ErrorCode, SolverError};
use crate::gcode::reader::{self, MoveKind, ReadMove, ReadOptions, ReadProgram, Spindle};
use crate::gcode::{Reference, SpindleDirection};
use crate::geometry::{Vec3, vec3};
use crate::stock::StockModel;
use crate::tool::{ShapeErrorPoint, Stiffness, Tool, ToolKind};
use crate::validate::{MAX_COORDINATE, Measure, coordinates, finite, optional_positive, positive, quoted};

use super::request::{
    DEFAULT_ARC_TOLERANCE, DEFAULT_EDGE_ELEMENTS, DEFAULT_MAX_CORRECTION, DEFAULT_MERGE_TOLERANCE, DEFAULT_RESOLUTION,
    DEFAULT_STEPS, DEFAULT_VIEW_CORRECTION_DEG, DEPTH_BUFFER_BYTES_PER_PIXEL, MAX_DEPTH_BUFFER_BYTES, MAX_HISTORIES,
    MAX_MERGE_TOLERANCE, MAX_PASSES, MAX_SAMPLING_RESOLUTION, MAX_SPINDLE_SPEEDS, Method, PathInput, PredictRequest,
    PrescribedDeflection,
};

/// Where each path node came from, for writing the corrected program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NodeSource {
    /// Index of the G-code move (or of the point) that ends at this node.
    pub(crate) item: usize,
    /// Chord of that move (arcs have several), and their count.
    pub(crate) chord: usize,
    pub(crate) chords: usize,
}

/// A validated request.
#[derive(Debug)]
pub(crate) struct Job {
    pub(crate) radius: f64,
    pub(crate) flutes: usize,
    pub(crate) helix: f64,
    pub(crate) shape_error: Vec<ShapeErrorPoint>,
    pub(crate) stiffness: Option<Stiffness>,
    pub(crate) stock: StockModel,
    pub(crate) path: PathModel,
    pub(crate) node_sources: Vec<NodeSource>,
    /// Offset from ball centre to programmed point.
    pub(crate) reference_offset: Vec3,
    pub(crate) method: Method,
    pub(crate) resolution: u32,
    pub(crate) tooth_feed_gap: f64,
    pub(crate) view_correction: bool,
    pub(crate) view_threshold: f64,
    pub(crate) flute_zero: f64,
    pub(crate) steps: usize,
    pub(crate) edge_elements: usize,
    pub(crate) cutting: Option<CuttingCoefficients>,
    pub(crate) deflection: Option<PrescribedDeflection>,
    pub(crate) max_correction: f64,
    pub(crate) iterations: u32,
    pub(crate) history: Vec<usize>,
    pub(crate) pass_range: std::ops::Range<usize>,
    pub(crate) spindle_speeds: Vec<f64>,
    /// θ_x, degrees.
    pub(crate) exclusion: Option<f64>,
    /// e_S for the excluded passes.
    pub(crate) exclusion_shape_error: bool,
    /// Merging of similar passes and its tolerance, mm.
    pub(crate) merge_tolerance: Option<f64>,
}

/// `value` (or `default`) within `lo..=hi`, else `E_INPUT` naming `field`.
fn range_u32(field: &str, value: Option<u32>, default: u32, lo: u32, hi: u32) -> Result<u32, SolverError> {
    let v = value.unwrap_or(default);
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(SolverError::input(field, format!("{field} must be {lo} to {hi} (got {v})")))
    }
}

/// The method settings of a request, checked.
struct Settings {
    resolution: u32,
    tooth_feed_gap: f64,
    view_threshold: f64,
    flute_zero: f64,
    steps: usize,
    edge_elements: usize,
    arc_tolerance: f64,
}

/// The path read into passes, with where each node came from.
struct ReadPath {
    path: PathModel,
    node_sources: Vec<NodeSource>,
    reference_offset: Vec3,
}

impl PredictRequest {
    /// Checks everything and reads the path; `mesh` holds the STL bytes of a `mesh` stock.
    ///
    /// The sections are checked in a fixed order (tool, method settings, conditions, output,
    /// stock, path, then what depends on the path), so a request with several faults is always
    /// refused for the same one.
    pub(crate) fn validate(&self, tool: &Tool, mesh: Option<&[u8]>, control: Control<'_>) -> Result<Job, SolverError> {
        let shape_error = check_tool(tool)?;
        let radius = tool.radius;
        let method = self.method;
        let flutes = tool.flutes as usize;
        let settings = self.settings(flutes)?;
        self.check_conditions()?;
        let (max_correction, iterations) = self.correction_limits()?;
        let history = self.history.clone().unwrap_or_default();
        if history.len() > MAX_HISTORIES {
            return Err(SolverError::input("history", format!("ask for at most {MAX_HISTORIES} pass histories")));
        }
        let defaults = Defaults {
            feed: self.feed.map(|f| positive("feed", f, Measure::Feed)).transpose()?,
            spindle_rpm: self.spindle_rpm.map(|s| positive("spindle_rpm", s, Measure::Number)).transpose()?,
            sign: match self.spindle_direction.unwrap_or_default() {
                SpindleDirection::Cw => -1.0,
                SpindleDirection::Ccw => 1.0,
            },
        };
        let stock = self.stock.model(mesh)?;
        let ReadPath { path, node_sources, reference_offset } =
            self.read_path(radius, &defaults, settings.arc_tolerance, control)?;
        for (k, &index) in history.iter().enumerate() {
            if index >= path.passes.len() {
                return Err(SolverError::input(
                    format!("history[{k}]"),
                    format!("the path has {} passes (indices from 0)", path.passes.len()),
                ));
            }
        }
        let (exclusion, exclusion_shape_error) = self.exclusion()?;
        let merge_tolerance = self.merge_tolerance()?;
        let pass_range = self.pass_range(path.passes.len())?;
        let spindle_speeds = spindle_speeds(&path)?;
        Ok(Job {
            radius,
            flutes,
            helix: tool.helix_deg.unwrap_or(0.0).to_radians(),
            shape_error,
            stiffness: tool.stiffness.clone(),
            stock,
            path,
            node_sources,
            reference_offset,
            method,
            resolution: settings.resolution,
            tooth_feed_gap: settings.tooth_feed_gap,
            view_correction: self.view_correction.unwrap_or(true),
            view_threshold: settings.view_threshold,
            flute_zero: settings.flute_zero,
            steps: settings.steps,
            edge_elements: settings.edge_elements,
            cutting: self.cutting,
            deflection: self.deflection.clone(),
            max_correction,
            iterations,
            history,
            pass_range,
            exclusion,
            exclusion_shape_error,
            merge_tolerance,
            spindle_speeds,
        })
    }

    /// The method settings: resolution (within the depth buffer's memory for that method), gap,
    /// view correction, flute angle, time steps (a whole number per flute), edge elements and
    /// the arc tolerance.
    fn settings(&self, flutes: usize) -> Result<Settings, SolverError> {
        let resolution = range_u32("resolution", self.resolution, DEFAULT_RESOLUTION, 16, MAX_SAMPLING_RESOLUTION)?;
        if self.method == Method::DepthBuffer {
            let bytes = u64::from(resolution).pow(2) * DEPTH_BUFFER_BYTES_PER_PIXEL;
            if bytes > MAX_DEPTH_BUFFER_BYTES {
                let limit = ((MAX_DEPTH_BUFFER_BYTES / DEPTH_BUFFER_BYTES_PER_PIXEL) as f64).sqrt() as u64;
                return Err(SolverError::new(
                    ErrorCode::ResolutionLimit,
                    format!(
                        "resolution {resolution} needs a depth buffer of up to {} MiB per worker; the limit is {} MiB (resolution at most {limit})",
                        bytes >> 20,
                        MAX_DEPTH_BUFFER_BYTES >> 20
                    ),
                )
                .at("resolution"));
            }
        }
        let tooth_feed_gap = f64::from(range_u32("tooth_feed_gap", self.tooth_feed_gap, 1, 1, 3)?);
        let view_threshold = match self.view_correction_deg {
            None => DEFAULT_VIEW_CORRECTION_DEG,
            Some(v) => {
                if !(0.0..=90.0).contains(&finite("view_correction_deg", v)?) {
                    return Err(SolverError::input("view_correction_deg", "view_correction_deg must lie in [0, 90]"));
                }
                v
            }
        }
        .to_radians();
        let flute_zero = finite("flute_zero_deg", self.flute_zero_deg.unwrap_or(0.0))?.to_radians();
        let steps = range_u32("samples_per_revolution", self.samples_per_revolution, DEFAULT_STEPS, 36, 4096)? as usize;
        let steps = steps.div_ceil(flutes) * flutes;
        let edge_elements = range_u32("edge_elements", self.edge_elements, DEFAULT_EDGE_ELEMENTS, 9, 720)? as usize;
        let arc_tolerance =
            optional_positive("arc_tolerance", self.arc_tolerance, DEFAULT_ARC_TOLERANCE, Measure::Length)?;
        Ok(Settings { resolution, tooth_feed_gap, view_threshold, flute_zero, steps, edge_elements, arc_tolerance })
    }

    /// The cutting coefficients and the prescribed deflection, when given.
    fn check_conditions(&self) -> Result<(), SolverError> {
        if let Some(cutting) = &self.cutting {
            cutting.validate("cutting")?;
        }
        if let Some(prescribed) = &self.deflection {
            if prescribed.x.is_empty() || prescribed.x.len() > 100_000 {
                return Err(SolverError::input("deflection.x", "give 1 to 100000 deflection values per revolution"));
            }
            if prescribed.y.len() != prescribed.x.len() {
                return Err(SolverError::input("deflection.y", "deflection.y needs as many values as deflection.x"));
            }
            for (axis, values) in [("x", &prescribed.x), ("y", &prescribed.y)] {
                for (k, v) in values.iter().enumerate() {
                    finite(&format!("deflection.{axis}[{k}]"), *v)?;
                }
            }
        }
        Ok(())
    }

    /// The correction's largest node move, mm, and its prediction rounds.
    fn correction_limits(&self) -> Result<(f64, u32), SolverError> {
        Ok(match &self.correction {
            None => (DEFAULT_MAX_CORRECTION, 1),
            Some(c) => (
                optional_positive(
                    "correction.max_correction",
                    c.max_correction,
                    DEFAULT_MAX_CORRECTION,
                    Measure::Length,
                )?,
                range_u32("correction.iterations", c.iterations, 1, 1, 3)?,
            ),
        })
    }

    /// The tool path as ball-centre passes, from points or a G-code program, within the pass
    /// limits.
    fn read_path(
        &self,
        radius: f64,
        defaults: &Defaults,
        arc_tolerance: f64,
        control: Control<'_>,
    ) -> Result<ReadPath, SolverError> {
        let reference_offset = match self.reference {
            Reference::Tip => -radius * Vec3::z(),
            Reference::Centre => Vec3::zeros(),
        };
        let centre_of = |p: Vec3| p - reference_offset;
        let mut builder = PathBuilder::default();
        let mut node_sources = Vec::new();
        match &self.path {
            PathInput::Points { points } => {
                if points.len() < 2 || points.len() > MAX_PASSES + 1 {
                    return Err(SolverError::input("path.points", format!("give 2 to {} points", MAX_PASSES + 1)));
                }
                let feed =
                    defaults.feed.ok_or_else(|| SolverError::input("feed", "a path of points needs feed (mm/min)"))?;
                let spindle_rpm = defaults
                    .spindle_rpm
                    .ok_or_else(|| SolverError::input("spindle_rpm", "a path of points needs spindle_rpm"))?;
                let source =
                    PassSource { line: None, block_number: None, feed, spindle_rpm, rotation_sign: defaults.sign };
                for (index, p) in points.iter().enumerate() {
                    coordinates(&format!("path.points[{index}]"), *p)?;
                    let centre = centre_of(vec3(*p));
                    if index == 0 {
                        builder.start(centre);
                    } else {
                        builder.to(centre, Some(source));
                    }
                    node_sources.push(NodeSource { item: index, chord: 0, chords: 1 });
                }
            }
            PathInput::Gcode { program: text } => {
                let options =
                    ReadOptions { block_delete: self.block_delete.unwrap_or(false), ..ReadOptions::default() };
                let read = reader::read_cancellable(text, "path.program", &options, control)?;
                build_from_program(&read, defaults, arc_tolerance, &centre_of, &mut builder, &mut node_sources)?;
            }
        }
        if builder.pass_count() == 0 {
            return Err(SolverError::new(ErrorCode::NoPasses, "the tool path has no feed moves from a known position")
                .at("path"));
        }
        if builder.pass_count() > MAX_PASSES {
            return Err(SolverError::new(
                ErrorCode::TooManyPasses,
                format!("the tool path has {} passes; the limit is {MAX_PASSES}", builder.pass_count()),
            )
            .at("path"));
        }
        Ok(ReadPath { path: builder.build(radius), node_sources, reference_offset })
    }

    /// The exclusion angle θ_x, degrees, and whether the excluded passes keep e_S.
    fn exclusion(&self) -> Result<(Option<f64>, bool), SolverError> {
        let exclusion = match self.exclusion_deg {
            None => None,
            Some(angle) if angle.is_finite() && (0.0..=90.0).contains(&angle) => Some(angle),
            Some(angle) => {
                return Err(SolverError::input(
                    "exclusion_deg",
                    format!("exclusion_deg must be 0 to 90 degrees (got {angle})"),
                ));
            }
        };
        let exclusion_shape_error = self.exclusion_shape_error.unwrap_or(false);
        if exclusion_shape_error && exclusion.is_none() {
            return Err(SolverError::input(
                "exclusion_shape_error",
                "exclusion_shape_error applies to passes excluded by exclusion_deg: give exclusion_deg too",
            ));
        }
        Ok((exclusion, exclusion_shape_error))
    }

    /// The tolerance similar passes are merged within, mm, when they are merged.
    fn merge_tolerance(&self) -> Result<Option<f64>, SolverError> {
        match (self.merge_similar_passes.unwrap_or(false), self.merge_tolerance) {
            (_, Some(t)) if !(t.is_finite() && t > 0.0 && t <= MAX_MERGE_TOLERANCE) => Err(SolverError::input(
                "merge_tolerance",
                format!(
                    "merge_tolerance must be above 0 and at most {MAX_MERGE_TOLERANCE} mm (got {})",
                    Measure::Length.quote(t)
                ),
            )),
            (false, Some(_)) => {
                Err(SolverError::input("merge_tolerance", "merge_tolerance applies with merge_similar_passes: true"))
            }
            (true, t) => Ok(Some(t.unwrap_or(DEFAULT_MERGE_TOLERANCE))),
            (false, None) => Ok(None),
        }
    }

    /// The passes to predict, within the path's `passes`.
    fn pass_range(&self, passes: usize) -> Result<std::ops::Range<usize>, SolverError> {
        match self.pass_range {
            None => Ok(0..passes),
            Some([from, to]) => {
                if from > to || to > passes {
                    return Err(SolverError::input(
                        "pass_range",
                        format!("pass_range must satisfy from ≤ to ≤ {passes} (the pass count)"),
                    ));
                }
                Ok(from..to)
            }
        }
    }
}

/// The tool: a valid ball end mill with a shape-error table, which is returned.
fn check_tool(tool: &Tool) -> Result<Vec<ShapeErrorPoint>, SolverError> {
    tool.validate("tool.")?;
    if tool.kind != ToolKind::Ball {
        return Err(SolverError::new(
            ErrorCode::ToolKind,
            format!("error prediction needs a ball end mill, not a {} tool", tool.kind.as_str()),
        )
        .at("tool.kind"));
    }
    let Some(shape_error) = tool.shape_error.clone() else {
        return Err(SolverError::new(
            ErrorCode::NoShapeError,
            "the tool has no shape-error table: add shape_error (a list of {\"angle_deg\", \"error\"}) to the tool",
        )
        .at("tool.shape_error"));
    };
    Ok(shape_error)
}

/// The path's distinct spindle speeds, ascending, within the limit.
fn spindle_speeds(path: &PathModel) -> Result<Vec<f64>, SolverError> {
    let mut spindle_speeds: Vec<f64> = path.passes.iter().map(|p| p.source.spindle_rpm).collect();
    spindle_speeds.sort_by(f64::total_cmp);
    spindle_speeds.dedup();
    if spindle_speeds.len() > MAX_SPINDLE_SPEEDS {
        return Err(SolverError::new(
            ErrorCode::TooManySpindleSpeeds,
            format!("the program uses {} spindle speeds; the limit is {MAX_SPINDLE_SPEEDS}", spindle_speeds.len()),
        )
        .at("path"));
    }
    Ok(spindle_speeds)
}

/// Cutting conditions used where the program sets none.
struct Defaults {
    feed: Option<f64>,
    spindle_rpm: Option<f64>,
    sign: f64,
}

/// Turns the program's moves into path nodes: every known move continues the path; a move from
/// an unknown position starts a new run at its end.
fn build_from_program(
    program: &ReadProgram,
    defaults: &Defaults,
    arc_tolerance: f64,
    centre_of: &impl Fn(Vec3) -> Vec3,
    builder: &mut PathBuilder,
    node_sources: &mut Vec<NodeSource>,
) -> Result<(), SolverError> {
    let field = "path.program";
    let mut current: Option<[f64; 3]> = None;
    let mut tool_number: Option<u32> = None;
    for (index, read_move) in program.moves.iter().enumerate() {
        let line = read_move.line;
        let cutting = !matches!(read_move.kind, MoveKind::Rapid);
        if cutting {
            tool_number = one_tool(tool_number, read_move)?;
        }
        let (Some(from), Some(to)) = (read_move.from_xyz(), read_move.to_xyz()) else {
            if cutting && read_move.to_xyz().is_none() {
                return Err(SolverError::new(
                    ErrorCode::GcodePosition,
                    format!(
                        "line {line}: a feed move to a position the program has not fully set (give X, Y and Z first)"
                    ),
                )
                .at(field));
            }
            builder.break_run();
            current = read_move.to_xyz();
            if let Some(to) = current {
                builder.start(centre_of(vec3(to)));
                node_sources.push(NodeSource { item: index, chord: 0, chords: 1 });
            }
            continue;
        };
        if current != Some(from) || !builder.is_open() {
            builder.start(centre_of(vec3(from)));
            node_sources.push(NodeSource { item: index, chord: 0, chords: 0 });
        }
        let source = if cutting { Some(pass_source(read_move, defaults)?) } else { None };
        if let Some(value) = from.iter().chain(&to).find(|value| value.abs() > MAX_COORDINATE) {
            return Err(SolverError::input(
                field,
                format!("line {line}: coordinates must lie within ±{MAX_COORDINATE} mm (got {} mm)", quoted(*value)),
            ));
        }
        let points = read_move.points(arc_tolerance).unwrap_or_else(|| vec![to]);
        let chords = points.len();
        if builder.pass_count() + chords > MAX_PASSES {
            return Err(SolverError::new(
                ErrorCode::TooManyPasses,
                format!("line {line}: the tool path has more than {MAX_PASSES} passes, the limit"),
            )
            .at(field));
        }
        for (chord, p) in points.iter().enumerate() {
            if source.is_some() {
                builder.to(centre_of(vec3(*p)), source);
            } else {
                builder.rapid_to(centre_of(vec3(*p)), line);
            }
            node_sources.push(NodeSource { item: index, chord, chords });
        }
        debug_assert_eq!(node_sources.len(), builder.node_count());
        current = Some(to);
    }
    Ok(())
}

/// The tool of the program's cutting moves so far, given `read_move` (a cutting move): one tool
/// per prediction, since the shape error and stiffness are one tool's.
fn one_tool(tool_number: Option<u32>, read_move: &ReadMove) -> Result<Option<u32>, SolverError> {
    let line = read_move.line;
    if let (Some(first), Some(this)) = (tool_number, read_move.modal.tool)
        && first != this
    {
        return Err(SolverError::new(
            ErrorCode::GcodeUnsupported,
            format!("line {line}: the program changes from tool {first} to tool {this}; predict one tool at a time"),
        )
        .at("path.program"));
    }
    Ok(tool_number.or(read_move.modal.tool))
}

/// The cutting conditions of a feed move: its modal feed, spindle speed and direction, or the
/// request's defaults where the program sets none.
fn pass_source(read_move: &ReadMove, defaults: &Defaults) -> Result<PassSource, SolverError> {
    let (line, field) = (read_move.line, "path.program");
    let feed = read_move.modal.feed.or(defaults.feed).ok_or_else(|| {
        SolverError::new(
            ErrorCode::NoFeed,
            format!("line {line}: feed move without a feed rate (F) and no default feed in the request"),
        )
        .at(field)
    })?;
    let spindle_rpm = read_move.modal.spindle_rpm.filter(|s| *s > 0.0).or(defaults.spindle_rpm).ok_or_else(|| {
        SolverError::new(
            ErrorCode::NoSpindle,
            format!("line {line}: feed move without a spindle speed (S) and no default spindle_rpm in the request"),
        )
        .at(field)
    })?;
    let rotation_sign = match read_move.modal.spindle {
        Spindle::Clockwise => -1.0,
        Spindle::CounterClockwise => 1.0,
        Spindle::Off => defaults.sign,
    };
    Ok(PassSource { line: Some(line), block_number: read_move.block_number, feed, spindle_rpm, rotation_sign })
}
