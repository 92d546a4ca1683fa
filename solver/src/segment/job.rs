//! A segment request validated into a [`Job`] with the machine's defaults applied (docs/spec/segment.md §1.2
//! inputs, §4 E6 and E16): the curve read into its shape, the chord-error plan resolved.

use crate::error::ErrorCode;

use super::arclength::ArcLengthTable;
use super::cut::Estimate;
use super::nurbs::Nurbs;
use super::request::{
    Curve, CurveRule, DEFAULT_CORNER_ANGLE_DEG, DEFAULT_SPINDLE_RPM, DEFAULT_WINDOW_CHORDS, Direction, MAX_COORDINATE,
    MAX_POLYLINE_POINTS, MIN_TOLERANCE, RadiusEstimate, SegmentRequest,
};
use super::shape::{AngleMemo, Arc, Ellipse, Polyline, Shape, Spline, ellipse_speed, require_length};
use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;
use crate::machine::rule::{BlockRule, RuleSettings};
use crate::machine::{MachineProfile, Mode};
use crate::validate::{Measure, coordinate, finite, positive};

/// Where the chord error comes from, resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Plan {
    Window { length: f64, estimate: Estimate },
    Max { length: f64, estimate: Estimate },
    Extremes { min_radius: Option<f64> },
    NormalAccel { min_radius: Option<f64> },
    Guarantee,
}

/// A validated request: the curve built, the machine's defaults applied.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Job {
    pub shape: Shape,
    /// Parameter ranges between corners.
    pub spans: Vec<(f64, f64)>,
    /// 2 or 3: the coordinates of the answer's points.
    pub dimension: usize,
    pub rule: BlockRule,
    pub plan: Plan,
    pub tolerance: Option<f64>,
    pub compare_tolerance: Option<f64>,
    pub spindle_rpm: f64,
    pub safe_z: Option<f64>,
    /// The least increment of the job's program, mm: 0.0001 of the units it is written in.
    pub least_increment: f64,
    pub warnings: Vec<Warning>,
}

/// A point `[x, y]` or `[x, y, z]` with finite coordinates of sane size.
fn point(field: &str, coordinates: &[f64]) -> Result<Vec3, SolverError> {
    if !(2..=3).contains(&coordinates.len()) {
        return Err(SolverError::input(
            field,
            format!(
                "a point has 2 or 3 coordinates (got {}); extra axes such as rotary ones have no metric here",
                coordinates.len()
            ),
        ));
    }
    for (axis, &value) in coordinates.iter().enumerate() {
        coordinate(&format!("{field}[{axis}]"), value)?;
    }
    Ok(Vec3::new(coordinates[0], coordinates[1], coordinates.get(2).copied().unwrap_or(0.0)))
}

/// Points of one list, all with the dimension of the first.
fn points(field: &str, list: &[Vec<f64>]) -> Result<(Vec<Vec3>, usize), SolverError> {
    let dimension = list.first().map_or(2, Vec::len);
    // Field names are formatted only when a point is refused: a 100 000-point polyline would
    // otherwise spend longer naming its points than segmenting them.
    let valid = |coordinates: &Vec<f64>| {
        coordinates.len() == dimension
            && (2..=3).contains(&dimension)
            && coordinates.iter().all(|value| value.is_finite() && value.abs() <= MAX_COORDINATE)
    };
    if list.iter().all(valid) {
        let point = |c: &Vec<f64>| Vec3::new(c[0], c[1], c.get(2).copied().unwrap_or(0.0));
        return Ok((list.iter().map(point).collect(), dimension));
    }
    let mut out = Vec::with_capacity(list.len());
    for (index, coordinates) in list.iter().enumerate() {
        let path = format!("{field}[{index}]");
        if coordinates.len() != dimension {
            return Err(SolverError::input(
                path,
                format!("every point must have {dimension} coordinates like the first (got {})", coordinates.len()),
            ));
        }
        out.push(point(&path, coordinates)?);
    }
    Ok((out, dimension))
}

fn radius(field: &str, value: f64) -> Result<f64, SolverError> {
    if positive(field, value, Measure::Length)? > MAX_COORDINATE {
        return Err(SolverError::input(
            field,
            format!("{field} must be at most {MAX_COORDINATE} mm (got {})", Measure::Length.quote(value)),
        ));
    }
    Ok(value)
}

/// The least increment of a program (4 decimals), in the program's units.
const LEAST_INCREMENT: f64 = 1e-4;

/// Largest angle accepted, degrees (about 2 800 turns): beyond it the angle's rounding in
/// radians exceeds a micro-radian, and a quarter-turn search could no longer advance.
const MAX_ANGLE_DEG: f64 = 1e6;

/// Gauss–Legendre panels a NURBS's arc-length table starts each knot span with (each is then
/// halved until its halves agree with it, [`ArcLengthTable::build`]): a span's speed is one
/// smooth function, so one panel is enough to start from, and the halving finds where it is
/// not (4 panels cost a quarter of the chord bench's B-spline solve for the same lengths to
/// 1e-15).
pub(crate) const NURBS_PANELS_PER_SPAN: usize = 1;

/// A finite angle in degrees within ±[`MAX_ANGLE_DEG`].
fn angle(field: &str, value: f64) -> Result<f64, SolverError> {
    if finite(field, value)?.abs() > MAX_ANGLE_DEG {
        return Err(SolverError::input(field, format!("{field} must lie within ±{MAX_ANGLE_DEG}° (got {value})")));
    }
    Ok(value)
}

/// Swept angle in radians from start to end in the direction: in (0, 2π], a full turn when the
/// angles differ by a non-zero multiple of 360°.
fn sweep(start_deg: f64, end_deg: f64, direction: Direction) -> f64 {
    let forward = match direction {
        Direction::Ccw => end_deg - start_deg,
        Direction::Cw => start_deg - end_deg,
    };
    let wrapped = forward.rem_euclid(360.0);
    if wrapped == 0.0 && forward != 0.0 { std::f64::consts::TAU } else { wrapped.to_radians() }
}

fn corner_angle(value: Option<f64>) -> Result<f64, SolverError> {
    let field = "curve.corner_angle_deg";
    let degrees = value.unwrap_or(DEFAULT_CORNER_ANGLE_DEG);
    if !(finite(field, degrees)? > 0.0 && degrees < 180.0) {
        return Err(SolverError::input(field, format!("corner_angle_deg must be between 0 and 180 (got {degrees})")));
    }
    Ok(degrees.to_radians())
}

/// What building a curve gives: its shape, the parameters of its corners and its dimension
/// (2 or 3).
type Built = (Shape, Vec<f64>, usize);

impl Curve {
    /// Builds the curve, its corner list and its dimension.
    pub(crate) fn build(&self) -> Result<(Shape, Vec<f64>, usize, Vec<Warning>), SolverError> {
        let mut warnings = Vec::new();
        let (shape, corners, dimension) = match self {
            Self::Circle { centre, radius, start_deg, direction } => {
                build_circle(centre, *radius, *start_deg, *direction)?
            }
            Self::Arc { centre, radius, start_deg, end_deg, direction } => {
                build_arc(centre, *radius, *start_deg, *end_deg, *direction)?
            }
            Self::Ellipse { centre, semi_axes, start_deg, end_deg, rotation_deg, direction } => {
                build_ellipse(centre, *semi_axes, *start_deg, *end_deg, *rotation_deg, *direction)?
            }
            Self::Polyline { points, corner_angle_deg } => build_polyline(points, *corner_angle_deg, &mut warnings)?,
            Self::Bspline { degree, control_points, knots, weights, corner_angle_deg } => {
                build_bspline(*degree, control_points, knots.as_deref(), weights.as_deref(), *corner_angle_deg)?
            }
            Self::Drawing { .. } => {
                return Err(SolverError::input(
                    "curve",
                    "a drawing curve needs its DXF file uploaded with the request (form part `drawing`)",
                ));
            }
        };
        let field = match self {
            Self::Polyline { .. } => "curve.points",
            Self::Bspline { .. } => "curve.control_points",
            _ => "curve.radius",
        };
        require_length(&shape, field)?;
        Ok((shape, corners, dimension, warnings))
    }
}

/// A full circle from `start_deg`.
fn build_circle(centre: &[f64], r: f64, start_deg: f64, direction: Direction) -> Result<Built, SolverError> {
    let c = point("curve.centre", centre)?;
    let shape = Shape::Arc(Arc {
        centre: c,
        radius: radius("curve.radius", r)?,
        start: angle("curve.start_deg", start_deg)?.to_radians(),
        sense: direction.sign(),
        sweep: std::f64::consts::TAU,
    });
    Ok((shape, Vec::new(), centre.len()))
}

/// A circular arc from `start_deg` to `end_deg`; refused when it has no sweep.
fn build_arc(centre: &[f64], r: f64, start_deg: f64, end_deg: f64, direction: Direction) -> Result<Built, SolverError> {
    let c = point("curve.centre", centre)?;
    let start = angle("curve.start_deg", start_deg)?;
    let end = angle("curve.end_deg", end_deg)?;
    let swept = sweep(start, end, direction);
    if swept == 0.0 {
        return Err(SolverError::new(
            ErrorCode::DegenerateCurve,
            "the arc starts and ends at the same angle: it has no length (use 0 and 360 for a full circle)",
        )
        .at("curve.end_deg"));
    }
    let shape = Shape::Arc(Arc {
        centre: c,
        radius: radius("curve.radius", r)?,
        start: start.to_radians(),
        sense: direction.sign(),
        sweep: swept,
    });
    Ok((shape, Vec::new(), centre.len()))
}

/// An elliptic arc with its arc-length table, panels broken at the quarter points.
fn build_ellipse(
    centre: &[f64],
    semi_axes: [f64; 2],
    start_deg: f64,
    end_deg: Option<f64>,
    rotation_deg: f64,
    direction: Direction,
) -> Result<Built, SolverError> {
    let c = point("curve.centre", centre)?;
    let a = radius("curve.semi_axes[0]", semi_axes[0])?;
    let b = radius("curve.semi_axes[1]", semi_axes[1])?;
    let start = angle("curve.start_deg", start_deg)?;
    let end = match end_deg {
        Some(end) => angle("curve.end_deg", end)?,
        None => start + 360.0,
    };
    let swept = sweep(start, end, direction);
    if swept == 0.0 {
        return Err(SolverError::new(
            ErrorCode::DegenerateCurve,
            "the ellipse arc starts and ends at the same angle: it has no length",
        )
        .at("curve.end_deg"));
    }
    let start = start.to_radians();
    let sense = direction.sign();
    let speed = |u: f64| ellipse_speed([a, b], start + sense * u);
    // Panel breaks at the quarter points, where the speed has its extremes.
    let quarter = std::f64::consts::FRAC_PI_2;
    let mut breaks = vec![0.0];
    let first = if sense > 0.0 { (start / quarter).floor() + 1.0 } else { (start / quarter).ceil() - 1.0 };
    let mut k = first;
    loop {
        let u = (k * quarter - start) * sense;
        if u >= swept - 1e-12 {
            break;
        }
        breaks.push(u);
        k += sense;
    }
    breaks.push(swept);
    let table = ArcLengthTable::build(&speed, &breaks, 16, "curve")?;
    let shape = Shape::Ellipse(Ellipse {
        centre: c,
        semi_axes: [a, b],
        rotation_sin_cos: angle("curve.rotation_deg", rotation_deg)?.to_radians().sin_cos(),
        start,
        sense,
        sweep: swept,
        table,
        angles: AngleMemo::default(),
    });
    Ok((shape, Vec::new(), centre.len()))
}

/// A polyline without repeated consecutive points (warned), its stations and corners.
fn build_polyline(
    list: &[Vec<f64>],
    corner_angle_deg: Option<f64>,
    warnings: &mut Vec<Warning>,
) -> Result<Built, SolverError> {
    if list.len() > MAX_POLYLINE_POINTS {
        return Err(SolverError::input(
            "curve.points",
            format!("at most {MAX_POLYLINE_POINTS} points are accepted (got {})", list.len()),
        ));
    }
    let corner = corner_angle(corner_angle_deg)?;
    let (all, dimension) = points("curve.points", list)?;
    let mut vertices: Vec<Vec3> = Vec::with_capacity(all.len());
    let mut dropped = 0;
    for p in all {
        if vertices.last() == Some(&p) {
            dropped += 1;
        } else {
            vertices.push(p);
        }
    }
    if dropped > 0 {
        warnings
            .push(Warning::new("W_DUPLICATE_POINTS", format!("{dropped} repeated consecutive points were dropped")));
    }
    if vertices.len() < 2 {
        return Err(SolverError::new(ErrorCode::DegenerateCurve, "a polyline needs at least two distinct points")
            .at("curve.points"));
    }
    let mut stations = Vec::with_capacity(vertices.len());
    let mut length = 0.0;
    stations.push(0.0);
    for pair in vertices.windows(2) {
        length += (pair[1] - pair[0]).norm();
        stations.push(length);
    }
    let shape = Shape::Polyline(Polyline { vertices, stations, last_edge: std::cell::Cell::new(0) });
    let corners = shape.corners(corner);
    Ok((shape, corners, dimension))
}

/// A B-spline or NURBS curve with its arc-length table and the corners at its knots.
fn build_bspline(
    degree: usize,
    control_points: &[Vec<f64>],
    knots: Option<&[f64]>,
    weights: Option<&[f64]>,
    corner_angle_deg: Option<f64>,
) -> Result<Built, SolverError> {
    let corner = corner_angle(corner_angle_deg)?;
    if control_points.len() > super::nurbs::MAX_CONTROL_POINTS {
        return Err(SolverError::input(
            "curve.control_points",
            format!(
                "at most {} control points are accepted (got {})",
                super::nurbs::MAX_CONTROL_POINTS,
                control_points.len()
            ),
        ));
    }
    let (control, dimension) = points("curve.control_points", control_points)?;
    let nurbs = Nurbs::new(degree, &control, knots, weights, "curve")?;
    if control.windows(2).all(|pair| pair[0] == pair[1]) {
        return Err(SolverError::new(
            ErrorCode::DegenerateCurve,
            "all control points coincide: the curve has no length",
        )
        .at("curve.control_points"));
    }
    let breaks: Vec<f64> = nurbs.breaks().iter().map(|(knot, _)| *knot).collect();
    let table = ArcLengthTable::build(&nurbs, &breaks, NURBS_PANELS_PER_SPAN, "curve.control_points")?;
    let shape = Shape::Spline(Spline::new(nurbs, table));
    let corners = shape.corners(corner);
    Ok((shape, corners, dimension))
}

fn optional_tolerance(field: &str, value: Option<f64>) -> Result<Option<f64>, SolverError> {
    let Some(value) = value else {
        return Ok(None);
    };
    if positive(field, value, Measure::Length)? < MIN_TOLERANCE {
        return Err(SolverError::input(
            field,
            format!("{field} must be at least {MIN_TOLERANCE} mm (got {})", Measure::Length.quote(value)),
        ));
    }
    Ok(Some(value))
}

impl SegmentRequest {
    /// A request for `curve` at `feed` (mm/min) on a control with `block_time_ms`, everything
    /// else at its default (window mode, no margins, no bounds): the starting point for callers
    /// in Rust, e.g. a path solver resampling its own dense points as a `polyline` (set `mode`
    /// to [`Mode::Guarantee`] for no short blocks, or use [`SegmentRequest::guarantee`]).
    pub fn new(curve: Curve, feed: f64, block_time_ms: f64) -> Self {
        Self {
            curve,
            feed: Some(feed),
            block_time_ms: Some(block_time_ms),
            mode: None,
            window: None,
            rule: None,
            min_radius: None,
            radius_estimate: None,
            margin: None,
            chord_error_factor: None,
            radius_factor: None,
            block_time_factor: None,
            allow_unsafe_margin: false,
            sagitta_approximation: false,
            min_chord_error: None,
            tolerance: None,
            compare_tolerance: None,
            machine: None,
            tool: None,
            spindle_rpm: None,
            plunge_feed: None,
            safe_z: None,
            units: None,
        }
    }

    /// [`SegmentRequest::new`] in mode `guarantee` (docs/spec/segment.md §2.9a): what a path solver uses
    /// for the curves it emits, so that no block but a final remainder starves the control.
    pub fn guarantee(curve: Curve, feed: f64, block_time_ms: f64) -> Self {
        Self { mode: Some(Mode::Guarantee), ..Self::new(curve, feed, block_time_ms) }
    }

    /// The block-time rule of this request with `machine`'s defaults (fields are named as in
    /// the request); also the warnings about unsafe factors or a feed above the machine's.
    ///
    /// # Errors
    /// `E_INPUT` naming the field for a missing or bad value.
    pub fn block_rule(&self, machine: Option<&MachineProfile>) -> Result<(BlockRule, Vec<Warning>), SolverError> {
        let settings = RuleSettings {
            feed: self.feed,
            block_time_ms: self.block_time_ms,
            margin: self.margin,
            min_chord_error: self.min_chord_error,
        };
        let adjust = |rule: &mut BlockRule| {
            rule.chord_error_factor = self.chord_error_factor.unwrap_or(1.0);
            rule.radius_factor = self.radius_factor.unwrap_or(1.0);
            rule.block_time_factor = self.block_time_factor.unwrap_or(1.0);
            rule.sagitta_approximation = self.sagitta_approximation;
        };
        BlockRule::resolve_with(&settings, machine, adjust, self.allow_unsafe_margin)
    }

    /// Validates the request with the resolved machine (if it names one).
    pub(crate) fn validate(&self, machine: Option<&MachineProfile>) -> Result<Job, SolverError> {
        let (rule, mut warnings) = self.block_rule(machine)?;
        let window = self.window.map(|w| positive("window", w, Measure::Length)).transpose()?;
        let default_window = DEFAULT_WINDOW_CHORDS * rule.target_chord();
        let estimate = match self.radius_estimate.unwrap_or_default() {
            RadiusEstimate::ThreePoint => Estimate::ThreePoint,
            RadiusEstimate::Minimum => Estimate::Minimum,
        };
        let min_radius = self.min_radius.map(|r| positive("min_radius", r, Measure::Length)).transpose()?;
        let mode = self.mode.or(machine.and_then(|m| m.mode)).unwrap_or_default();
        let plan = match (mode, self.rule) {
            (Mode::Window, Some(_)) => {
                return Err(SolverError::input("rule", "rule applies to mode \"curve\" only"));
            }
            (Mode::Window, None) => Plan::Window { length: window.unwrap_or(default_window), estimate },
            (Mode::Guarantee, rule) => {
                let stray = [
                    ("rule", rule.is_some()),
                    ("window", window.is_some()),
                    ("radius_estimate", self.radius_estimate.is_some()),
                ];
                if let Some((field, _)) = stray.iter().find(|(_, given)| *given) {
                    return Err(SolverError::input(
                        *field,
                        format!("{field} does not apply to mode \"guarantee\" (each chord uses its smallest radius)"),
                    ));
                }
                Plan::Guarantee
            }
            (Mode::Curve, rule) => match rule.unwrap_or_default() {
                CurveRule::Max => Plan::Max { length: window.unwrap_or(default_window), estimate },
                other => {
                    if window.is_some() {
                        return Err(SolverError::input(
                            "window",
                            "window applies to mode \"window\" and rule \"max\" only",
                        ));
                    }
                    if self.radius_estimate.is_some() {
                        return Err(SolverError::input(
                            "radius_estimate",
                            "radius_estimate applies to mode \"window\" and rule \"max\" only",
                        ));
                    }
                    if other == CurveRule::NormalAccel {
                        Plan::NormalAccel { min_radius }
                    } else {
                        Plan::Extremes { min_radius }
                    }
                }
            },
        };
        if min_radius.is_some() && !matches!(plan, Plan::Extremes { .. } | Plan::NormalAccel { .. }) {
            return Err(SolverError::input(
                "min_radius",
                "min_radius applies to mode \"curve\" with rule \"extremes\" or \"normal_accel\" only",
            ));
        }
        let tolerance = optional_tolerance("tolerance", self.tolerance)?;
        let compare_tolerance = optional_tolerance("compare_tolerance", self.compare_tolerance)?;
        let spindle_rpm = crate::machine::spindle_within(
            machine.and_then(|machine| machine.max_spindle_rpm),
            "spindle_rpm",
            self.spindle_rpm.map_or(Ok(DEFAULT_SPINDLE_RPM), |rpm| positive("spindle_rpm", rpm, Measure::Number))?,
        )?;
        let safe_z = self.safe_z.map(|z| coordinate("safe_z", z)).transpose()?;
        let (shape, corners, dimension, curve_warnings) = self.curve.build()?;
        warnings.extend(curve_warnings);
        let (start, end) = shape.domain();
        let mut spans = Vec::with_capacity(corners.len() + 1);
        let mut from = start;
        for corner in corners {
            if corner > from && corner < end {
                spans.push((from, corner));
                from = corner;
            }
        }
        spans.push((from, end));
        let least_increment = LEAST_INCREMENT * self.units.unwrap_or_default().mm_per_unit();
        Ok(Job {
            shape,
            spans,
            dimension,
            rule,
            plan,
            tolerance,
            compare_tolerance,
            spindle_rpm,
            safe_z,
            least_increment,
            warnings,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_follow_the_direction() {
        let deg = |x: f64| x.to_radians();
        assert!((sweep(0.0, 90.0, Direction::Ccw) - deg(90.0)).abs() < 1e-15);
        assert!((sweep(0.0, 90.0, Direction::Cw) - deg(270.0)).abs() < 1e-15);
        assert!((sweep(350.0, 10.0, Direction::Ccw) - deg(20.0)).abs() < 1e-14);
        assert!((sweep(0.0, 360.0, Direction::Ccw) - deg(360.0)).abs() < 1e-15);
        assert_eq!(sweep(30.0, 30.0, Direction::Ccw), 0.0);
    }
}
