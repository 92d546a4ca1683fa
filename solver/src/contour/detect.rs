//! Corner detection on an existing closed CL point list (docs/spec/contour.md §3.4, claims 8 and 9): the
//! patent's discrete curvature (a) with (b), (c, reading R2) and the protrusion condition (d),
//! its radial-difference measure (f), and the rotation-invariant turn-angle rule recommended as
//! the default.

use serde::{Deserialize, Serialize};

use super::element::ElementKind;
use super::job::LoopConfig;
use super::loops::{self, LoopShape};
use super::pass::MAX_ARC_STEPS;
use super::request::{self as contour_request, LoopStyle};
use crate::capability::Control;
use crate::error::{ErrorCode, SolverError, Warning};
use crate::planar::{Containment, SegmentGrid, Vec2, centroid, segments_intersect, signed_area, turn_angle, vec2};
use crate::validate::{MAX_COORDINATE, Measure, coordinates, finite, positive};

/// How corners are found on a point list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum DetectMode {
    /// σφ_i ≥ ψ_min (rotation-invariant; the default).
    #[default]
    TurnAngle,
    /// Claim 8: κ_i ≥ κ_th and condition (d).
    PatentCurvature,
    /// Claim 9: ΔL_i / h_i ≥ λ_th.
    PatentDeltaL,
}

/// The measures of §3.4 at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMeasures {
    /// κ_i of Eq. (a); `None` where a chord is vertical (the patent's formula is undefined).
    pub curvature: Option<f64>,
    /// Condition (d): farther from the centre than both neighbours.
    pub protrudes: bool,
    /// ΔL_i of Eq. (f), mm.
    pub delta_l: f64,
    /// ΔL_i / h_i with h_i the mean spacing at the point.
    pub delta_l_per_step: f64,
    /// φ_i: signed turn at the point, radians.
    pub turn: f64,
}

/// The centre (a, b) (the area centroid; the mean of the points for a degenerate list) and the
/// measures at every point of a closed point list.
pub fn measures(points: &[Vec2]) -> (Vec2, Vec<PointMeasures>) {
    let n = points.len();
    if n < 3 {
        return (Vec2::zeros(), Vec::new());
    }
    let centre = centroid(points).unwrap_or_else(|| points.iter().sum::<Vec2>() / n as f64);
    let radial = |p: &Vec2| (p - centre).norm();
    let list = (0..n)
        .map(|i| {
            let (before, here, after) = (points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
            let curvature = {
                let (dx0, dx1, dx) = (here.x - before.x, after.x - here.x, after.x - before.x);
                (dx0 != 0.0 && dx1 != 0.0 && dx != 0.0).then(|| {
                    let slope_in = (here.y - before.y) / dx0;
                    let slope_out = (after.y - here.y) / dx1;
                    let second = 2.0 * (slope_out - slope_in) / dx;
                    let mean = 0.5 * (slope_in + slope_out);
                    second.abs() / (1.0 + mean * mean).powf(1.5)
                })
            };
            let (l0, l1, l2) = (radial(&before), radial(&here), radial(&after));
            let delta_l = 2.0 * l1 - l0 - l2;
            let spacing = 0.5 * ((here - before).norm() + (after - here).norm());
            PointMeasures {
                curvature,
                protrudes: l1 > l0 && l1 > l2,
                delta_l,
                delta_l_per_step: if spacing > 0.0 { delta_l / spacing } else { 0.0 },
                turn: turn_angle(&(here - before), &(after - here)),
            }
        })
        .collect();
    (centre, list)
}

/// Whether a point is a corner under `mode` (`threshold`: ψ_min in radians for `turn_angle`,
/// κ_th in 1/mm, λ_th); `sigma` = +1 with the material on the left.
pub fn is_corner(measure: &PointMeasures, mode: DetectMode, threshold: f64, sigma: f64) -> bool {
    match mode {
        DetectMode::TurnAngle => sigma * measure.turn >= threshold,
        DetectMode::PatentCurvature => measure.protrudes && measure.curvature.is_some_and(|k| k >= threshold),
        DetectMode::PatentDeltaL => measure.delta_l_per_step >= threshold,
    }
}

/// Which side of travel the material lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum MaterialSide {
    /// Material on the left of travel (σ = +1).
    #[default]
    Left,
    /// Material on the right of travel (σ = −1).
    Right,
}

/// Corner loops added to a closed tool-centre path made elsewhere (claims 8–10): detect the
/// corners on its points, then loop round the protruding ones.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PathLoopRequest {
    /// The closed CL path `[[x, y], ...]` of the tool centre in travel order (the last point need
    /// not repeat the first).
    pub path: Vec<[f64; 2]>,
    /// `left` (default) or `right` of travel.
    #[serde(default)]
    pub material_side: MaterialSide,
    /// `turn_angle` (default), `patent_curvature` (claim 8) or `patent_delta_l` (claim 9).
    #[serde(default)]
    pub detect: DetectMode,
    /// Threshold of the mode: ψ_min in degrees for `turn_angle` (default 10), κ_th in 1/mm for
    /// `patent_curvature` (default 1/tool_radius), λ_th for `patent_delta_l` (default
    /// sin(5°)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
    /// Tool radius, mm (the default loop size).
    pub tool_radius: f64,
    /// Loop style and sizing (as for contours).
    #[serde(default)]
    pub corner_loop: super::request::CornerLoop,
    /// Chord tolerance of loop arcs, mm (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
}

/// The detection measures at one path point.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct DetectedPoint {
    /// Signed turn φ, degrees (counter-clockwise positive).
    pub turn_deg: f64,
    /// κ of Eq. (a), 1/mm; absent where a chord is vertical.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curvature: Option<f64>,
    /// Condition (d).
    pub protrudes: bool,
    /// ΔL of Eq. (f), mm.
    pub delta_l: f64,
    /// ΔL / h.
    pub delta_l_per_step: f64,
    /// Whether the chosen mode calls it a corner.
    pub corner: bool,
    /// Whether a loop was made there.
    pub looped: bool,
}

/// One move of the looped path.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PathMove {
    /// `cut` (the given path, exit and entry legs) or `loop`.
    pub kind: super::answer::MoveKind,
    /// End point `[x, y]`.
    pub to: [f64; 2],
}

/// The answer of [`loop_path`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PathLoopAnswer {
    /// The centre (a, b) of the trajectory used by (d) and (f): the area centroid.
    pub centre: [f64; 2],
    /// Per input point (after removing repeated points).
    pub points: Vec<DetectedPoint>,
    /// The path with loops, from the first point round to it.
    pub moves: Vec<PathMove>,
    /// Claim 10: the largest |cross| of incoming and outgoing unit moves at the corner visits.
    pub max_abs_cross: f64,
    /// Claim 10: the smallest dot product there (1: straight through).
    pub min_dot: f64,
    /// Everything worth knowing.
    pub warnings: Vec<crate::error::Warning>,
}

/// Adds corner loops to a closed CL path (claims 8–10). The loops are checked against the path
/// itself: no loop move may cross it or enter the material side (the material lies at least the
/// tool radius beyond a valid CL path, so that keeps the loops in the air).
///
/// # Errors
/// `E_INPUT` for bad numbers, `E_DEGENERATE` for fewer than 3 distinct points,
/// `E_TOO_MANY_POINTS`, `E_TOO_MANY_MOVES` (over the contour's move limit).
pub fn loop_path(request: &PathLoopRequest) -> Result<PathLoopAnswer, SolverError> {
    loop_path_within(request, super::request::MAX_MOVES, Control::default())
}

/// [`loop_path`] with a smaller move budget: `E_TOO_MANY_MOVES` at `path` as soon as the looped
/// path holds more than `max_moves` moves (huge loops chorded finely on many corners).
///
/// # Errors
/// As [`loop_path`].
pub fn loop_path_within(
    request: &PathLoopRequest,
    max_moves: usize,
    control: Control<'_>,
) -> Result<PathLoopAnswer, SolverError> {
    let radius = positive("tool_radius", request.tool_radius, Measure::Length)?;
    let points = path_points(request, max_moves)?;
    control.check()?;
    let n = points.len();
    let tolerance = request.tolerance.unwrap_or(contour_request::DEFAULT_TOLERANCE);
    if finite("tolerance", tolerance)? < contour_request::MIN_TOLERANCE {
        return Err(SolverError::input("tolerance", "tolerance is below the smallest accepted"));
    }
    let sigma = match request.material_side {
        MaterialSide::Left => 1.0,
        MaterialSide::Right => -1.0,
    };
    let threshold = detect_threshold(request, radius)?;
    // The loop sizing of contours, with the request's detection deciding where.
    let config = request.corner_loop.config(radius)?;

    let (centre, measures) = measures(&points);
    control.check()?;
    let mut warnings = Vec::new();
    let corner = detect_corners(request, &measures, sigma, threshold, &config, &mut warnings);
    control.check()?;

    let material_inside = (signed_area(&points) > 0.0) == (sigma > 0.0);
    let grid = SegmentGrid::new((0..n).map(|k| (points[k], points[(k + 1) % n])).collect(), 0.0);
    control.check()?;
    let looper = Looper { points: &points, grid, material_inside, tolerance, sigma };
    let mut scratch = Vec::new();
    let mut looped = vec![false; n];
    let mut skipped = 0;
    let mut moves: Vec<PathMove> = Vec::with_capacity(n + 1);
    let mut visits: Vec<usize> = Vec::new();
    let mut route: Vec<Vec2> = vec![points[0]];
    let cut = super::answer::MoveKind::Cut;
    for step in 1..=n {
        control.check()?;
        control.report(step, n);
        let k = step % n;
        let p = points[k];
        moves.push(PathMove { kind: cut, to: [p.x, p.y] });
        route.push(p);
        if !corner[k] || config.style == LoopStyle::None {
            continue;
        }
        let d1 = (p - points[(k + n - 1) % n]).normalize();
        let d2 = (points[(k + 1) % n] - p).normalize();
        let Some((shape, _)) = loops::sized(&config, &p, &d1, &d2, sigma) else {
            continue;
        };
        let Some(shape) = looper.fitted(shape, k, &d1, &d2, &mut scratch) else {
            skipped += 1;
            continue;
        };
        looped[k] = true;
        visits.push(route.len() - 1);
        let looped_moves = chorded_loop(&shape, &p, tolerance);
        if moves.len() + looped_moves.len() + (n - step) > max_moves {
            return Err(SolverError::new(
                ErrorCode::TooManyMoves,
                format!(
                    "the looped path needs more than {max_moves} moves: use a coarser tolerance, smaller loops or fewer points"
                ),
            )
            .at("path"));
        }
        for (_, to, kind) in looped_moves {
            let kind = if kind == ElementKind::Loop { super::answer::MoveKind::Loop } else { cut };
            moves.push(PathMove { kind, to: [to.x, to.y] });
            route.push(to);
        }
        visits.push(route.len() - 1);
    }
    if skipped > 0 {
        warnings.push(Warning::new(
            "W_LOOP_SKIPPED_GOUGE",
            format!("{skipped} corners got no loop: every variant would cross the path or enter the material"),
        ));
    }
    let (max_abs_cross, min_dot) = corner_visit_turns(&visits, &route);
    let points = measures
        .iter()
        .zip(corner.iter().zip(&looped))
        .map(|(m, (&corner, &looped))| DetectedPoint {
            turn_deg: m.turn.to_degrees(),
            curvature: m.curvature,
            protrudes: m.protrudes,
            delta_l: m.delta_l,
            delta_l_per_step: m.delta_l_per_step,
            corner,
            looped,
        })
        .collect();
    Ok(PathLoopAnswer { centre: [centre.x, centre.y], points, moves, max_abs_cross, min_dot, warnings })
}

/// The request's path as points: finite, repeated points dropped (also a last point repeating
/// the first), at least 3 and at most `max_moves` of them.
fn path_points(request: &PathLoopRequest, max_moves: usize) -> Result<Vec<Vec2>, SolverError> {
    if request.path.len() > contour_request::MAX_POINTS {
        return Err(SolverError::new(
            ErrorCode::TooManyPoints,
            format!("the path has {} points; the limit is {}", request.path.len(), contour_request::MAX_POINTS),
        )
        .at("path"));
    }
    let mut points: Vec<Vec2> = Vec::with_capacity(request.path.len());
    for (index, point) in request.path.iter().enumerate() {
        let p = vec2(if point.iter().all(|value| value.is_finite() && value.abs() <= MAX_COORDINATE) {
            *point
        } else {
            coordinates(&format!("path[{index}]"), *point)?
        });
        if points.last().is_none_or(|last| (p - last).norm() > super::prepare::DUPLICATE_TOLERANCE) {
            points.push(p);
        }
    }
    while points.len() > 1 && (points[0] - points[points.len() - 1]).norm() <= super::prepare::DUPLICATE_TOLERANCE {
        points.pop();
    }
    let n = points.len();
    if n < 3 {
        return Err(SolverError::new(ErrorCode::Degenerate, "the path needs at least 3 distinct points").at("path"));
    }
    if n > max_moves {
        return Err(SolverError::new(
            ErrorCode::TooManyMoves,
            format!("the path alone has more than {max_moves} moves"),
        )
        .at("path"));
    }
    Ok(points)
}

/// The detection threshold in the units [`is_corner`] takes (radians for the turn angle), the
/// mode's default when the request gives none.
fn detect_threshold(request: &PathLoopRequest, radius: f64) -> Result<f64, SolverError> {
    let threshold = match (request.detect, request.threshold) {
        (_, Some(value)) => positive("threshold", value, Measure::Number)?,
        (DetectMode::TurnAngle, None) => 10.0,
        (DetectMode::PatentCurvature, None) => 1.0 / radius,
        (DetectMode::PatentDeltaL, None) => 5f64.to_radians().sin(),
    };
    if request.detect == DetectMode::TurnAngle {
        if threshold >= 180.0 {
            return Err(SolverError::input("threshold", "a turn threshold must lie below 180°"));
        }
        Ok(threshold.to_radians())
    } else {
        Ok(threshold)
    }
}

/// Per point: whether the request's mode calls it a corner turning towards the air; warns where
/// the patent's rules are undefined or miss turns the loop sizing would take.
fn detect_corners(
    request: &PathLoopRequest,
    measures: &[PointMeasures],
    sigma: f64,
    threshold: f64,
    config: &LoopConfig,
    warnings: &mut Vec<Warning>,
) -> Vec<bool> {
    let undefined = measures.iter().filter(|m| m.curvature.is_none()).count();
    if request.detect == DetectMode::PatentCurvature && undefined > 0 {
        warnings.push(Warning::new(
            "W_DETECT_UNDEFINED",
            format!("Eq. (a) is undefined at {undefined} points (vertical chords); use turn_angle there"),
        ));
    }
    let corner: Vec<bool> =
        measures.iter().map(|m| sigma * m.turn > 0.0 && is_corner(m, request.detect, threshold, sigma)).collect();
    if request.detect != DetectMode::TurnAngle {
        let disagree = measures.iter().zip(&corner).filter(|(m, c)| sigma * m.turn >= config.min_turn && !**c).count();
        if disagree > 0 {
            warnings.push(Warning::new(
                "W_DETECT_DISAGREE",
                format!(
                    "{disagree} points turn by at least {:.1}° towards the air but the patent rule misses them",
                    config.min_turn.to_degrees()
                ),
            ));
        }
    }
    corner
}

/// A loop's moves from `p` round to `p`: its arcs chorded from outside within `tolerance`, each
/// move with its element's kind.
fn chorded_loop(shape: &LoopShape, p: &Vec2, tolerance: f64) -> Vec<(Vec2, Vec2, ElementKind)> {
    let mut from = *p;
    let mut moves = Vec::new();
    for element in shape.elements(p) {
        for to in element.chord(tolerance, MAX_ARC_STEPS) {
            moves.push((from, to, element.kind()));
            from = to;
        }
    }
    moves
}

/// The given path and what a loop on it must clear: the path itself and its material side.
struct Looper<'a> {
    points: &'a [Vec2],
    grid: SegmentGrid,
    /// Whether the material lies inside the closed path.
    material_inside: bool,
    tolerance: f64,
    sigma: f64,
}

impl Looper<'_> {
    /// The loop at point `k` that clears the path: `shape` as sized, else up to four halvings,
    /// then a triangle of the last leg; `None` when none of them clears.
    fn fitted(&self, shape: LoopShape, k: usize, d1: &Vec2, d2: &Vec2, scratch: &mut Vec<usize>) -> Option<LoopShape> {
        let p = self.points[k];
        let mut candidate = Some(shape);
        let mut attempt = shape;
        for round in 0..6 {
            if self.clears(&attempt, k, scratch) {
                break;
            }
            attempt = if round < 4 {
                attempt.scaled(&p, d1, d2, self.sigma, 0.5)
            } else {
                LoopShape::triangle(&p, d1, d2, attempt.leg)
            };
            if round == 5 {
                candidate = None;
            }
        }
        candidate.map(|_| attempt)
    }

    /// Whether every move of the loop at point `k` ends off the material side and crosses no
    /// edge of the path but the two meeting at `k`.
    fn clears(&self, shape: &LoopShape, k: usize, scratch: &mut Vec<usize>) -> bool {
        let (points, grid, material_inside) = (self.points, &self.grid, self.material_inside);
        let n = points.len();
        let p = points[k];
        let (before, after) = ((k + n - 1) % n, k);
        chorded_loop(shape, &p, self.tolerance).iter().all(|(a, b, _)| {
            let outside = match grid.containment(b, scratch) {
                Containment::Boundary => (b - p).norm() < 1e-12,
                Containment::Inside => !material_inside,
                Containment::Outside => material_inside,
            };
            scratch.clear();
            grid.candidates(a, b, 0.0, scratch);
            outside
                && scratch
                    .iter()
                    .all(|&e| e == before || e == after || !segments_intersect(a, b, &points[e], &points[(e + 1) % n]))
        })
    }
}

/// Claim 10 at the corner visits (route indices): the largest |cross| and the smallest dot
/// product of the unit moves into and out of each.
fn corner_visit_turns(visits: &[usize], route: &[Vec2]) -> (f64, f64) {
    let (mut max_abs_cross, mut min_dot) = (0.0_f64, 1.0_f64);
    for &i in visits {
        let (Some(back), Some(here), Some(ahead)) =
            (i.checked_sub(1).and_then(|j| route.get(j)), route.get(i), route.get(i + 1))
        else {
            continue;
        };
        let (Some(u), Some(v)) = ((here - back).try_normalize(0.0), (ahead - here).try_normalize(0.0)) else {
            continue;
        };
        max_abs_cross = max_abs_cross.max(crate::planar::cross(&u, &v).abs());
        min_dot = min_dot.min(u.dot(&v));
    }
    (max_abs_cross, min_dot)
}
