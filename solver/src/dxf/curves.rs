//! The geometry of a DXF profile (docs/spec/dxf.md §2–§4): arcs, bulges, ellipses and splines as
//! chords, open pieces joined into loops, loops checked and nested.

use std::collections::HashMap;

use crate::error::SolverError;

/// An open piece of the profile: its points and the entity it came from.
/// A closed loop of the profile (the last point not repeated) and the entity it starts with.
pub(super) type Loop = (Vec<[f64; 2]>, String);

/// The outer boundary and the islands.
pub(super) type Nested = (Vec<[f64; 2]>, Vec<Vec<[f64; 2]>>);

pub(super) struct Piece {
    pub(super) points: Vec<[f64; 2]>,
    pub(super) label: String,
}

/// Chords per radian of an arc of `radius` whose sagitta stays within `tolerance`.
fn arc_steps(radius: f64, sweep: f64, tolerance: f64) -> usize {
    let step = if radius > tolerance { 2.0 * (1.0 - tolerance / radius).acos() } else { std::f64::consts::PI };
    ((sweep.abs() / step).ceil() as usize).clamp(1, 1_000_000)
}

/// The points of an arc after its start: from `start` (radians) through `sweep` (signed,
/// counter-clockwise positive), the start point first.
pub(super) fn flatten_arc(centre: [f64; 2], radius: f64, start: f64, sweep: f64, tolerance: f64) -> Vec<[f64; 2]> {
    let steps = arc_steps(radius, sweep, tolerance);
    (0..=steps)
        .map(|k| {
            let angle = start + sweep * k as f64 / steps as f64;
            [centre[0] + radius * angle.cos(), centre[1] + radius * angle.sin()]
        })
        .collect()
}

/// The points after `from` of a polyline segment to `to` with `bulge` (tan of a quarter of the
/// included angle, positive counter-clockwise); `to` exactly last.
pub(super) fn bulge_points(from: [f64; 2], to: [f64; 2], bulge: f64, tolerance: f64) -> Vec<[f64; 2]> {
    let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
    let chord = dx.hypot(dy);
    if bulge.abs() < 1e-12 || chord == 0.0 {
        return vec![to];
    }
    let sweep = 4.0 * bulge.atan();
    let radius = chord / (2.0 * (sweep / 2.0).sin().abs());
    // The centre lies left of the chord for a counter-clockwise arc (docs/spec/dxf.md §2).
    let k = (1.0 - bulge * bulge) / (4.0 * bulge);
    let centre = [(from[0] + to[0]) / 2.0 - dy * k, (from[1] + to[1]) / 2.0 + dx * k];
    let start = (from[1] - centre[1]).atan2(from[0] - centre[0]);
    let mut points = flatten_arc(centre, radius, start, sweep, tolerance);
    points.remove(0);
    if let Some(last) = points.last_mut() {
        *last = to;
    }
    points
}

/// An elliptic arc: centre, major axis (vector from the centre), `ratio` of minor to major
/// (negative: mirrored), parameters from `start` through `sweep` radians.
pub(super) fn flatten_ellipse(
    centre: [f64; 2],
    major: [f64; 2],
    ratio: f64,
    start: f64,
    sweep: f64,
    tolerance: f64,
) -> Vec<[f64; 2]> {
    let a = major[0].hypot(major[1]);
    let minor = [-major[1] * ratio, major[0] * ratio];
    // The largest radius of curvature is a²/b; its steps bound the sagitta everywhere.
    let b = a * ratio.abs();
    let steps = arc_steps(a * a / b.max(1e-12), sweep, tolerance).max(8);
    (0..=steps)
        .map(|k| {
            let t = start + sweep * k as f64 / steps as f64;
            let (c, s) = (t.cos(), t.sin());
            [centre[0] + major[0] * c + minor[0] * s, centre[1] + major[1] * c + minor[1] * s]
        })
        .collect()
}

/// A NURBS point at parameter `u` (de Boor's algorithm on homogeneous points).
pub(super) fn nurbs_point(degree: usize, control: &[[f64; 2]], knots: &[f64], weights: &[f64], u: f64) -> [f64; 2] {
    let n = control.len();
    let mut span = degree;
    while span + 1 < n && knots[span + 1] <= u {
        span += 1;
    }
    let mut d: Vec<[f64; 3]> = (0..=degree)
        .map(|j| {
            let i = span - degree + j;
            let w = weights[i];
            [control[i][0] * w, control[i][1] * w, w]
        })
        .collect();
    for r in 1..=degree {
        for j in (r..=degree).rev() {
            let i = span - degree + j;
            let denominator = knots[i + degree + 1 - r] - knots[i];
            let alpha = if denominator == 0.0 { 0.0 } else { (u - knots[i]) / denominator };
            let before = d[j - 1];
            for (value, previous) in d[j].iter_mut().zip(before) {
                *value = (1.0 - alpha) * previous + alpha * *value;
            }
        }
    }
    let p = d[degree];
    [p[0] / p[2], p[1] / p[2]]
}

/// A NURBS with clamped knots (the first and last knot `degree + 1` times) describing the same
/// curve on its domain [knots[degree], knots[n]]: each end's knot is inserted (Boehm's
/// algorithm, on homogeneous points) until it is repeated `degree` times, then the knots and
/// control points outside the domain are dropped.
pub(super) fn clamped(
    degree: usize,
    control: Vec<[f64; 2]>,
    knots: Vec<f64>,
    weights: Vec<f64>,
) -> (Vec<[f64; 2]>, Vec<f64>, Vec<f64>) {
    let mut points: Vec<[f64; 3]> = control.iter().zip(&weights).map(|(p, w)| [p[0] * w, p[1] * w, *w]).collect();
    let mut knots = knots;
    clamp_start(degree, &mut points, &mut knots);
    // The end is the start of the reversed curve (parameter mirrored).
    points.reverse();
    let (low, high) = (knots[0], knots[knots.len() - 1]);
    knots = knots.iter().rev().map(|k| low + high - k).collect();
    clamp_start(degree, &mut points, &mut knots);
    points.reverse();
    knots = knots.iter().rev().map(|k| low + high - k).collect();
    let control = points.iter().map(|p| [p[0] / p[2], p[1] / p[2]]).collect();
    let weights = points.iter().map(|p| p[2]).collect();
    (control, knots, weights)
}

fn clamp_start(degree: usize, points: &mut Vec<[f64; 3]>, knots: &mut Vec<f64>) {
    let start = knots[degree];
    if knots[..=degree].iter().all(|k| *k == start) {
        return;
    }
    // Insert `start` until it is there `degree` times.
    while knots.iter().filter(|k| **k == start).count() < degree {
        let span = knots.iter().rposition(|k| *k <= start).unwrap_or(degree);
        let mut inserted = Vec::with_capacity(points.len() + 1);
        for i in 0..=points.len() {
            if i + degree <= span {
                inserted.push(points[i]);
            } else if i > span {
                inserted.push(points[i - 1]);
            } else {
                let alpha = (start - knots[i]) / (knots[i + degree] - knots[i]);
                let (a, b) = (points[i - 1], points[i]);
                inserted.push([
                    (1.0 - alpha) * a[0] + alpha * b[0],
                    (1.0 - alpha) * a[1] + alpha * b[1],
                    (1.0 - alpha) * a[2] + alpha * b[2],
                ]);
            }
        }
        knots.insert(span + 1, start);
        *points = inserted;
    }
    // `start` at knots[j..j + degree]: the curve starts at control point j − 1.
    let j = knots.iter().position(|k| *k == start).unwrap_or(0);
    if j > 0 {
        points.drain(..j - 1);
        knots.drain(..j - 1);
        knots[0] = start;
    }
}

/// A spline as chords: each knot span halved until the curve's midpoint stays within
/// `tolerance` of the chord (and a quarter point too, so an inflection is not missed).
pub(super) fn flatten_spline(
    degree: usize,
    control: &[[f64; 2]],
    knots: &[f64],
    weights: &[f64],
    tolerance: f64,
) -> Vec<[f64; 2]> {
    let at = |u: f64| nurbs_point(degree, control, knots, weights, u);
    let (first, last) = (knots[degree], knots[control.len()]);
    let mut points = vec![at(first)];
    let mut stops: Vec<f64> = knots[degree..=control.len()].to_vec();
    stops.dedup();
    for pair in stops.windows(2) {
        subdivide(&at, pair[0], pair[1], tolerance, 0, &mut points);
    }
    if let Some(end) = points.last_mut() {
        *end = at(last);
    }
    points
}

fn subdivide(at: &impl Fn(f64) -> [f64; 2], u0: f64, u1: f64, tolerance: f64, depth: usize, out: &mut Vec<[f64; 2]>) {
    let (a, b) = (at(u0), at(u1));
    let flat = [0.25, 0.5, 0.75].iter().all(|f| to_segment(at(u0 + (u1 - u0) * f), a, b) <= tolerance);
    if depth >= 24 || (depth >= 2 && flat) {
        out.push(b);
        return;
    }
    let middle = 0.5 * (u0 + u1);
    subdivide(at, u0, middle, tolerance, depth + 1, out);
    subdivide(at, middle, u1, tolerance, depth + 1, out);
}

fn to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length = dx * dx + dy * dy;
    let t = if length > 0.0 { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length).clamp(0.0, 1.0) } else { 0.0 };
    (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
}

fn format_point(p: [f64; 2]) -> String {
    format!("({:.4} mm, {:.4} mm)", p[0], p[1])
}

/// Open pieces joined end to end within `tolerance` into closed loops (each with the label of
/// its first piece).
///
/// # Errors
/// An open chain: the end with no other end within the tolerance, and the nearest other end.
pub(super) fn join(pieces: Vec<Piece>, tolerance: f64, field: &str) -> Result<Vec<Loop>, SolverError> {
    let cell = tolerance.max(1e-9);
    let key = |p: [f64; 2]| ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64);
    // Every piece end by cell: (piece, whether it is the piece's last point).
    let mut ends: HashMap<(i64, i64), Vec<(usize, bool)>> = HashMap::new();
    for (index, piece) in pieces.iter().enumerate() {
        ends.entry(key(piece.points[0])).or_default().push((index, false));
        ends.entry(key(piece.points[piece.points.len() - 1])).or_default().push((index, true));
    }
    let mut used = vec![false; pieces.len()];
    let nearest_free = |p: [f64; 2], used: &[bool]| -> Option<(usize, bool, f64)> {
        let (cx, cy) = key(p);
        let mut best: Option<(f64, usize, bool)> = None;
        for x in cx - 1..=cx + 1 {
            for y in cy - 1..=cy + 1 {
                for &(index, is_last) in ends.get(&(x, y)).into_iter().flatten() {
                    if used[index] {
                        continue;
                    }
                    let points = &pieces[index].points;
                    let end = if is_last { points[points.len() - 1] } else { points[0] };
                    let gap = (end[0] - p[0]).hypot(end[1] - p[1]);
                    if gap <= tolerance && best.is_none_or(|b| gap < b.0) {
                        best = Some((gap, index, is_last));
                    }
                }
            }
        }
        best.map(|(gap, index, is_last)| (index, is_last, gap))
    };
    let mut loops = Vec::new();
    for first in 0..pieces.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let mut points = pieces[first].points.clone();
        loop {
            let end = points[points.len() - 1];
            let next = nearest_free(end, &used);
            // The chain closes at its start unless a free piece goes on nearer (pieces shorter
            // than the tolerance would otherwise close the loop one piece early).
            let closing = (end[0] - points[0][0]).hypot(end[1] - points[0][1]);
            if points.len() > 2 && closing <= tolerance && next.is_none_or(|(_, _, gap)| closing <= gap) {
                points.pop();
                break;
            }
            let Some((next, reversed, _)) = next else {
                let nearest = pieces
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| *i != first)
                    .flat_map(|(_, piece)| [piece.points[0], piece.points[piece.points.len() - 1]])
                    .chain(std::iter::once(points[0]))
                    .filter(|p| (p[0] - end[0]).hypot(p[1] - end[1]) > tolerance)
                    .min_by(|a, b| {
                        let da = (a[0] - end[0]).hypot(a[1] - end[1]);
                        let db = (b[0] - end[0]).hypot(b[1] - end[1]);
                        da.total_cmp(&db)
                    });
                let gap = nearest.map_or(String::new(), |p| {
                    format!(
                        "; the nearest end is {} at {:.4} mm (join_tolerance {tolerance} mm)",
                        format_point(p),
                        (p[0] - end[0]).hypot(p[1] - end[1])
                    )
                });
                return Err(SolverError::input(
                    field,
                    format!(
                        "open chain: the chain from {} ({}) stops at {} with no other end within \
                         {tolerance} mm{gap}",
                        format_point(points[0]),
                        pieces[first].label,
                        format_point(end),
                    ),
                ));
            };
            used[next] = true;
            let piece = &pieces[next].points;
            if reversed {
                points.extend(piece.iter().rev().skip(1));
            } else {
                points.extend(piece.iter().skip(1));
            }
        }
        loops.push((points, pieces[first].label.clone()));
    }
    Ok(loops)
}

/// Signed area (positive counter-clockwise).
fn area(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n).map(|i| points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1]).sum::<f64>() / 2.0
}

/// Where two segments cross (not at a shared end), if they do.
fn crossing(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> Option<[f64; 2]> {
    let r = [b[0] - a[0], b[1] - a[1]];
    let s = [d[0] - c[0], d[1] - c[1]];
    let denominator = r[0] * s[1] - r[1] * s[0];
    if denominator.abs() < 1e-15 {
        return None;
    }
    let q = [c[0] - a[0], c[1] - a[1]];
    let t = (q[0] * s[1] - q[1] * s[0]) / denominator;
    let u = (q[0] * r[1] - q[1] * r[0]) / denominator;
    let inside = |v: f64| v > 1e-9 && v < 1.0 - 1e-9;
    (inside(t) && inside(u)).then(|| [a[0] + t * r[0], a[1] + t * r[1]])
}

/// Refuses a loop that crosses itself, naming the point.
pub(super) fn check_simple(points: &[[f64; 2]], label: &str, field: &str) -> Result<(), SolverError> {
    let n = points.len();
    if n < 3 {
        return Err(SolverError::input(field, format!("the loop of {label} has no area")));
    }
    // Segments by grid cell; only segments sharing a cell are compared.
    let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for axis in 0..2 {
            low[axis] = low[axis].min(p[axis]);
            high[axis] = high[axis].max(p[axis]);
        }
    }
    let side = ((high[0] - low[0]).max(high[1] - low[1]) / (n as f64).sqrt()).max(1e-9);
    let cell = |v: f64, axis: usize| ((v - low[axis]) / side).floor() as i64;
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        for x in cell(a[0].min(b[0]), 0)..=cell(a[0].max(b[0]), 0) {
            for y in cell(a[1].min(b[1]), 1)..=cell(a[1].max(b[1]), 1) {
                grid.entry((x, y)).or_default().push(i);
            }
        }
    }
    for segments in grid.values() {
        for (k, &i) in segments.iter().enumerate() {
            for &j in &segments[k + 1..] {
                let adjacent = j == i + 1 || i == j + 1 || (i == 0 && j == n - 1) || (j == 0 && i == n - 1);
                if adjacent {
                    continue;
                }
                if let Some(p) = crossing(points[i], points[(i + 1) % n], points[j], points[(j + 1) % n]) {
                    return Err(SolverError::input(
                        field,
                        format!("self-intersection: the loop of {label} crosses itself at {}", format_point(p)),
                    ));
                }
            }
        }
    }
    if area(points).abs() < 1e-12 {
        return Err(SolverError::input(field, format!("the loop of {label} has no area")));
    }
    Ok(())
}

fn inside(p: [f64; 2], polygon: &[[f64; 2]]) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            inside = !inside;
        }
    }
    inside
}

/// The largest loop as the boundary (counter-clockwise) and the loops inside it as islands
/// (clockwise).
///
/// # Errors
/// A loop outside the boundary: the drawing holds more than one part.
pub(super) fn nest(loops: Vec<Loop>, field: &str) -> Result<Nested, SolverError> {
    let Some(outer) = (0..loops.len()).max_by(|&a, &b| area(&loops[a].0).abs().total_cmp(&area(&loops[b].0).abs()))
    else {
        return Err(SolverError::input(field, "the drawing has no closed loop"));
    };
    let mut boundary = loops[outer].0.clone();
    if area(&boundary) < 0.0 {
        boundary.reverse();
    }
    let mut islands = Vec::new();
    for (index, (points, label)) in loops.into_iter().enumerate() {
        if index == outer {
            continue;
        }
        if !inside(points[0], &boundary) {
            return Err(SolverError::input(
                field,
                format!(
                    "the loop of {label} at {} lies outside the outer boundary: the drawing holds more than one \
                     part; choose a layer",
                    format_point(points[0])
                ),
            ));
        }
        let mut island = points;
        if area(&island) > 0.0 {
            island.reverse();
        }
        islands.push(island);
    }
    Ok((boundary, islands))
}

/// The signed area, for the tests.
#[cfg(test)]
pub(super) fn tests_area(points: &[[f64; 2]]) -> f64 {
    area(points)
}
