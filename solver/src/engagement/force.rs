//! Spindle torque and power along the path from Kienzle's law (docs/spec/engagement.md §11 items 4 and 5):
//! per tooth F_t = k_c1.1·a_p·h^(1−m_c), torque M = R·ΣF_t, power P = 2πNM/60, with the helix
//! lag 2a_p·tan λ/D spreading each tooth's cut over that angle.
//!
//! At one sample the torque depends on the tooth phase β. Its mean over β is closed:
//! M̄ = R·k_c1.1·a_p·f_z^a·(k/2π)·∫_E max(0, sin θ)^a dθ (a = 1 − m_c; the helix does not change
//! it, it only averages the torque over a window of β). Its peak over β is found numerically:
//! between breakpoints (a tooth, or the top of its helical edge, on an arc end or at 0°/180°)
//! the torque is smooth, and without a helix a sum of concave terms ([`phase::peak`]). On a
//! curved path with the arc-feed correction (§11 item 6) the chip is f_z·c(θ)·sin θ, so the
//! terms carry c(θ)^(1−m_c).
//!
//! Ball and bull-nose ends (§11 item 5): on the rounded end the edge at height z meets the
//! material at the angle κ from the tool axis, so its chip is h = f_z·sin θ·sin κ, its width
//! dz/sin κ and its lever arm r(z). A tooth's tangential force and torque are then the flat
//! model's with a_p replaced by [`ForceModel::force_width`] = ∫ sin^(−m_c)κ dz and R·a_p by
//! [`ForceModel::torque_width`] = ∫ r(z)·sin^(−m_c)κ dz, integrated in κ along the corner arc
//! (z = r_c(1 − cos κ)) with the same sin^a tables; a flat end gives a_p and R·a_p.
//!
//! The engagement itself differs by height on a rounded end (each section meets the stock its
//! height has left): [`super::heights`] finds it per section, and every force, torque and power
//! here is then the share-weighted sum over the sections ([`Bands`]).

use super::arcfeed::ArcFeed;
use super::arcs::{Arc, SpindleDirection};
use super::heights::{Bands, Loads, Section, Stack};
use super::kienzle::SinPower;
use super::phase;

/// Tooth on an arc end counts as inside, degrees (closed arcs, as in `teeth`).
pub(crate) const END_TOLERANCE: f64 = 1e-9;
/// Longest piece of an arc over which the arc-feed factor is taken as constant, degrees: the
/// factor is smooth, so the error is about (1°)²/24 of its curvature, below 1e-5.
const FACTOR_PIECE_DEG: f64 = 1.0;

/// A validated force model for one request.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ForceModel {
    pub kc11: f64,
    pub mc: f64,
    /// a_p, mm.
    pub axial_depth: f64,
    /// ∫₀^a_p sin^(−m_c)κ dz, mm: the chip width a tooth's force scales with (a_p for a flat end).
    pub force_width: f64,
    /// ∫₀^a_p r(z)·sin^(−m_c)κ dz, mm²: the width times lever arm its torque scales with (R·a_p
    /// for a flat end).
    pub torque_width: f64,
    /// Λ = 2a_p·tan λ/D, degrees (0 without a helix).
    pub lag_deg: f64,
    /// R, mm.
    pub radius: f64,
    /// r_c of the end, mm: 0 flat, R ball; a rounded end's engagement is taken by height
    /// ([`super::heights`]).
    pub corner_radius: f64,
    /// tan λ of the helix (0 without one).
    pub helix_tan: f64,
    /// The tooth load tabulated for a rounded end's sections.
    pub loads: Option<Box<Loads>>,
    pub direction: SpindleDirection,
    /// F_r/F_t.
    pub radial_ratio: f64,
    /// ∫ sin^a.
    pub table: SinPower,
    /// ∫ sin^(a+1), for the force's components (sin^a·sin θ).
    pub table_next: SinPower,
}

/// Torque at one sample for one flute count, N·m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SampleTorque {
    /// Mean over the tooth phase.
    pub mean: f64,
    /// Largest over the tooth phase.
    pub peak: f64,
}

impl ForceModel {
    /// ∫ over [from, to] (degrees) of (c(θ)·max(0, sin θ))^a dθ, θ in radians.
    fn between(&self, from: f64, to: f64, feed: Option<&ArcFeed>) -> f64 {
        let Some(feed) = feed else {
            return self.table.between(from.to_radians(), to.to_radians());
        };
        let pieces = ((to - from) / FACTOR_PIECE_DEG).ceil().max(1.0);
        let width = (to - from) / pieces;
        (0..pieces as usize)
            .map(|i| {
                let low = from + width * i as f64;
                let factor = feed.factor(low + 0.5 * width).powf(self.table.exponent());
                factor * self.table.between(low.to_radians(), (low + width).to_radians())
            })
            .sum()
    }

    /// ∫ over the arcs of (c(θ)·max(0, sin θ))^a dθ (θ in radians): the phase-mean term.
    pub(crate) fn engaged_integral(&self, arcs: &[Arc], feed: Option<&ArcFeed>) -> f64 {
        arcs.iter().map(|arc| self.between(arc.from, arc.to, feed)).sum()
    }

    /// N·m of torque per unit of the sin^a term for a feed per tooth `fz`:
    /// k_c1.1·∫r(z)·sin^(−m_c)κ dz·f_z^a / 1000 (R·k_c1.1·a_p·f_z^a / 1000 for a flat end).
    fn scale(&self, fz: f64) -> f64 {
        self.torque_width * self.kc11 * fz.powf(self.table.exponent()) / 1000.0
    }

    /// The chip widths of a tool with corner radius `corner_radius` (0 flat, R ball) and radius
    /// `radius` cut `axial_depth` deep: (force width, torque width), see the module's notes.
    pub(crate) fn end_widths(
        table: &SinPower,
        table_next: &SinPower,
        radius: f64,
        corner_radius: f64,
        axial_depth: f64,
    ) -> (f64, f64) {
        let on_corner = axial_depth.min(corner_radius);
        let straight = axial_depth - on_corner;
        if on_corner <= 0.0 {
            return (straight, radius * straight);
        }
        // z = r_c(1 − cos κ), dz = r_c·sin κ dκ, r = R − r_c + r_c·sin κ:
        // ∫ sin^(−m_c)κ dz = r_c·∫ sin^a κ dκ, ∫ r·sin^(−m_c)κ dz = (R − r_c)·r_c·∫ sin^a + r_c²·∫ sin^(a+1).
        let top = (1.0 - on_corner / corner_radius).clamp(-1.0, 1.0).acos();
        let (power, next) = (table.between(0.0, top), table_next.between(0.0, top));
        let force_width = corner_radius * power + straight;
        let torque_width =
            (radius - corner_radius) * corner_radius * power + corner_radius * corner_radius * next + radius * straight;
        (force_width, torque_width)
    }

    /// The phase-mean term of one sample: [`Self::engaged_integral`] of the full radius's arcs,
    /// or with a rounded end's sections (`bands`) their torque-share-weighted
    /// sum, so that [`Self::mean_torque`] and [`Self::feed_for_torque`] apply unchanged.
    pub(crate) fn integral(&self, arcs: &[Arc], feed: Option<&ArcFeed>, bands: Option<&Bands>) -> f64 {
        match bands {
            Some(bands) => bands
                .sections
                .iter()
                .map(|section| section.torque_share * self.engaged_integral(&section.arcs, section.feed.as_ref()))
                .sum(),
            None => self.engaged_integral(arcs, feed),
        }
    }

    /// Mean torque over the tooth phase from the engaged integral, N·m.
    pub(crate) fn mean_torque(&self, integral: f64, flutes: u32, fz: f64) -> f64 {
        self.scale(fz) * f64::from(flutes) * integral / std::f64::consts::TAU
    }

    /// Feed per tooth at which the phase-mean torque equals `torque` (N·m); infinite without
    /// engagement.
    pub(crate) fn feed_for_torque(&self, torque: f64, integral: f64, flutes: u32) -> f64 {
        let unit = self.mean_torque(integral, flutes, 1.0);
        if unit <= 0.0 { f64::INFINITY } else { (torque / unit).powf(1.0 / self.table.exponent()) }
    }

    /// Mean and peak torque over the tooth phase, N·m; with a rounded end's sections (`bands`)
    /// summed over them.
    pub(crate) fn torque(
        &self,
        arcs: &[Arc],
        feed: Option<&ArcFeed>,
        bands: Option<&Bands>,
        integral: f64,
        flutes: u32,
        fz: f64,
    ) -> SampleTorque {
        let empty = bands.map_or(arcs.is_empty(), Bands::empty);
        if empty {
            return SampleTorque { mean: 0.0, peak: 0.0 };
        }
        let mean = self.mean_torque(integral, flutes, fz);
        let peak = self.scale(fz)
            * match bands {
                Some(bands) => match bands.stack() {
                    Some(stack) => self.stacked_peak(stack, flutes, false),
                    None => self.sliced_peak(
                        &bands.sections,
                        flutes,
                        |section| section.torque_share,
                        |section, tip| self.section_tooth(section, tip),
                    ),
                },
                None => self.peak_sum(arcs, flutes, feed),
            };
        // The peak of a function is never below its mean; the numeric search may miss by 1e-12.
        SampleTorque { mean, peak: peak.max(mean) }
    }

    /// One tooth's sin^a term with its tip at `tip` (degrees): the value on the arcs, or with a
    /// helix the mean over the lag window behind the tip.
    pub(crate) fn tooth(&self, arcs: &[Arc], tip: f64, feed: Option<&ArcFeed>) -> f64 {
        if self.lag_deg <= 0.0 {
            return self.edge_point(arcs, tip, feed).unwrap_or(0.0);
        }
        // The edge above the tip trails it: cw teeth run towards smaller θ, so the trailing
        // edge sits at larger θ; ccw the other way.
        let (low, high) = match self.direction {
            SpindleDirection::Cw => (tip, tip + self.lag_deg),
            SpindleDirection::Ccw => (tip - self.lag_deg, tip),
        };
        let mut total = 0.0;
        in_window(arcs, low, high, |a, b| total += self.between(a, b, feed));
        total / self.lag_deg.to_radians()
    }

    /// The largest and smallest max(0, sin θ)^a over θ in [`from`, `to`] (degrees): sin^a
    /// rises to 90° and falls after it, so both are at the ends or a crest (1) or a trough (0).
    fn power_range(&self, from: f64, to: f64) -> (f64, f64) {
        let power = |theta: f64| match &self.loads {
            Some(loads) => loads.power(theta),
            None => self.table.integrand(theta.to_radians()),
        };
        let (a, b) = (power(from), power(to));
        let crest = 90.0 + 360.0 * ((from - 90.0) / 360.0).ceil();
        let trough = 270.0 + 360.0 * ((from - 270.0) / 360.0).ceil();
        // Off [0°, 180°] the load is 0: a range that leaves it reaches 0.
        let zero = 180.0 + 360.0 * ((from - 180.0) / 360.0).ceil();
        let largest = if crest <= to { 1.0 } else { a.max(b) };
        let smallest = if trough <= to || zero < to { 0.0 } else { a.min(b) };
        (largest, smallest)
    }

    /// One tooth's load term on a section: at one height from the tabulated load, else as
    /// [`Self::tooth_in`].
    fn section_tooth(&self, section: &Section, tip: f64) -> f64 {
        let (Some(loads), None, true) = (&self.loads, section.feed, section.lag.1 <= section.lag.0) else {
            return self.tooth_in(&section.arcs, tip, section.feed.as_ref(), section.lag);
        };
        let at = self.window(tip, (section.lag.0, section.lag.0)).0;
        if section.arcs.iter().any(|a| a.contains(at, END_TOLERANCE)) { loads.power(at) } else { 0.0 }
    }

    /// One tooth's force on a section: at one height from the tabulated load, else as
    /// [`Self::tooth_force_in`].
    fn section_force(&self, section: &Section, tip: f64) -> (f64, f64) {
        let (Some(loads), None, true) = (&self.loads, section.feed, section.lag.1 <= section.lag.0) else {
            return self.tooth_force_in(&section.arcs, tip, section.feed.as_ref(), section.lag);
        };
        let at = self.window(tip, (section.lag.0, section.lag.0)).0;
        if !section.arcs.iter().any(|a| a.contains(at, END_TOLERANCE)) {
            return (0.0, 0.0);
        }
        let w = loads.power(at);
        let (s, c) = at.to_radians().sin_cos();
        let turning = match self.direction {
            SpindleDirection::Cw => 1.0,
            SpindleDirection::Ccw => -1.0,
        };
        (-turning * w * s - self.radial_ratio * w * c, turning * w * c - self.radial_ratio * w * s)
    }

    /// The edge's tool angles, degrees, where its lag behind the tip runs over `lag` (from, to):
    /// the edge above the tip trails it, and cw teeth run towards smaller θ, so the trailing edge
    /// sits at larger θ; ccw the other way.
    fn window(&self, tip: f64, lag: (f64, f64)) -> (f64, f64) {
        match self.direction {
            SpindleDirection::Cw => (tip + lag.0, tip + lag.1),
            SpindleDirection::Ccw => (tip - lag.1, tip - lag.0),
        }
    }

    /// [`Self::tooth`] for the part of the edge whose lag runs over `lag` (a section of a
    /// rounded end; the flat end keeps its own copy, the hot path of the bench): the mean over
    /// that window, or the value at its one angle when it has no width.
    fn tooth_in(&self, arcs: &[Arc], tip: f64, feed: Option<&ArcFeed>, lag: (f64, f64)) -> f64 {
        let width = lag.1 - lag.0;
        if width <= 0.0 {
            return self.edge_point(arcs, self.window(tip, (lag.0, lag.0)).0, feed).unwrap_or(0.0);
        }
        let (low, high) = self.window(tip, lag);
        let mut total = 0.0;
        in_window(arcs, low, high, |a, b| total += self.between(a, b, feed));
        total / width.to_radians()
    }

    /// ∫ over [from, to] (degrees) of w(θ)·(sin θ, cos θ) dθ with w = (c(θ)·max(0, sin θ))^a:
    /// the pieces of one tooth's force along and across the travel.
    fn moments(&self, from: f64, to: f64, feed: Option<&ArcFeed>) -> (f64, f64) {
        let a = self.table.exponent();
        // ∫ sin^a·cos = sin^(a+1)/(a+1) where sin ≥ 0; the back half carries no chip.
        let cos_moment = |low: f64, high: f64| {
            let mut total = 0.0;
            let first = (low / 360.0).floor() as i64;
            let last = (high / 360.0).floor() as i64;
            for turn in first..=last {
                let base = 360.0 * turn as f64;
                let (x, y) = (low.max(base), high.min(base + 180.0));
                if y > x {
                    let power = |t: f64| t.to_radians().sin().max(0.0).powf(a + 1.0);
                    total += (power(y) - power(x)) / (a + 1.0);
                }
            }
            total
        };
        let Some(feed) = feed else {
            return (self.table_next.between(from.to_radians(), to.to_radians()), cos_moment(from, to));
        };
        let pieces = ((to - from) / FACTOR_PIECE_DEG).ceil().max(1.0);
        let width = (to - from) / pieces;
        (0..pieces as usize).fold((0.0, 0.0), |(sin_sum, cos_sum), i| {
            let low = from + width * i as f64;
            let factor = feed.factor(low + 0.5 * width).powf(a);
            (
                sin_sum + factor * self.table_next.between(low.to_radians(), (low + width).to_radians()),
                cos_sum + factor * cos_moment(low, low + width),
            )
        })
    }

    /// One tooth's force on the tool per k_c1.1·a_p·f_z^a, in the tool frame (along the right
    /// normal r̂, along the travel t̂): the tangential part opposes the edge's motion, the radial
    /// part pushes the tool away from the material.
    pub(crate) fn tooth_force(&self, arcs: &[Arc], tip: f64, feed: Option<&ArcFeed>) -> (f64, f64) {
        if self.lag_deg <= 0.0 {
            return self.edge_point_force(arcs, tip, feed);
        }
        let (low, high) = match self.direction {
            SpindleDirection::Cw => (tip, tip + self.lag_deg),
            SpindleDirection::Ccw => (tip - self.lag_deg, tip),
        };
        let (sin_part, cos_part) = self.window_moments(arcs, low, high, feed);
        let lag = self.lag_deg.to_radians();
        self.tool_frame(sin_part / lag, cos_part / lag)
    }

    /// [`Self::tooth_force`] for the part of the edge whose lag runs over `lag` (see
    /// [`Self::tooth_in`]).
    fn tooth_force_in(&self, arcs: &[Arc], tip: f64, feed: Option<&ArcFeed>, lag: (f64, f64)) -> (f64, f64) {
        let width = lag.1 - lag.0;
        if width <= 0.0 {
            return self.edge_point_force(arcs, self.window(tip, (lag.0, lag.0)).0, feed);
        }
        let (low, high) = self.window(tip, lag);
        let (sin_part, cos_part) = self.window_moments(arcs, low, high, feed);
        let width = width.to_radians();
        self.tool_frame(sin_part / width, cos_part / width)
    }

    /// The sin^a term of an edge without helix lag whose one point is at `at`; `None` outside
    /// the arcs.
    fn edge_point(&self, arcs: &[Arc], at: f64, feed: Option<&ArcFeed>) -> Option<f64> {
        arcs.iter().any(|arc| arc.contains(at, END_TOLERANCE)).then(|| {
            let factor = feed.map_or(1.0, |f| f.factor(at).powf(self.table.exponent()));
            factor * self.table.integrand(at.to_radians())
        })
    }

    /// The force of an edge without helix lag whose one point is at `at`: zero outside the arcs.
    fn edge_point_force(&self, arcs: &[Arc], at: f64, feed: Option<&ArcFeed>) -> (f64, f64) {
        let Some(w) = self.edge_point(arcs, at, feed) else { return (0.0, 0.0) };
        let (s, c) = at.to_radians().sin_cos();
        self.tool_frame(w * s, w * c)
    }

    /// The sine and cosine moments of the engaged arcs (every turn of them) inside the edge's
    /// window [low, high], degrees.
    fn window_moments(&self, arcs: &[Arc], low: f64, high: f64, feed: Option<&ArcFeed>) -> (f64, f64) {
        let (mut sin_part, mut cos_part) = (0.0, 0.0);
        in_window(arcs, low, high, |x, y| {
            let (s, c) = self.moments(x, y, feed);
            sin_part += s;
            cos_part += c;
        });
        (sin_part, cos_part)
    }

    /// Moments w·sin θ and w·cos θ into the tool frame: w·[turning·(−sin θ, cos θ) +
    /// ratio·(−cos θ, −sin θ)], where cw teeth run towards smaller θ (velocity −de/dθ), ccw
    /// towards larger.
    fn tool_frame(&self, sin_part: f64, cos_part: f64) -> (f64, f64) {
        let turning = match self.direction {
            SpindleDirection::Cw => 1.0,
            SpindleDirection::Ccw => -1.0,
        };
        (-turning * sin_part - self.radial_ratio * cos_part, turning * cos_part - self.radial_ratio * sin_part)
    }

    /// Largest resultant force on the tool over the tooth phase, N; with a rounded end's
    /// sections (`bands`) the resultant of all their forces.
    pub(crate) fn peak_force(
        &self,
        arcs: &[Arc],
        flutes: u32,
        fz: f64,
        feed: Option<&ArcFeed>,
        bands: Option<&Bands>,
    ) -> f64 {
        if let Some(bands) = bands {
            if bands.empty() {
                return 0.0;
            }
            let scale = self.kc11 * self.force_width * fz.powf(self.table.exponent());
            if let Some(stack) = bands.stack() {
                return scale * self.stacked_peak(stack, flutes, true);
            }
            let sections = &bands.sections[..];
            let pitch = 360.0 / f64::from(flutes);
            let resultant = |phase: f64| {
                let (mut x, mut y) = (0.0, 0.0);
                for section in sections {
                    if section.arcs.is_empty() {
                        continue;
                    }
                    for j in 0..flutes {
                        let tip = phase + f64::from(j) * pitch;
                        let (fx, fy) = self.section_force(section, tip);
                        x += section.force_share * fx;
                        y += section.force_share * fy;
                    }
                }
                x.hypot(y)
            };
            // Over the piece the resultant moves from its middle value by at most the sum of its
            // terms' moves: each tooth's load times √(1 + (F_r/F_t)²) moves by its change and
            // turns with the tooth.
            let magnitude = self.radial_ratio.hypot(1.0);
            let bound = |low: f64, high: f64| {
                let turn = (0.5 * (high - low)).to_radians();
                let mut total = resultant(0.5 * (low + high));
                for section in sections {
                    for j in 0..flutes {
                        let shift = f64::from(j) * pitch;
                        let (largest, change) = self.section_change(section, low + shift, high + shift, true);
                        total += magnitude * section.force_share * (change + largest * turn);
                    }
                }
                total
            };
            return scale * phase::peak_bounded(flutes, &self.sliced_ends(sections), resultant, bound);
        }
        if arcs.is_empty() {
            return 0.0;
        }
        let pitch = 360.0 / f64::from(flutes);
        let resultant = |phase: f64| {
            let (x, y) = (0..flutes).fold((0.0, 0.0), |(x, y), j| {
                let (fx, fy) = self.tooth_force(arcs, phase + f64::from(j) * pitch, feed);
                (x + fx, y + fy)
            });
            x.hypot(y)
        };
        let scale = self.kc11 * self.force_width * fz.powf(self.table.exponent());
        scale * phase::peak_of(flutes, &self.ends(arcs), resultant)
    }

    /// Tooth angles where a tooth's load jumps or bends.
    fn ends(&self, arcs: &[Arc]) -> Vec<f64> {
        let mut ends: Vec<f64> = arcs.iter().flat_map(|a| [a.from, a.to]).chain([0.0, 180.0]).collect();
        if self.lag_deg > 0.0 {
            // The top of the edge crossing the same places.
            let shift = match self.direction {
                SpindleDirection::Cw => -self.lag_deg,
                SpindleDirection::Ccw => self.lag_deg,
            };
            ends.extend(ends.clone().iter().map(|e| e + shift));
        }
        ends
    }

    /// max over the phase β of Σ_j tooth(β + j·360°/k).
    pub(crate) fn peak_sum(&self, arcs: &[Arc], flutes: u32, feed: Option<&ArcFeed>) -> f64 {
        phase::peak(flutes, &self.ends(arcs), |tip| self.tooth(arcs, tip, feed))
    }

    /// The phase peak over the sections from their stacked shares (no helix, no arc-feed factor):
    /// of the torque term Σ_j W(θ_j)·sin^a θ_j, or with `force` of the resultant's |Σ_j W(θ_j)·
    /// sin^a θ_j·(tangential + radial direction)| per k_c1.1·force width·f_z^a. Between two
    /// breakpoints every tooth stays on one step of W, which bounds each piece.
    fn stacked_peak(&self, stack: &Stack, flutes: u32, force: bool) -> f64 {
        let pitch = 360.0 / f64::from(flutes);
        let turning = match self.direction {
            SpindleDirection::Cw => 1.0,
            SpindleDirection::Ccw => -1.0,
        };
        let share = |theta: f64| {
            let (torque, force_share) = stack.weight(theta);
            if force { force_share } else { torque }
        };
        let sum = |phase: f64| {
            let (mut total, mut x, mut y) = (0.0, 0.0, 0.0);
            for j in 0..flutes {
                let tip = phase + f64::from(j) * pitch;
                let load = share(tip);
                if load <= 0.0 {
                    continue;
                }
                let w =
                    load * self.loads.as_ref().map_or_else(|| self.table.integrand(tip.to_radians()), |l| l.power(tip));
                if force {
                    let (s, c) = tip.to_radians().sin_cos();
                    x += -turning * w * s - self.radial_ratio * w * c;
                    y += turning * w * c - self.radial_ratio * w * s;
                } else {
                    total += w;
                }
            }
            if force { x.hypot(y) } else { total }
        };
        // Over the piece every tooth keeps its share; its term moves from the middle value by its
        // change of sin^a and, for the force, turns with the tooth.
        let magnitude = if force { self.radial_ratio.hypot(1.0) } else { 1.0 };
        let bound = |low: f64, high: f64| {
            let middle = 0.5 * (low + high);
            let turn = if force { (0.5 * (high - low)).to_radians() } else { 0.0 };
            let mut total = sum(middle);
            for j in 0..flutes {
                let shift = f64::from(j) * pitch;
                let load = share(middle + shift);
                if load > 0.0 {
                    let (largest, smallest) = self.power_range(low + shift, high + shift);
                    total += magnitude * load * (largest - smallest + largest * turn);
                }
            }
            total
        };
        let ends: Vec<f64> = stack.steps().chain([0.0, 180.0]).collect();
        phase::peak_bounded(flutes, &ends, sum, bound)
    }

    /// Tooth angles where a section's load jumps or bends: its arcs' ends and 0°/180°, where the
    /// bottom and the top of its stretch of the edge cross them.
    fn sliced_ends(&self, sections: &[Section]) -> Vec<f64> {
        let mut ends = Vec::new();
        for section in sections {
            if section.arcs.is_empty() {
                continue;
            }
            let places = section.arcs.iter().flat_map(|a| [a.from, a.to]).chain([0.0, 180.0]);
            for place in places {
                for lag in [section.lag.0, section.lag.1] {
                    ends.push(match self.direction {
                        SpindleDirection::Cw => place - lag,
                        SpindleDirection::Ccw => place + lag,
                    });
                }
            }
        }
        ends
    }

    /// max over the phase β of Σ_j Σ_sections share(section)·load(section, β + j·360°/k),
    /// found between the sections' breakpoints with [`phase::peak_bounded`] (pieces whose bound
    /// cannot beat the best found are skipped).
    fn sliced_peak(
        &self,
        sections: &[Section],
        flutes: u32,
        share: impl Fn(&Section) -> f64,
        load: impl Fn(&Section, f64) -> f64,
    ) -> f64 {
        let pitch = 360.0 / f64::from(flutes);
        let sum = |phase: f64| {
            let mut total = 0.0;
            for section in sections {
                if section.arcs.is_empty() {
                    continue;
                }
                let weight = share(section);
                for j in 0..flutes {
                    total += weight * load(section, phase + f64::from(j) * pitch);
                }
            }
            total
        };
        // Over the piece the sum moves from its middle value by at most its terms' changes.
        let bound = |low: f64, high: f64| {
            let mut total = sum(0.5 * (low + high));
            for section in sections {
                let weight = share(section);
                for j in 0..flutes {
                    let shift = f64::from(j) * pitch;
                    total += weight * self.section_change(section, low + shift, high + shift, false).1;
                }
            }
            total
        };
        phase::peak_bounded(flutes, &self.sliced_ends(sections), sum, bound)
    }

    /// For tips in [`low`, `high`] (degrees, one piece between breakpoints): the largest value
    /// of a section's load term G = (c·max(0, sin θ))^a on the angles its window covers (0 off
    /// its arcs), and how far its tooth load (G at one angle, or its mean over the lag window)
    /// can move from its value at the piece's middle: G's largest less its smallest value there,
    /// or for a window of width w by shifting it h/2, G_max·h/(2w) (its force vector, two
    /// slivers: G_max·h/w; `force`).
    fn section_change(&self, section: &Section, low: f64, high: f64, force: bool) -> (f64, f64) {
        let (from, _) = self.window(low, section.lag);
        let (_, to) = self.window(high, section.lag);
        let (mut largest, mut smallest): (f64, f64) = (0.0, 0.0);
        for arc in &section.arcs {
            let (start, end) = (arc.from - END_TOLERANCE, arc.to + END_TOLERANCE);
            let first = ((from - end) / 360.0).floor() as i64;
            let last = ((to - start) / 360.0).ceil() as i64;
            for turn in first..=last {
                let shift = 360.0 * turn as f64;
                let (x, y) = ((start + shift).max(from), (end + shift).min(to));
                if y >= x {
                    let (high, low) = self.power_range(x, y);
                    largest = largest.max(high);
                    if start + shift <= from && to <= end + shift {
                        // The whole range on this arc: G is never below its least value there.
                        smallest = low;
                    }
                }
            }
        }
        if largest <= 0.0 {
            return (0.0, 0.0);
        }
        let a = self.table.exponent();
        // c(θ) lies between |1 − R/r_path| and 1 + R/r_path.
        let (most, least) =
            section.feed.map_or((1.0, 1.0), |feed| (feed.largest_factor().powf(a), feed.smallest_factor().powf(a)));
        let (largest, smallest) = (most * largest, least * smallest);
        let width = section.lag.1 - section.lag.0;
        let change = if width > 0.0 {
            let step = (high - low) / width;
            if force { largest * step.min(2.0) } else { largest * (0.5 * step).min(1.0) }
        } else {
            largest - smallest
        };
        (largest, change)
    }
}

/// Calls `piece(from, to)` for every part of the arcs, each turn of them, inside the window
/// [low, high], degrees.
fn in_window(arcs: &[Arc], low: f64, high: f64, mut piece: impl FnMut(f64, f64)) {
    for arc in arcs {
        // Copies of the arc, one turn apart, that overlap the window.
        let first = ((low - arc.to) / 360.0).floor() as i64;
        let last = ((high - arc.from) / 360.0).ceil() as i64;
        for turn in first..=last {
            let shift = 360.0 * turn as f64;
            let (from, to) = ((arc.from + shift).max(low), (arc.to + shift).min(high));
            if to > from {
                piece(from, to);
            }
        }
    }
}

/// Spindle power for a torque, kW: P = 2πN·M/60.
pub(crate) fn power_kw(torque_nm: f64, spindle_rpm: f64) -> f64 {
    std::f64::consts::TAU * spindle_rpm * torque_nm / 60.0 / 1000.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engagement::heights::Section;

    fn model(mc: f64, lag_deg: f64, direction: SpindleDirection) -> ForceModel {
        ForceModel {
            kc11: 1800.0,
            mc,
            axial_depth: 2.0,
            force_width: 2.0,
            torque_width: 10.0,
            lag_deg,
            radius: 5.0,
            corner_radius: 0.0,
            helix_tan: 0.0,
            loads: None,
            direction,
            radial_ratio: 0.3,
            table: SinPower::new(1.0 - mc),
            table_next: SinPower::new(2.0 - mc),
        }
    }

    fn arc(from: f64, to: f64) -> Arc {
        Arc { from, to }
    }

    fn sum(model: &ForceModel, arcs: &[Arc], flutes: u32, phase: f64) -> f64 {
        let pitch = 360.0 / f64::from(flutes);
        (0..flutes).map(|j| model.tooth(arcs, phase + f64::from(j) * pitch, None)).sum()
    }

    /// Brute-force phase scan.
    fn scanned(model: &ForceModel, arcs: &[Arc], flutes: u32) -> f64 {
        let pitch = 360.0 / f64::from(flutes);
        (0..=100_000).map(|i| sum(model, arcs, flutes, pitch * f64::from(i) / 100_000.0)).fold(0.0, f64::max)
    }

    #[test]
    fn peak_matches_a_fine_scan() {
        let cases = [vec![arc(0.0, 180.0)], vec![arc(0.0, 60.0)], vec![arc(16.0, 23.0), arc(157.0, 164.0)]];
        for lag in [0.0, 25.0] {
            let m = model(0.25, lag, SpindleDirection::Cw);
            for arcs in &cases {
                for k in [1, 2, 3, 4, 7] {
                    let exact = m.peak_sum(arcs, k, None);
                    let scan = scanned(&m, arcs, k);
                    assert!(exact >= scan - 1e-9, "lag {lag} {arcs:?} k {k}: {exact} < {scan}");
                    // The scan's step of 0.0036° misses a peak on a jump by up to 3e-5 of it.
                    assert!(exact - scan < 1e-4 * scan.max(1e-9), "lag {lag} {arcs:?} k {k}: {exact} vs {scan}");
                }
            }
        }
    }

    #[test]
    fn helix_lag_delays_the_exit_by_the_lag_angle() {
        // A cw tooth runs from 120° down to 30° on the arc: its tip cuts over [30°, 120°]; with a
        // lag of 20° its top leaves 20° later, at tip angle 10°, and enters 20° after the tip.
        let lag = 20.0;
        let arcs = [arc(30.0, 120.0)];
        let flat = model(0.25, 0.0, SpindleDirection::Cw);
        let helix = model(0.25, lag, SpindleDirection::Cw);
        assert_eq!(helix.tooth(&arcs, 120.0 + 1e-6, None), 0.0);
        assert!(helix.tooth(&arcs, 120.0 - 1e-3, None) > 0.0);
        assert!(helix.tooth(&arcs, 30.0 - lag + 1e-3, None) > 0.0);
        assert_eq!(helix.tooth(&arcs, 30.0 - lag - 1e-6, None), 0.0);
        assert_eq!(flat.tooth(&arcs, 30.0 - 1e-6, None), 0.0);
        // Fully in the cut (tip from 100° down to 30°) the helical tooth is the window mean.
        let tip: f64 = 60.0;
        let mean = flat.table.between(tip.to_radians(), (tip + lag).to_radians()) / lag.to_radians();
        assert!((helix.tooth(&arcs, tip, None) - mean).abs() < 1e-12);
        // ccw teeth trail on the other side.
        let ccw = model(0.25, lag, SpindleDirection::Ccw);
        assert!(ccw.tooth(&arcs, 120.0 + lag - 1e-3, None) > 0.0);
        assert_eq!(ccw.tooth(&arcs, 120.0 + lag + 1e-6, None), 0.0);
        assert_eq!(ccw.tooth(&arcs, 30.0 - 1e-6, None), 0.0);
    }

    #[test]
    fn helix_keeps_the_mean_and_lowers_the_peak() {
        let arcs = [arc(0.0, 60.0)];
        let flat = model(0.2, 0.0, SpindleDirection::Cw);
        for lag in [10.0, 45.0, 400.0] {
            let helix = model(0.2, lag, SpindleDirection::Cw);
            for k in [1, 2, 4] {
                // Mean over the phase by a fine scan equals the closed form for both.
                let pitch = 360.0 / f64::from(k);
                let n = 20_000;
                let scan_mean: f64 =
                    (0..n).map(|i| sum(&helix, &arcs, k, pitch * (f64::from(i) + 0.5) / f64::from(n))).sum::<f64>()
                        / f64::from(n);
                let closed = f64::from(k) * flat.engaged_integral(&arcs, None) / std::f64::consts::TAU;
                assert!((scan_mean - closed).abs() < 1e-4 * closed, "lag {lag} k {k}: {scan_mean} vs {closed}");
                assert!(helix.peak_sum(&arcs, k, None) <= flat.peak_sum(&arcs, k, None) + 1e-12);
            }
        }
    }

    #[test]
    fn helical_tooth_force_is_the_window_mean_of_the_straight_one() {
        let arcs = [arc(10.0, 150.0)];
        for direction in [SpindleDirection::Cw, SpindleDirection::Ccw] {
            let flat = model(0.25, 0.0, direction);
            let helix = model(0.25, 30.0, direction);
            for tip in [-20.0, 0.0, 45.0, 100.0, 140.0, 170.0] {
                let (low, high) = match direction {
                    SpindleDirection::Cw => (tip, tip + 30.0),
                    SpindleDirection::Ccw => (tip - 30.0, tip),
                };
                let n = 30_000;
                let (mut x, mut y) = (0.0, 0.0);
                for i in 0..n {
                    let (fx, fy) =
                        flat.tooth_force(&arcs, low + (high - low) * (f64::from(i) + 0.5) / f64::from(n), None);
                    x += fx / f64::from(n);
                    y += fy / f64::from(n);
                }
                let (hx, hy) = helix.tooth_force(&arcs, tip, None);
                assert!(
                    (hx - x).abs() < 1e-5 && (hy - y).abs() < 1e-5,
                    "{direction:?} {tip}: ({hx}, {hy}) vs ({x}, {y})"
                );
            }
        }
    }

    /// Sections with arcs, shares, lags (none, single heights, a window) and arc-feed factors.
    fn sections(lags: &[(f64, f64)], feed: Option<ArcFeed>) -> Bands {
        let arcs = [
            vec![arc(0.0, 60.0)],
            vec![arc(10.0, 120.0)],
            vec![arc(20.0, 40.0), arc(150.0, 170.0)],
            vec![arc(0.0, 180.0)],
        ];
        let shares = [(0.1, 0.15), (0.2, 0.25), (0.3, 0.2), (0.4, 0.4)];
        Bands::new(
            arcs.iter()
                .zip(shares)
                .zip(lags)
                .map(|((arcs, (torque_share, force_share)), lag)| Section {
                    radius: 1.0,
                    torque_share,
                    force_share,
                    lag: *lag,
                    arcs: arcs.clone(),
                    feed,
                })
                .collect(),
        )
    }

    #[test]
    fn the_sections_peaks_match_a_fine_scan() {
        let plain = [(0.0, 0.0); 4];
        let helix = [(0.0, 0.0), (4.0, 4.0), (8.0, 8.0), (12.0, 30.0)];
        for direction in [SpindleDirection::Cw, SpindleDirection::Ccw] {
            let mut m = model(0.25, 0.0, direction);
            m.loads = Some(Box::new(Loads::new(0.75)));
            for (lags, feed) in [
                (&plain, None),
                (&helix, None),
                (&plain, Some(ArcFeed::new(0.3, 1.0))),
                (&helix, Some(ArcFeed::new(0.5, -1.0))),
            ] {
                let bands = sections(lags, feed);
                assert_eq!(bands.stack().is_some(), lags == &plain && feed.is_none());
                for k in [1, 2, 3, 5] {
                    let pitch = 360.0 / f64::from(k);
                    let torque_at = |phase: f64| {
                        let mut total = 0.0;
                        for section in &bands.sections {
                            for j in 0..k {
                                let tip = phase + f64::from(j) * pitch;
                                total += section.torque_share
                                    * m.tooth_in(&section.arcs, tip, section.feed.as_ref(), section.lag);
                            }
                        }
                        total
                    };
                    let force_at = |phase: f64| {
                        let (mut x, mut y) = (0.0, 0.0);
                        for section in &bands.sections {
                            for j in 0..k {
                                let tip = phase + f64::from(j) * pitch;
                                let (fx, fy) = m.tooth_force_in(&section.arcs, tip, section.feed.as_ref(), section.lag);
                                x += section.force_share * fx;
                                y += section.force_share * fy;
                            }
                        }
                        x.hypot(y)
                    };
                    let n = 100_000;
                    let scan = |f: &dyn Fn(f64) -> f64| {
                        (0..=n).map(|i| f(pitch * f64::from(i) / f64::from(n))).fold(0.0, f64::max)
                    };
                    let unit = m.scale(1.0);
                    let torque = m.torque(&[], None, Some(&bands), 0.0, k, 1.0).peak / unit;
                    let force = m.peak_force(&[], k, 1.0, None, Some(&bands)) / (m.kc11 * m.force_width);
                    let label = format!("{direction:?} lags {lags:?} feed {feed:?} k {k}");
                    for (what, exact, scanned) in
                        [("torque", torque, scan(&torque_at)), ("force", force, scan(&force_at))]
                    {
                        // The tabulated load is within 3e-7 of the power.
                        assert!(exact >= scanned * (1.0 - 1e-6), "{label} {what}: {exact} < scan {scanned}");
                        assert!(exact - scanned < 2e-4 * scanned, "{label} {what}: {exact} vs scan {scanned}");
                    }
                }
            }
        }
    }

    #[test]
    fn power_is_two_pi_n_m_over_sixty() {
        assert!((power_kw(10.0, 6000.0) - std::f64::consts::TAU * 100.0 * 10.0 / 1000.0).abs() < 1e-12);
    }
}
