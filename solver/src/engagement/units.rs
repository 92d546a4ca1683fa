//! The engagement request and answer in inches (docs/spec/api.md, Units): every length and feed
//! each type holds, listed field by field. Lengths: coordinates, radii, depths, the sample
//! spacing, chip thicknesses and feeds per tooth; feeds per minute. Unchanged: angles, times,
//! spindle speeds, counts, torques (N·m), powers (kW), forces (N), frequencies, and the Kienzle
//! values (k_c1.1 in N/mm² at a chip of 1 mm, as material tables give them). A G-code path keeps
//! its own G20/G21 (G21 when it has neither). The removal rate (`mrr`, `max_mrr`) is a volume
//! per minute: mm³/min or inch³/min.

use super::answer::{FeedBlock, FeedPlan, FluteLimit, FluteResult, ForceInfo, GridInfo, OverLimit, PathEngagement};
use super::request::{
    Candidate, FeedPlanRequest, PathInput, PathSegments, PreviousCut, SegmentInput, Stock, StockBitmap, StockPolygon,
};
use super::{EngagementAnswer, EngagementRequest, EngagementSample, EngagementSolution};
use crate::units::{Scale, Scaling};

/// A volume (mm³ or mm³/min): scaled by the cube of the length's conversion.
fn scale_volume(volume: &mut Option<f64>, scaling: Scaling) {
    if let Some(volume) = volume {
        *volume = scaling.apply(scaling.apply(scaling.apply(*volume)));
    }
}

impl Scale for EngagementRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            tool,
            stock,
            path,
            paths,
            spindle_rpm: _,
            plunge_feed,
            feed_per_tooth,
            feed,
            flute_counts: _,
            thickness_limit,
            time_limit_s: _,
            representative: _,
            spindle_direction: _,
            engine: _,
            step,
            grid,
            burr_disengage_deg: _,
            chipping_disengage_deg: _,
            radial_depth_min,
            radial_depth_max,
            spike_threshold_deg: _,
            min_feed_per_tooth,
            axial_depth,
            stock_top_z,
            cut_z,
            clearance,
            feed_plan,
            contact_dots: _,
            block_time_ms: _,
            machine: _,
            candidate: _,
            arc_feed_correction: _,
            kienzle: _,
            material: _,
            units: _,
            verification,
        } = self;
        verification.scale(scaling);
        tool.scale(scaling);
        stock.scale(scaling);
        path.scale(scaling);
        paths.scale(scaling);
        for value in [
            plunge_feed,
            feed_per_tooth,
            feed,
            thickness_limit,
            step,
            grid,
            radial_depth_min,
            radial_depth_max,
            min_feed_per_tooth,
            axial_depth,
            stock_top_z,
            cut_z,
            clearance,
        ] {
            value.scale(scaling);
        }
        feed_plan.scale(scaling);
    }
}

impl Scale for Stock {
    fn scale(&mut self, scaling: Scaling) {
        let Self { polygon, holes, polygons, bitmap, previous_cuts } = self;
        polygon.scale(scaling);
        holes.scale(scaling);
        polygons.scale(scaling);
        bitmap.scale(scaling);
        previous_cuts.scale(scaling);
    }
}

impl Scale for StockPolygon {
    fn scale(&mut self, scaling: Scaling) {
        let Self { name: _, outer, holes } = self;
        outer.scale(scaling);
        holes.scale(scaling);
    }
}

impl Scale for StockBitmap {
    fn scale(&mut self, scaling: Scaling) {
        let Self { origin, cell, width: _, height: _, data: _ } = self;
        origin.scale(scaling);
        cell.scale(scaling);
    }
}

impl Scale for PreviousCut {
    fn scale(&mut self, scaling: Scaling) {
        let Self { path, radius } = self;
        path.scale(scaling);
        radius.scale(scaling);
    }
}

impl Scale for Candidate {
    fn scale(&mut self, scaling: Scaling) {
        let Self { name: _, path, axial_depth, cut_z } = self;
        path.scale(scaling);
        axial_depth.scale(scaling);
        cut_z.scale(scaling);
    }
}

/// Points and segments are scaled; G-code text is read in its own G20/G21.
impl Scale for PathInput {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Points(points) => points.scale(scaling),
            Self::Segments(PathSegments { start, segments, gcode: _ }) => {
                start.scale(scaling);
                segments.scale(scaling);
            }
        }
    }
}

impl Scale for SegmentInput {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Line { to, rapid: _ } => to.scale(scaling),
            Self::Arc { to, center, dir: _ } => {
                to.scale(scaling);
                center.scale(scaling);
            }
        }
    }
}

/// The target thickness, the feed cap and the shortest block (not the relative tolerance).
impl Scale for FeedPlanRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self { target_thickness, max_feed, flute_count: _, basis: _, tolerance: _, min_block_length } = self;
        target_thickness.scale(scaling);
        max_feed.scale(scaling);
        min_block_length.scale(scaling);
    }
}

/// The echoed tool, machine and stock, the thickness limit, the cycle time's dynamics and every
/// path's result; the material's Kienzle values are not lengths.
impl Scale for EngagementAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            tool,
            machine,
            material: _,
            stock,
            thickness_limit,
            time_limit_s: _,
            cycle_time,
            result,
            verification,
        } = self;
        verification.scale(scaling);
        tool.scale(scaling);
        machine.scale(scaling);
        stock.scale(scaling);
        thickness_limit.scale(scaling);
        cycle_time.scale(scaling);
        result.scale(scaling);
    }
}

impl Scale for EngagementSolution {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Single(result) => result.scale(scaling),
            Self::Comparison(comparison) => comparison.candidates.scale(scaling),
        }
    }
}

/// A path's results; what its program needs (`post`) stays in mm, as the program is written
/// from the answer before the answer is converted.
impl Scale for PathEngagement {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            name: _,
            samples,
            flutes,
            recommended: _,
            path_length,
            feed_length,
            time_flute_count: _,
            program_flute_count: _,
            engine: _,
            step,
            grid,
            engaged_intervals,
            max_engaged_deg: _,
            max_engaged_at_s,
            max_radial_depth,
            max_mrr,
            contact_dots,
            forces,
            feed_plan,
            blocks,
            warnings,
            post: _,
        } = self;
        warnings.scale(scaling);
        samples.scale(scaling);
        flutes.scale(scaling);
        for value in [path_length, feed_length, step, max_engaged_at_s, max_radial_depth] {
            value.scale(scaling);
        }
        grid.scale(scaling);
        engaged_intervals.scale(scaling);
        scale_volume(max_mrr, scaling);
        // Each dot is [s, θ_deg]: only s is a length.
        for dot in contact_dots.iter_mut().flatten() {
            dot[0].scale(scaling);
        }
        forces.scale(scaling);
        feed_plan.scale(scaling);
        blocks.scale(scaling);
    }
}

impl Scale for EngagementSample {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            s,
            t: _,
            position,
            heading_deg: _,
            segment: _,
            arcs: _,
            engaged_deg: _,
            radial_depth,
            arc_details: _,
            mean_chip_thickness,
            thickness,
            teeth: _,
            torque_nm: _,
            peak_torque_nm: _,
            power_kw: _,
            peak_force_n: _,
            mrr,
            flags: _,
        } = self;
        for value in [s, radial_depth, mean_chip_thickness] {
            value.scale(scaling);
        }
        position.scale(scaling);
        for value in thickness.iter_mut() {
            value.scale(scaling);
        }
        scale_volume(mrr, scaling);
    }
}

impl Scale for FluteResult {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            flute_count: _,
            feed_per_tooth,
            feed,
            max_thickness,
            mean_thickness,
            min_thickness,
            median_thickness,
            time_s: _,
            recommended: _,
            thickness_margin,
            time_margin_s: _,
            over_limits,
            max_teeth: _,
            multi_tooth_intervals,
            mean_torque_nm: _,
            peak_torque_nm: _,
            mean_power_kw: _,
            peak_power_kw: _,
            peak_force_n: _,
            tooth_passing_hz: _,
        } = self;
        for value in [feed_per_tooth, feed, max_thickness, mean_thickness, min_thickness, median_thickness] {
            value.scale(scaling);
        }
        thickness_margin.scale(scaling);
        over_limits.scale(scaling);
        multi_tooth_intervals.scale(scaling);
    }
}

/// The chip thickness and machine feed limits are a length and a feed; the others are not.
impl Scale for OverLimit {
    fn scale(&mut self, scaling: Scaling) {
        let Self { limit, value, allowed } = self;
        match limit {
            FluteLimit::Thickness | FluteLimit::MachineFeed => {
                value.scale(scaling);
                allowed.scale(scaling);
            }
            FluteLimit::Time | FluteLimit::SpindleTorque | FluteLimit::SpindlePower | FluteLimit::SpindleSpeed => {}
        }
    }
}

impl Scale for GridInfo {
    fn scale(&mut self, scaling: Scaling) {
        let Self { cell, origin, width: _, height: _, bytes: _ } = self;
        cell.scale(scaling);
        origin.scale(scaling);
    }
}

/// The axial depth; the Kienzle exponent, ratios, angles, powers and frequencies are not lengths.
impl Scale for ForceInfo {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            kc11: _,
            mc: _,
            axial_depth,
            radial_ratio: _,
            helix_lag_deg: _,
            height_sections: _,
            spindle_power_kw: _,
            spindle_torque_nm: _,
            natural_frequencies_hz: _,
        } = self;
        axial_depth.scale(scaling);
    }
}

impl Scale for FeedPlan {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            flute_count: _,
            target_thickness,
            basis: _,
            max_feed,
            blocks,
            time_s: _,
            nominal_time_s: _,
            feed_range,
        } = self;
        target_thickness.scale(scaling);
        max_feed.scale(scaling);
        blocks.scale(scaling);
        feed_range.scale(scaling);
    }
}

impl Scale for FeedBlock {
    fn scale(&mut self, scaling: Scaling) {
        let Self { segment: _, from_s, to_s, feed, limited_by: _ } = self;
        from_s.scale(scaling);
        to_s.scale(scaling);
        feed.scale(scaling);
    }
}
