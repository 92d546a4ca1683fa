//! Division coordinates and the one-number encoding of claim 1 (docs/spec/contour.md §3.6), and the
//! straightness check at the corner points of claim 10 (§3.7).
//!
//! The centre path is cut into points: every element end is one (so each looped corner point P
//! appears twice), a line of length ℓ gets ⌈ℓ/h⌉ equal steps, an arc ⌈ρ|sweep|/h⌉ equal angular
//! steps (chord points on the arc). Each step is a heading and one length.

use super::element::{Element, ElementKind};
use crate::planar::{Vec2, cross, direction};

/// The division of a pass.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Division {
    /// The points, from S round to S.
    pub points: Vec<Vec2>,
    /// Running length along the chords at each point, mm.
    pub s: Vec<f64>,
    /// Per step: heading θ_k (radians, from +x) and length ℓ_k.
    pub turtle: Vec<(f64, f64)>,
    /// Indices of the corner visits: the start of every exit leg and the end of every entry leg.
    pub corner_visits: Vec<usize>,
}

/// Divides the elements with largest spacing `h` (> 0).
pub fn divide(elements: &[Element], h: f64) -> Division {
    let mut division = Division::default();
    let Some(first) = elements.first() else {
        return division;
    };
    division.points.push(first.start());
    division.s.push(0.0);
    let steps = |length: f64| ((length / h - 1e-9).ceil()).max(1.0) as usize;
    for element in elements {
        if element.kind() == ElementKind::Exit {
            division.corner_visits.push(division.points.len() - 1);
        }
        let start = division.points.last().copied().unwrap_or_else(|| element.start());
        let mut new_points: Vec<Vec2> = match element {
            Element::Line { end, .. } => {
                let count = steps(element.length());
                (1..=count).map(|i| start + (end - start) * (i as f64 / count as f64)).collect()
            }
            Element::Arc { centre, radius, sweep, .. } => {
                let count = steps(element.length());
                let begin = (start - centre).y.atan2((start - centre).x);
                (1..=count).map(|i| centre + *radius * direction(begin + sweep * (i as f64 / count as f64))).collect()
            }
        };
        if let Some(last) = new_points.last_mut() {
            *last = element.end();
        }
        for point in new_points {
            let previous = division.points.last().copied().unwrap_or(point);
            let step = point - previous;
            let length = step.norm();
            division.turtle.push((step.y.atan2(step.x), length));
            division.s.push(division.s.last().copied().unwrap_or(0.0) + length);
            division.points.push(point);
        }
        if element.kind() == ElementKind::Entry {
            division.corner_visits.push(division.points.len() - 1);
        }
    }
    division
}

/// Claim 10 at every corner visit: the largest |unit(P_i − P_{i−f}) × unit(P_{i+k} − P_i)| and
/// the smallest dot product of the same unit vectors (1 when the path runs straight through).
pub fn collinearity(division: &Division, before: usize, after: usize) -> (f64, f64) {
    let mut worst_cross: f64 = 0.0;
    let mut worst_dot: f64 = 1.0;
    for &i in &division.corner_visits {
        let (Some(back), Some(ahead), Some(here)) = (
            i.checked_sub(before).and_then(|j| division.points.get(j)),
            division.points.get(i + after),
            division.points.get(i),
        ) else {
            continue;
        };
        let (Some(u), Some(v)) = ((here - back).try_normalize(0.0), (ahead - here).try_normalize(0.0)) else {
            continue;
        };
        worst_cross = worst_cross.max(cross(&u, &v).abs());
        worst_dot = worst_dot.min(u.dot(&v));
    }
    (worst_cross, worst_dot)
}

/// Replays a turtle list from `start` (check T1: it reproduces the points).
pub fn replay(start: Vec2, turtle: &[(f64, f64)]) -> Vec<Vec2> {
    let mut points = vec![start];
    let mut at = start;
    for (heading, length) in turtle {
        at += *length * direction(*heading);
        points.push(at);
    }
    points
}

/// Points on a closed polygon with spacing at most `h`: each edge in ⌈ℓ/h⌉ equal steps, starting
/// at vertex 0; returns the points and the index of every polygon vertex among them.
pub fn divide_polygon(polygon: &[Vec2], h: f64) -> (Vec<Vec2>, Vec<usize>) {
    let n = polygon.len();
    let mut points = Vec::new();
    let mut vertices = Vec::with_capacity(n);
    for k in 0..n {
        let (a, b) = (polygon[k], polygon[(k + 1) % n]);
        vertices.push(points.len());
        let count = (((b - a).norm() / h - 1e-9).ceil()).max(1.0) as usize;
        points.extend((0..count).map(|i| a + (b - a) * (i as f64 / count as f64)));
    }
    (points, vertices)
}
