//! Chording of circular arcs from outside (docs/spec/contour.md §3.5.1 loop arcs): the polyline's segments are tangent to the arc, so no
//! point of it comes closer to the centre than the radius (a tool-centre arc chorded this way
//! never cuts deeper than the arc itself), and its first and last segments continue the arc's end
//! tangents exactly (collinear with straight moves that join the arc tangentially).

use super::{Vec2, direction};

/// The points after `start` of a polyline circumscribing the arc about `centre` that starts at
/// `start` and turns by `sweep` radians (positive counter-clockwise): `n` equal sub-arcs, a vertex
/// at the crossing of the tangents of each sub-arc's ends (at radius `R / cos(Δ/2)`), and the
/// arc's exact end point last. `n` is the smallest count keeping that outward deviation within
/// `max_error` (at least 1), capped at `max_steps`.
pub fn circumscribed_arc(centre: &Vec2, start: &Vec2, sweep: f64, max_error: f64, max_steps: usize) -> Vec<Vec2> {
    let radius = (start - centre).norm();
    circumscribed_arc_steps(centre, start, sweep, arc_steps(radius, sweep, max_error).min(max_steps.max(1)))
}

/// [`circumscribed_arc`] with `steps` equal sub-arcs (at least 1): the full segments are
/// `2R·tan(Δ/2)` long, the first and last (along the end tangents) half that.
pub fn circumscribed_arc_steps(centre: &Vec2, start: &Vec2, sweep: f64, steps: usize) -> Vec<Vec2> {
    let radius = (start - centre).norm();
    let start_angle = (start.y - centre.y).atan2(start.x - centre.x);
    let end = centre + radius * direction(start_angle + sweep);
    if radius == 0.0 || sweep == 0.0 {
        return vec![end];
    }
    let steps = steps.max(1);
    let step = sweep / steps as f64;
    let outer = radius / (0.5 * step).cos();
    let mut points: Vec<Vec2> =
        (0..steps).map(|k| centre + outer * direction(start_angle + (k as f64 + 0.5) * step)).collect();
    points.push(end);
    points
}

/// The largest sub-arc angle (radians) whose circumscribed vertex lies within `max_error` of an
/// arc of `radius`: `2·acos(R / (R + max_error))`, at most 120°; 0 for a degenerate input.
pub fn arc_max_step(radius: f64, max_error: f64) -> f64 {
    if max_error > 0.0 && radius > 0.0 { 2.0 * (radius / (radius + max_error)).acos() } else { 0.0 }
        .min(std::f64::consts::TAU / 3.0)
}

/// Sub-arcs needed so that the circumscribed polyline stays within `max_error` of the arc:
/// `R (1/cos(Δ/2) − 1) ≤ max_error`, and at most 120° per sub-arc.
pub fn arc_steps(radius: f64, sweep: f64, max_error: f64) -> usize {
    let max_step = arc_max_step(radius, max_error);
    if max_step <= 0.0 {
        return 1;
    }
    // Saturating float → integer conversion; callers cap the count anyway.
    ((sweep.abs() / max_step).ceil() as usize).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar::{cross, point_segment_distance};
    use approx::assert_abs_diff_eq;
    use std::f64::consts::PI;

    #[test]
    fn circumscribed_polyline_stays_outside_and_within_tolerance() {
        let centre = Vec2::new(22.0, -2.0);
        let start = Vec2::new(22.0, -1.0);
        let points = circumscribed_arc(&centre, &start, -1.5 * PI, 0.01, 10_000);
        assert_abs_diff_eq!(*points.last().unwrap(), Vec2::new(21.0, -2.0), epsilon = 1e-12);
        let mut previous = start;
        for point in &points {
            let nearest = point_segment_distance(&centre, &previous, point);
            assert!(nearest >= 1.0 - 1e-12, "{nearest}");
            assert!((point - centre).norm() <= 1.01 + 1e-12);
            previous = *point;
        }
        // The first segment continues the tangent at the start (heading +x for a clockwise arc
        // starting straight above the centre).
        let first = points[0] - start;
        assert_abs_diff_eq!(cross(&first, &Vec2::x()), 0.0, epsilon = 1e-12);
        assert!(first.x > 0.0);
    }

    #[test]
    fn step_count_follows_the_tolerance() {
        assert_eq!(arc_steps(1.0, PI / 2.0, 1.0), 1);
        assert!(arc_steps(1.0, 2.0 * PI, 1e-4) > 100);
        assert_eq!(arc_steps(1.0, PI, 0.0), 1);
    }
}
