//! Engine B, the exact boundary test (docs/spec/engagement.md §5.3.3): at each sample, the part of the
//! tool circle that lies in the stock and at least R from the path travelled so far.
//!
//! Instead of stepping θ on a grid and bisecting, the circle is split where it crosses any
//! boundary that can change the answer: the stock outline (or bitmap cell edges, or the edge of
//! an earlier cut) and the R-offsets of the nearby travelled pieces (offset lines or circles and
//! the end circles). Between two consecutive crossings membership cannot change, so one test at
//! the middle decides the whole sub-arc and the arc ends are exact, with no δθ.

use crate::error::ErrorCode;
use std::f64::consts::PI;

use super::P2;
use super::arcs::{Arc, normalise};
use super::segments::{NearPieces, Route, Shape, Station};
use super::stock::{NearEdges, OutlineSide, REACH_TOLERANCE, Region};
use crate::error::SolverError;
use crate::planar::right_normal;

/// Boundary and distance tests allowed per path before the engine gives up (a hang guard for
/// pathological stock outlines; tens of seconds of work, far above real jobs).
pub(crate) const MAX_TESTS: u64 = 4_000_000_000;

/// Reusable buffers and the work counter.
#[derive(Debug, Default)]
pub(crate) struct ExactEngine {
    pieces: Vec<Shape>,
    near: NearPieces,
    near_edges: NearEdges,
    /// The last circle clear of the outline: its centre, radius and whether it lies in the
    /// outline. A clear circle whose disc overlaps that one's lies in the same face of the
    /// outline (the two discs together are connected and hold no edge), so it has the same
    /// answer without the ray query.
    last_clear: Option<(P2, f64, bool)>,
    angles: Vec<f64>,
    tests: u64,
    /// Tests allowed before the engine gives up; at least [`MAX_TESTS`].
    limit: u64,
    /// The last normal's bits and its polar angle: along a line every sample has the same
    /// normal, and the angle is a pure function of it.
    last_angle: Option<([u64; 2], f64)>,
    /// Per sub-arc position of the last sample: its middle angle's bits with that angle's
    /// cosine and sine. Consecutive samples along a straight cut mostly split the circle at the
    /// same tool angles to the bit, so the middles repeat and their cosine and sine (a fifth of
    /// the engine's time) are pure functions of them.
    middles: Vec<(u64, f64, f64)>,
    /// The arcs of the last [`Self::arcs_in_place`] call (a buffer kept between samples).
    found: Vec<Arc>,
}

impl ExactEngine {
    /// An engine allowed `limit` tests (at least [`MAX_TESTS`]): one that evaluates several
    /// circles per sample (the height bands of a rounded end).
    pub(crate) fn with_limit(limit: u64) -> Self {
        Self { limit, ..Self::default() }
    }

    /// The engaged arcs at `station` (§5.3.1) for a tool of `radius`.
    pub(crate) fn arcs(
        &mut self,
        route: &Route,
        region: &Region,
        radius: f64,
        station: &Station,
    ) -> Result<Vec<Arc>, SolverError> {
        Ok(self.arcs_in_place(route, region, radius, station)?.to_vec())
    }

    /// [`Self::arcs`] in the engine's own buffer, valid until the next call: the sample loop
    /// keeps a copy only when the arcs differ from the previous sample's, so most samples
    /// allocate nothing here.
    pub(crate) fn arcs_in_place(
        &mut self,
        route: &Route,
        region: &Region,
        radius: f64,
        station: &Station,
    ) -> Result<&[Arc], SolverError> {
        let centre = station.centre;
        let forward = station.tangent;
        let right = right_normal(&forward);
        route.swept_before(station, 2.0 * radius, &mut self.pieces, &mut self.near);
        self.angles.clear();
        for piece in &self.pieces {
            piece.crossings(radius, centre, radius, &mut self.angles);
        }
        let outline_side = region.crossings(centre, radius, &mut self.angles, &mut self.near_edges);
        // Global polar angle γ ↦ tool angle θ = γ − angle of the right-hand normal (§4.1).
        let bits = [right.x.to_bits(), right.y.to_bits()];
        let right_angle = match self.last_angle {
            Some((last, angle)) if last == bits => angle,
            _ => {
                let angle = right.y.atan2(right.x);
                self.last_angle = Some((bits, angle));
                angle
            }
        };
        for angle in &mut self.angles {
            *angle = wrap_rad(*angle - right_angle);
        }
        self.angles.extend([-PI, -PI / 2.0, 0.0, PI / 2.0]);
        // Unstable is enough: angles equal under the total order are the same bits.
        self.angles.sort_unstable_by(f64::total_cmp);
        self.angles.dedup_by(|a, b| (*a - *b).abs() <= 1e-13);
        self.tests += (self.angles.len() * (self.pieces.len() + 1)) as u64;
        self.check_budget()?;
        let limit = radius * (1.0 - REACH_TOLERANCE);
        let mut arcs = std::mem::take(&mut self.found);
        arcs.clear();
        // Clear of the outline: one containment test at the centre answers for every sub-arc
        // (the outline's ray query is the costly part of a test), taken at the first need.
        let mut centre_in_outline: Option<bool> = None;
        let count = self.angles.len();
        for index in 0..count {
            let low = self.angles[index];
            let high = self.angles.get(index + 1).copied().unwrap_or(PI);
            if high - low <= 0.0 {
                continue;
            }
            let middle = 0.5 * (low + high);
            let (cos, sin) = self.middle_cos_sin(index, middle);
            let q = centre + radius * (cos * right + sin * forward);
            let engaged = self.pieces.iter().all(|piece| piece.distance(q) >= limit)
                && match outline_side {
                    OutlineSide::Clear => {
                        *centre_in_outline.get_or_insert_with(|| match self.last_clear {
                            Some((last, last_radius, inside)) if (centre - last).norm() < radius.min(last_radius) => {
                                self.last_clear = Some((centre, radius, inside));
                                inside
                            }
                            _ => {
                                let inside = region.in_outline(centre, &mut self.tests);
                                self.last_clear = Some((centre, radius, inside));
                                inside
                            }
                        }) && region.kept_by_cuts(q, &mut self.tests)
                    }
                    OutlineSide::Near => region.contains(q, &mut self.tests),
                };
            if engaged {
                arcs.push(Arc { from: low.to_degrees(), to: high.to_degrees() });
            }
        }
        self.found = normalise(arcs);
        self.check_budget()?;
        Ok(&self.found)
    }

    /// cos and sin of the middle of sub-arc `index`, reused from the last sample when that
    /// sub-arc had the same middle.
    fn middle_cos_sin(&mut self, index: usize, middle: f64) -> (f64, f64) {
        let bits = middle.to_bits();
        if let Some(&(last, cos, sin)) = self.middles.get(index)
            && last == bits
        {
            return (cos, sin);
        }
        let (cos, sin) = (middle.cos(), middle.sin());
        if index >= self.middles.len() {
            // Sub-arcs are visited in order, so the list grows one position at a time; the
            // placeholder NaN bits never match a middle, which lies in [−π, π].
            self.middles.resize(index + 1, (f64::NAN.to_bits(), 0.0, 0.0));
        }
        if let Some(slot) = self.middles.get_mut(index) {
            *slot = (bits, cos, sin);
        }
        (cos, sin)
    }

    /// Refuses once the work limit is spent.
    fn check_budget(&self) -> Result<(), SolverError> {
        let limit = self.limit.max(MAX_TESTS);
        if self.tests > limit {
            return Err(SolverError::new(
                ErrorCode::WorkLimit,
                format!(
                    "the exact engine exceeded its limit of {limit} boundary tests: use a larger step or a simpler stock"
                ),
            )
            .at("step"));
        }
        Ok(())
    }
}

/// Wraps radians into [−π, π).
fn wrap_rad(angle: f64) -> f64 {
    let wrapped = euclid_turn(angle + PI) - PI;
    if wrapped >= PI { -PI } else { wrapped }
}

/// `shifted.rem_euclid(2π)` to the bit, without its `fmod` call for the engine's angles
/// (a polar angle less the normal's, shifted by π: within [−π, 3π]), where the call was over 1 %
/// of the run time. On [2π, 4π) fmod's exact result is shifted − 2π, which that subtraction
/// gives exactly (Sterbenz); on (−2π, 0) rem_euclid adds 2π to shifted itself, as done here.
fn euclid_turn(shifted: f64) -> f64 {
    let turn = 2.0 * PI;
    if (0.0..turn).contains(&shifted) {
        shifted
    } else if (turn..2.0 * turn).contains(&shifted) {
        shifted - turn
    } else if shifted > -turn && shifted < 0.0 {
        // −2π itself goes to rem_euclid: fmod gives −0 there, which it keeps.
        shifted + turn
    } else {
        shifted.rem_euclid(turn)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euclid_turn_is_rem_euclid_to_the_bit() {
        let turn = 2.0 * PI;
        let mut values = vec![0.0, -0.0, turn, 2.0 * turn, -turn, PI, 3.0 * PI, -PI, 1e-300, -1e-300, 7.0 * PI];
        values.extend([turn, 2.0 * turn, -turn].iter().flat_map(|&v| [v.next_up(), v.next_down()]));
        // A deterministic spread over the engine's range and beyond.
        let mut x = 0.123_456_789_f64;
        for _ in 0..100_000 {
            x = (x * 3.987_654_321 + 0.314_159).fract();
            values.push(-3.0 * PI + 9.0 * PI * x);
        }
        for value in values {
            assert_eq!(euclid_turn(value).to_bits(), value.rem_euclid(turn).to_bits(), "{value:e}");
        }
    }
}
