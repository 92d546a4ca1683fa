//! The engagement of a ball or bull-nose end by height (docs/spec/engagement.md §11 item 5): the end's
//! section at height z above the tip is a circle of radius r(z), which meets the stock that the
//! sections of the same height have left along the path so far, so each height has its own
//! engaged arcs. The exact engine finds them for any radius.
//!
//! The corner (below min(a_p, r_c)) is integrated over z by the trapezoid rule: its edges start
//! [`CORNER_BANDS`] bands of equal height apart, and a band is halved, up to [`MAX_HALVINGS`]
//! times, while the rule's error over it (its share of the torque width times h²·|f''|/2, f(z)
//! the ∫ sin^a over the arcs at height z, f'' from divided differences) is more than
//! [`TOLERANCE`] of the whole: where a wall comes into reach or a scallop ends, not where the
//! engagement only changes smoothly. Each edge becomes a [`Section`] with its trapezoid weight,
//! its radius, its arcs and the helix lag z·tan λ/R of its one height; the straight flank above
//! the corner, whose section is the full circle, is one more, with the lag window over its
//! height (as a flat end's). Where nothing changes with height (a slot) the first edges agree
//! and the sums are exact; beside a wall they are within 0.1 % of a quadrature over z (tests).
//! The contact graph, a_e and H_k stay the full radius's.
//!
//! Cost: one engine call per section (about 9 to 20 a sample) and phase peaks over the
//! sections' breakpoints; without a helix or arc-feed factor the sections stack into one step
//! function of the tool angle ([`Stack`]), so a tooth's load over all of them is one lookup.

use super::arcfeed::ArcFeed;
use super::arcs::{Arc, wrap_deg};
use super::force::{END_TOLERANCE, ForceModel};
use crate::error::SolverError;

/// Bands the corner's height is first cut into.
pub(crate) const CORNER_BANDS: usize = 8;
/// Most halvings of a first band.
pub(crate) const MAX_HALVINGS: u32 = 6;
/// A band is halved while the trapezoid's estimated error over it exceeds this fraction of the
/// sum over all bands.
pub(crate) const TOLERANCE: f64 = 1e-3;
/// Most sections evaluated at one sample.
pub(crate) const MAX_SECTIONS: usize = 64;
/// The smallest section radius taken at a ball's tip, as a fraction of R (its limit there).
const TIP_RADIUS: f64 = 1e-3;

/// One section of the end at one sample: its share of the end's chip widths, where on the edge
/// it sits (its helix lag) and what it engages.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Section {
    /// Radius of the section, mm.
    pub radius: f64,
    /// Its part of [`ForceModel::force_width`], as a fraction of it.
    pub force_share: f64,
    /// Its part of [`ForceModel::torque_width`], as a fraction of it.
    pub torque_share: f64,
    /// Helix lag of the edge at its bottom and top, degrees (equal: one height).
    pub lag: (f64, f64),
    /// Its engaged arcs.
    pub arcs: Vec<Arc>,
    /// The arc-feed factor at its radius (on arcs of the path, with the correction).
    pub feed: Option<ArcFeed>,
}

/// All sections of the end at one sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Bands {
    pub sections: Vec<Section>,
    /// The sections' shares stacked over the tool angle, when none has a helix lag or an
    /// arc-feed factor.
    stack: Option<Stack>,
}

impl Bands {
    /// The sections with their stacked shares when none has a helix lag or an arc-feed factor.
    pub(crate) fn new(sections: Vec<Section>) -> Self {
        let plain = sections.iter().all(|section| section.lag == (0.0, 0.0) && section.feed.is_none());
        let stack = plain.then(|| Stack::new(&sections));
        Self { sections, stack }
    }

    /// Nothing engaged at any height.
    pub(crate) fn empty(&self) -> bool {
        self.sections.iter().all(|section| section.arcs.is_empty())
    }

    /// The stacked shares, when the sections' loads differ only in their weights.
    pub(crate) fn stack(&self) -> Option<&Stack> {
        self.stack.as_ref()
    }
}

/// Σ over the sections of share·[θ on the section's arcs], a step function of the tool angle:
/// with no helix and no arc-feed factor a tooth's load over all sections is W(θ)·sin^a θ, one
/// lookup instead of a sum over the sections.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Stack {
    /// Where pieces start, in [−180°, 180°) ascending, with the torque and force shares of all
    /// pieces that start there or before.
    starts: Vec<(f64, f64, f64)>,
    /// Where pieces end, likewise.
    ends: Vec<(f64, f64, f64)>,
}

impl Stack {
    fn new(sections: &[Section]) -> Self {
        // (from, to, (torque share, force share)), closed, within [−180°, 180°].
        let mut pieces = Vec::new();
        for section in sections {
            let shares = (section.torque_share, section.force_share);
            for arc in &section.arcs {
                // Closed arcs with the ends' tolerance, as `Arc::contains`.
                let (from, to) = (arc.from - END_TOLERANCE, arc.to + END_TOLERANCE);
                if to - from >= 360.0 {
                    pieces.push((-180.0, 180.0, shares));
                    continue;
                }
                let start = wrap_deg(from);
                let end = start + (to - from);
                if end < 180.0 {
                    pieces.push((start, end, shares));
                } else {
                    pieces.push((start, 180.0, shares));
                    pieces.push((-180.0, end - 360.0, shares));
                }
            }
        }
        let summed = |mut list: Vec<(f64, (f64, f64))>| {
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (mut torque, mut force) = (0.0, 0.0);
            list.into_iter()
                .map(|(angle, (t, f))| {
                    torque += t;
                    force += f;
                    (angle, torque, force)
                })
                .collect::<Vec<_>>()
        };
        Self {
            starts: summed(pieces.iter().map(|p| (p.0, p.2)).collect()),
            ends: summed(pieces.iter().map(|p| (p.1, p.2)).collect()),
        }
    }

    /// The torque and force shares of the sections engaged at `theta` (degrees, any turn).
    pub(crate) fn weight(&self, theta: f64) -> (f64, f64) {
        let theta = wrap_deg(theta);
        let started = self.starts.partition_point(|p| p.0 <= theta);
        let ended = self.ends.partition_point(|p| p.0 < theta);
        let upto = |list: &[(f64, f64, f64)], count: usize| {
            count.checked_sub(1).and_then(|last| list.get(last)).map_or((0.0, 0.0), |p| (p.1, p.2))
        };
        let (a, b) = (upto(&self.starts, started), upto(&self.ends, ended));
        ((a.0 - b.0).max(0.0), (a.1 - b.1).max(0.0))
    }

    /// The angles where the weight steps.
    pub(crate) fn steps(&self) -> impl Iterator<Item = f64> + '_ {
        self.starts.iter().chain(&self.ends).map(|p| p.0)
    }
}

/// max(0, sin θ)^a tabulated every [`LOAD_STEP`] degrees over [0°, 180°] for the sections'
/// single-height loads, interpolated linearly (within 3e-7 of the load; within 5° of 0° and
/// 180°, where sin^a bends sharply, it is computed): a section's tooth costs a lookup instead of
/// a power.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Loads {
    exponent: f64,
    values: Vec<f64>,
}

/// Spacing of [`Loads`], degrees.
const LOAD_STEP: f64 = 0.01;
/// Within this of 0° and 180° the load is computed, not interpolated, degrees.
const LOAD_EDGE: f64 = 5.0;

impl Loads {
    pub(crate) fn new(exponent: f64) -> Self {
        let count = (180.0 / LOAD_STEP).round() as usize;
        let values = (0..=count).map(|i| (i as f64 * LOAD_STEP).to_radians().sin().max(0.0).powf(exponent)).collect();
        Self { exponent, values }
    }

    /// max(0, sin θ)^a, θ in degrees (any turn).
    pub(crate) fn power(&self, theta: f64) -> f64 {
        let theta = super::arcs::modulo(theta, 360.0);
        if theta >= 180.0 {
            return 0.0;
        }
        if !(LOAD_EDGE..=180.0 - LOAD_EDGE).contains(&theta) {
            return theta.to_radians().sin().max(0.0).powf(self.exponent);
        }
        let position = theta / LOAD_STEP;
        let index = (position as usize).min(self.values.len() - 2);
        let t = position - index as f64;
        self.values[index] + t * (self.values[index + 1] - self.values[index])
    }
}

/// A corner height whose section has been evaluated.
struct Edge {
    z: f64,
    arcs: Vec<Arc>,
    /// ∫ sin^a over its arcs.
    measure: f64,
    /// The end's (force, torque) widths from the tip up to `z`.
    widths: (f64, f64),
}

impl ForceModel {
    /// Whether the end is rounded and cuts: its engagement is then taken by height.
    pub(crate) fn rounded(&self) -> bool {
        self.corner_radius > 0.0 && self.axial_depth > 0.0 && self.torque_width > 0.0 && self.force_width > 0.0
    }

    /// Radius of the section at height `z` of the corner (a ball's tip: [`TIP_RADIUS`]·R).
    fn section_radius(&self, z: f64) -> f64 {
        let below = self.corner_radius - z.clamp(0.0, self.corner_radius);
        let radius = self.radius - self.corner_radius + (self.corner_radius.powi(2) - below * below).max(0.0).sqrt();
        radius.max(TIP_RADIUS * self.radius)
    }

    /// Helix lag of the edge at height `z`, degrees.
    fn lag_at(&self, z: f64) -> f64 {
        (z * self.helix_tan / self.radius).to_degrees()
    }

    /// The sections of a rounded end at one sample: `full` are the full radius's arcs there,
    /// `engaged(r)` finds a section's arcs, `feed(r)` its arc-feed factor. `None` for a flat end.
    ///
    /// # Errors
    /// What `engaged` fails with.
    pub(crate) fn bands(
        &self,
        full: &[Arc],
        mut engaged: impl FnMut(f64) -> Result<Vec<Arc>, SolverError>,
        feed: impl Fn(f64) -> Option<ArcFeed>,
    ) -> Result<Option<Bands>, SolverError> {
        if !self.rounded() {
            return Ok(None);
        }
        let top = self.axial_depth.min(self.corner_radius);
        let mut edge = |z: f64| -> Result<Edge, SolverError> {
            let radius = self.section_radius(z);
            let arcs = if radius >= self.radius { full.to_vec() } else { engaged(radius)? };
            let widths = Self::end_widths(&self.table, &self.table_next, self.radius, self.corner_radius, z);
            Ok(Edge { z, measure: self.engaged_integral(&arcs, None), arcs, widths })
        };
        let mut edges = Vec::with_capacity(MAX_SECTIONS);
        for index in 0..=CORNER_BANDS {
            edges.push(edge(top * index as f64 / CORNER_BANDS as f64)?);
        }
        for _ in 0..MAX_HALVINGS {
            let halve = self.to_halve(&edges);
            if halve.is_empty() {
                break;
            }
            let mut middles = Vec::with_capacity(halve.len());
            for &index in &halve {
                middles.push(edge(0.5 * (edges[index].z + edges[index + 1].z))?);
            }
            let mut middles = halve.into_iter().zip(middles).peekable();
            let mut refined = Vec::with_capacity(edges.len() + middles.len());
            for (index, current) in edges.into_iter().enumerate() {
                refined.push(current);
                if let Some((_, middle)) = middles.next_if(|(band, _)| *band == index) {
                    refined.push(middle);
                }
            }
            edges = refined;
        }
        Ok(Some(Bands::new(self.sections(edges, full, feed))))
    }

    /// The bands among `edges` to halve (their lower edges' indices, rising): those whose
    /// trapezoid error exceeds the tolerance, the largest first as far as [`MAX_SECTIONS`]
    /// leaves room; none when all are within it.
    fn to_halve(&self, edges: &[Edge]) -> Vec<usize> {
        // Each band's share of the torque width, and the trapezoid's error over it from the
        // curvature of f(z) = ∫ sin^a over the arcs at z: share·h²·|f''|/12 where f is smooth,
        // f'' from the divided differences at its edges; taken 6 times larger, since at a
        // kink (where a wall comes into reach: f = 0 below, √ above) the rule misses up to
        // share·h²·|f''|/2.
        let band = |pair: &[Edge]| (pair[1].widths.1 - pair[0].widths.1) / self.torque_width;
        let total: f64 = edges.windows(2).map(|pair| band(pair) * 0.5 * (pair[0].measure + pair[1].measure)).sum();
        let limit = TOLERANCE * total.max(1e-9);
        let bent: Vec<f64> = edges
            .windows(3)
            .map(|three| {
                let slope = |a: &Edge, b: &Edge| (b.measure - a.measure) / (b.z - a.z);
                2.0 * (slope(&three[1], &three[2]) - slope(&three[0], &three[1])).abs() / (three[2].z - three[0].z)
            })
            .collect();
        // At edge i (1 ≤ i ≤ len − 2) the curvature is bent[i − 1]; the outer edges take
        // their neighbour's.
        let curvature = |index: usize| bent[index.clamp(1, bent.len()) - 1];
        let mut split: Vec<(f64, usize)> = edges
            .windows(2)
            .enumerate()
            .map(|(index, pair)| {
                let height = pair[1].z - pair[0].z;
                let bend = curvature(index).max(curvature(index + 1));
                (band(pair) * height * height * bend / 2.0, index)
            })
            .filter(|(error, _)| *error > limit)
            .collect();
        let room = MAX_SECTIONS.saturating_sub(edges.len());
        if split.is_empty() || room == 0 {
            return Vec::new();
        }
        // The largest changes first, as many as there is room for.
        split.sort_by(|a, b| b.0.total_cmp(&a.0));
        split.truncate(room);
        let mut halve: Vec<usize> = split.into_iter().map(|(_, index)| index).collect();
        halve.sort_unstable();
        halve
    }

    /// The sections of the end from its refined edges: each edge with half of each neighbouring
    /// band's widths (the trapezoid rule), and above the corner the straight flank at the full
    /// radius's arcs.
    fn sections(&self, mut edges: Vec<Edge>, full: &[Arc], feed: impl Fn(f64) -> Option<ArcFeed>) -> Vec<Section> {
        let (force_width, torque_width) = (self.force_width, self.torque_width);
        let mut sections = Vec::with_capacity(edges.len() + 1);
        for index in 0..edges.len() {
            let below = index.checked_sub(1).and_then(|i| edges.get(i)).map(|e| e.widths);
            let above = edges.get(index + 1).map(|e| e.widths);
            let here = edges[index].widths;
            // Trapezoid: half of each neighbouring band.
            let half = |pick: fn((f64, f64)) -> f64| {
                0.5 * (below.map_or(0.0, |b| pick(here) - pick(b)) + above.map_or(0.0, |a| pick(a) - pick(here)))
            };
            let z = edges[index].z;
            let radius = self.section_radius(z);
            sections.push(Section {
                radius,
                force_share: half(|w| w.0) / force_width,
                torque_share: half(|w| w.1) / torque_width,
                lag: (self.lag_at(z), self.lag_at(z)),
                arcs: std::mem::take(&mut edges[index].arcs),
                feed: feed(radius),
            });
        }
        if self.axial_depth > self.corner_radius {
            let corner = edges.last().map_or((0.0, 0.0), |e| e.widths);
            sections.push(Section {
                radius: self.radius,
                force_share: (force_width - corner.0) / force_width,
                torque_share: (torque_width - corner.1) / torque_width,
                lag: (self.lag_at(self.corner_radius), self.lag_at(self.axial_depth)),
                arcs: full.to_vec(),
                feed: feed(self.radius),
            });
        }
        sections
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tabulated_loads_are_the_power_of_the_sine() {
        for exponent in [0.6, 0.75, 1.0] {
            let loads = Loads::new(exponent);
            for step in 0..=36_000 {
                let theta = -180.0 + 0.0137 * f64::from(step);
                let exact = theta.to_radians().sin().max(0.0).powf(exponent);
                assert!((loads.power(theta) - exact).abs() <= 3e-7 * exact, "{exponent} {theta}");
            }
        }
    }

    #[test]
    fn stacked_shares_follow_the_closed_arcs() {
        let sections = [
            Section {
                torque_share: 0.25,
                force_share: 0.5,
                arcs: vec![Arc { from: 0.0, to: 180.0 }],
                ..Section::default()
            },
            Section {
                torque_share: 0.75,
                force_share: 0.5,
                arcs: vec![Arc { from: 90.0, to: 200.0 }],
                ..Section::default()
            },
        ];
        let stack = Stack::new(&sections);
        assert_eq!(stack.weight(-10.0), (0.0, 0.0));
        assert_eq!(stack.weight(0.0), (0.25, 0.5));
        assert_eq!(stack.weight(45.0), (0.25, 0.5));
        assert_eq!(stack.weight(90.0), (1.0, 1.0));
        assert_eq!(stack.weight(180.0), (1.0, 1.0));
        // 190° is −170°: only the second arc, across ±180°.
        assert_eq!(stack.weight(190.0), (0.75, 0.5));
        assert_eq!(stack.weight(-165.0), (0.75, 0.5));
        assert_eq!(stack.weight(-150.0), (0.0, 0.0));
        // Every angle the sections' own test accepts, and no other.
        for step in 0..3600 {
            let theta = -180.0 + f64::from(step) * 0.1;
            let expected = sections
                .iter()
                .filter(|s| s.arcs.iter().any(|a| a.contains(theta, END_TOLERANCE)))
                .fold((0.0, 0.0), |(t, f), s| (t + s.torque_share, f + s.force_share));
            let got = stack.weight(theta);
            assert!((got.0 - expected.0).abs() < 1e-12 && (got.1 - expected.1).abs() < 1e-12, "{theta}: {got:?}");
        }
    }
}
