//! The greedy chord on a polyline (docs/spec/segment.md §2.9a, the fast search for a polyline taken as the
//! true curve): the chord's end is placed on an edge exactly, where the first of the vertices
//! it spans reaches the chord error. With the chord from A to B(λ) = P + λ·E on the edge from P
//! to P + E, a vertex V is within e of the chord's line while |(V − A) × (B(λ) − A)|² ≤
//! e²·|B(λ) − A|², a quadratic in λ; the edge is found from the predicted one (the previous
//! chord's length) by these quadratics too. One pass over the chord's vertices per edge tried
//! and one to check the chord found, where the secant search measured the chord five or six
//! times (its function has a kink at every vertex).

use super::cut::Vertex;
use super::shape::Polyline;
use crate::geometry::Vec3;

/// Most edges tried for one chord before the caller's general search takes over.
const EDGE_TRIALS: usize = 64;

/// Where the chord from A reaches the chord error on one edge.
enum OnEdge {
    /// Already at the edge's start: some vertex is beyond the error there.
    Before,
    /// At this fraction of the edge.
    At(f64),
    /// Not on this edge: the chord to its end fits.
    Beyond,
}

/// The end of the longest chord from `start` whose vertices stay within `allowed` of it, up to
/// `limit`, with that chord's deviation; `predicted` is the expected chord length (mm).
/// `None` where this search cannot decide (a vertex projecting beyond the chord's ends, rounding
/// at a turn of the polyline): the caller's general search takes over.
pub(crate) fn chord_end(
    line: &Polyline,
    start: &Vertex,
    allowed: f64,
    limit: &Vertex,
    predicted: f64,
) -> Option<(f64, f64)> {
    let stations = &line.stations;
    let count = line.vertices.len();
    let a = start.point;
    // Aim a rounding's width inside: the distances are computed again from the end's own point.
    let size = a.amax().max(limit.point.amax()).max(1.0);
    let aim = allowed - 64.0 * f64::EPSILON * size;
    if aim <= 0.0 || count < 2 {
        return None;
    }
    let start_edge = line.edge(start.u);
    let first = start_edge + 1;
    if first >= count || stations[first] <= start.u {
        return None;
    }
    // The last vertex strictly before the limit; none: the chord to the limit spans no vertex.
    let Some(last) = last_before(stations, first, limit.u) else {
        return Some((limit.u, 0.0));
    };
    // Edge k runs from vertex k (k ≥ first) to vertex k + 1, or to the limit from `last`.
    let edge_end = |k: usize| if k == last { (limit.u, limit.point) } else { (stations[k + 1], line.vertices[k + 1]) };
    let on_edge = |k: usize| {
        let (_, end) = edge_end(k);
        crossing(&line.vertices[first..=k], &a, &line.vertices[k], &(end - line.vertices[k]), aim)
    };
    // From the predicted edge (the previous chord's length), forward by doubling steps until
    // an edge is too far, then by halving between the last edge reached and that one.
    let target = start.u + predicted;
    let mut edge = first;
    while edge < last && stations[edge + 1] <= target {
        edge += 1;
    }
    let mut reached = first - 1; // an edge whose end the chord reaches (first − 1: A's own)
    let mut too_far: Option<usize> = None; // an edge at whose start the chord is already too long
    let mut step = 1;
    for _ in 0..EDGE_TRIALS {
        match on_edge(edge)? {
            OnEdge::At(fraction) => {
                let (end_s, _) = edge_end(edge);
                return checked(line, start, stations[edge] + fraction * (end_s - stations[edge]), allowed);
            }
            OnEdge::Beyond if edge == last => return checked(line, start, limit.u, allowed),
            OnEdge::Beyond => reached = edge,
            OnEdge::Before => too_far = Some(edge),
        }
        edge = match too_far {
            // Two neighbouring edges disagree about the vertex between them: rounding.
            Some(far) if far <= reached + 1 => return None,
            Some(far) => (reached + far) / 2,
            None => {
                step *= 2;
                (edge + step / 2).min(last)
            }
        };
    }
    None
}

/// The last vertex index from `first` on with a station strictly before `limit`.
fn last_before(stations: &[f64], first: usize, limit: f64) -> Option<usize> {
    // A bisection, not a walk: the limit is often the path's end, far beyond the chord.
    let before = stations.get(first..)?.partition_point(|&s| s < limit);
    (before > 0).then(|| first + before - 1)
}

/// The chord from `start` to arc length `s` if its deviation, measured as the answer reports it,
/// is within `allowed`.
fn checked(line: &Polyline, start: &Vertex, s: f64, allowed: f64) -> Option<(f64, f64)> {
    let deviation = line.deviation(start.u, s);
    (deviation <= allowed).then_some((s, deviation))
}

/// Where on the edge from `from` along `along` (λ from 0 to 1) the chord from `a` first leaves
/// `aim` of a vertex in `spanned` (the vertices strictly between `a` and the edge's points,
/// `from` itself last), by the line distance. `None` for an edge of no length.
fn crossing(spanned: &[Vec3], a: &Vec3, from: &Vec3, along: &Vec3, aim: f64) -> Option<OnEdge> {
    let base = from - a;
    let aim_squared = aim * aim;
    let (base_squared, base_along, along_squared) = (base.norm_squared(), base.dot(along), along.norm_squared());
    if along_squared == 0.0 {
        return None;
    }
    let mut first_crossing = f64::INFINITY;
    for vertex in spanned {
        let w = vertex - a;
        let (p, q) = (w.cross(&base), w.cross(along));
        // f(λ) = |p + λq|² − e²·|base + λ·along|² = α·λ² + 2β·λ + γ.
        let alpha = q.norm_squared() - aim_squared * along_squared;
        let beta = p.dot(&q) - aim_squared * base_along;
        let gamma = p.norm_squared() - aim_squared * base_squared;
        if gamma > 0.0 {
            return Some(OnEdge::Before);
        }
        if let Some(root) = first_rise(alpha, beta, gamma) {
            first_crossing = first_crossing.min(root);
        }
    }
    Some(if first_crossing <= 1.0 { OnEdge::At(first_crossing) } else { OnEdge::Beyond })
}

/// The least λ ≥ 0 where α·λ² + 2β·λ + γ (γ ≤ 0) becomes positive, if any.
fn first_rise(alpha: f64, beta: f64, gamma: f64) -> Option<f64> {
    if alpha == 0.0 {
        return (beta > 0.0).then(|| -gamma / (2.0 * beta));
    }
    let discriminant = beta * beta - alpha * gamma;
    if discriminant < 0.0 {
        return None; // never reaches zero (α < 0 here)
    }
    // The roots without cancellation: q = −(β + sign(β)·√D), roots q/α and γ/q.
    let q = -(beta + beta.signum() * discriminant.sqrt());
    let (r1, r2) = (q / alpha, if q == 0.0 { 0.0 } else { gamma / q });
    let (low, high) = (r1.min(r2), r1.max(r2));
    if alpha > 0.0 {
        // Convex, non-positive at 0: one root ≤ 0 ≤ the other, where it rises.
        Some(high.max(0.0))
    } else if beta > 0.0 && low >= 0.0 {
        // Concave, rising at 0: it touches zero first at the lower root.
        Some(low)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polyline(points: Vec<Vec3>) -> Polyline {
        let mut stations = vec![0.0];
        for pair in points.windows(2) {
            stations.push(stations.last().unwrap() + (pair[1] - pair[0]).norm());
        }
        Polyline { vertices: points, stations, last_edge: std::cell::Cell::new(0) }
    }

    fn vertex(line: &Polyline, s: f64) -> Vertex {
        let edge = line.edge(s);
        let (a, b) = (line.vertices[edge], line.vertices[(edge + 1).min(line.vertices.len() - 1)]);
        let (s0, s1) = (line.stations[edge], line.stations[(edge + 1).min(line.vertices.len() - 1)]);
        let fraction = if s1 > s0 { ((s - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { 0.0 };
        Vertex { u: s, s, point: a + (b - a) * fraction }
    }

    #[test]
    fn chords_end_where_the_first_vertex_reaches_the_error() {
        // A wavy 3-D curve sampled 0.05 mm apart with a little noise, chords of 0.3 to 2 mm.
        let points: Vec<Vec3> = (0..4000)
            .map(|k| {
                let t = f64::from(k) * 0.05 / 30.0;
                let noise = 1e-4 * (f64::from(k) * 12.9898).sin();
                Vec3::new(30.0 * t.cos() + noise, 20.0 * t.sin() + 3.0 * (5.0 * t).sin(), 0.5 * t)
            })
            .collect();
        let line = polyline(points);
        let length = *line.stations.last().unwrap();
        let limit = vertex(&line, length);
        let mut found = 0;
        for (k, allowed) in (0..300).zip([1e-4, 1e-3, 1e-2].into_iter().cycle()) {
            let start = vertex(&line, length * f64::from(k) / 300.0);
            for predicted in [0.1, 1.0, 5.0] {
                let Some((end, deviation)) = chord_end(&line, &start, allowed, &limit, predicted) else {
                    continue;
                };
                assert!(end > start.u && end <= limit.u);
                assert_eq!(deviation, line.deviation(start.u, end));
                assert!(deviation <= allowed, "{deviation} over {allowed}");
                if end < limit.u {
                    // Longest: a micrometre further the chord no longer fits.
                    let further = (end + 1e-3 * (end - start.u)).min(limit.u);
                    assert!(
                        line.deviation(start.u, further) > allowed,
                        "chord from {} to {end} not the longest",
                        start.u
                    );
                }
                found += 1;
            }
        }
        assert!(found > 800, "only {found} chords decided here");
    }
}
