//! Tool-path correction (docs/spec/predict.md §3.14, claim 9): every node moves against the
//! predicted errors of the passes on both sides of it, in the direction of E′_i + E′_j and by the
//! amount that best cancels both passes' normal errors (projection least squares); a clamp limits
//! the move (§5 E20). Arcs are refitted through their corrected chord points.

use crate::geometry::Vec3;

/// The predicted error of one pass: e (mm, along n) and the unit normal n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PassError {
    /// Signed error e, mm (> 0: material left).
    pub error: f64,
    /// Unit surface normal n, out of the material.
    pub normal: [f64; 3],
}

/// The correction of one node from the passes before (`previous`) and after (`next`) it:
/// c = s*·û with û ∥ E′_i + E′_j and s* = −Σ e_q(û·n_q) / Σ (û·n_q)²; one valid neighbour gives
/// c = −e·n, none gives 0. The flag is set when E′_i + E′_j vanishes (the two errors cancel).
pub fn node_correction(previous: Option<PassError>, next: Option<PassError>) -> ([f64; 3], bool) {
    let vector = |p: &PassError| Vec3::new(p.normal[0], p.normal[1], p.normal[2]);
    match (previous, next) {
        (None, None) => ([0.0; 3], false),
        (Some(only), None) | (None, Some(only)) => {
            let c = -only.error * vector(&only);
            ([c.x, c.y, c.z], false)
        }
        (Some(i), Some(j)) => {
            let (ni, nj) = (vector(&i), vector(&j));
            let sum = -i.error * ni - j.error * nj;
            let scale = i.error.abs().max(j.error.abs());
            if scale == 0.0 {
                return ([0.0; 3], false);
            }
            if sum.norm() <= 1e-9 * scale {
                return ([0.0; 3], true);
            }
            let direction = sum.normalize();
            let (di, dj) = (direction.dot(&ni), direction.dot(&nj));
            let denominator = di * di + dj * dj;
            if denominator <= 1e-18 {
                return ([0.0; 3], true);
            }
            let s = -(i.error * di + j.error * dj) / denominator;
            let c = s * direction;
            ([c.x, c.y, c.z], false)
        }
    }
}

/// Corrections of the nodes of one connected polyline: `passes[k]` runs from node k to node
/// k + 1 (`None`: no valid prediction), so there are `passes.len() + 1` nodes.
pub fn polyline_corrections(passes: &[Option<PassError>]) -> Vec<[f64; 3]> {
    (0..=passes.len())
        .map(|node| {
            let previous = node.checked_sub(1).and_then(|k| passes[k]);
            let next = passes.get(node).copied().flatten();
            node_correction(previous, next).0
        })
        .collect()
}

/// Shortens `c` to at most `limit`; returns whether it had to.
pub(crate) fn clamp(c: &mut Vec3, limit: f64) -> bool {
    let length = c.norm();
    if length > limit {
        *c *= limit / length;
        true
    } else {
        false
    }
}

/// Least-squares arc centre in the plane of axes (a, b) through the corrected ends, fitted to the
/// corrected interior chord points: the centre lies on the ends' perpendicular bisector, and
/// |p|² − |s|² − 2c·(p − s) = 0 is linear in the position along it.
pub(crate) fn refit_centre(start: &Vec3, end: &Vec3, interior: &[Vec3], guess: &Vec3, (a, b): (usize, usize)) -> Vec3 {
    let mid = [(start[a] + end[a]) / 2.0, (start[b] + end[b]) / 2.0];
    let chord = [end[a] - start[a], end[b] - start[b]];
    let length = chord[0].hypot(chord[1]);
    let mut centre = *guess;
    if length < 1e-12 {
        return centre;
    }
    let direction = [-chord[1] / length, chord[0] / length];
    let (mut numerator, mut denominator) = (0.0, 0.0);
    for p in interior {
        let d = [p[a] - start[a], p[b] - start[b]];
        let target = p[a] * p[a] + p[b] * p[b]
            - start[a] * start[a]
            - start[b] * start[b]
            - 2.0 * (mid[0] * d[0] + mid[1] * d[1]);
        let slope = 2.0 * (direction[0] * d[0] + direction[1] * d[1]);
        numerator += target * slope;
        denominator += slope * slope;
    }
    let along = if denominator > 1e-18 {
        numerator / denominator
    } else {
        (guess[a] - mid[0]) * direction[0] + (guess[b] - mid[1]) * direction[1]
    };
    centre[a] = mid[0] + along * direction[0];
    centre[b] = mid[1] + along * direction[1];
    centre
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refit_recovers_a_circle() {
        let centre = Vec3::new(1.0, 2.0, 0.0);
        let on = |angle: f64| centre + 5.0 * Vec3::new(angle.cos(), angle.sin(), 0.0);
        let interior: Vec<Vec3> = (1..10).map(|k| on(0.1 * f64::from(k))).collect();
        let fitted = refit_centre(&on(0.0), &on(1.0), &interior, &Vec3::zeros(), (0, 1));
        assert!((fitted - centre).norm() < 1e-9);
    }

    #[test]
    fn clamp_limits_length() {
        let mut c = Vec3::new(0.3, 0.4, 0.0);
        assert!(clamp(&mut c, 0.1));
        assert!((c.norm() - 0.1).abs() < 1e-15);
        assert!(!clamp(&mut c, 0.2));
    }
}
