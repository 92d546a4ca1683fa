//! The deburr request and answer in inches (docs/spec/api.md, Units): every length and feed each
//! type holds, listed field by field. Lengths: the workpiece's origin and sizes, the holes' sizes,
//! eccentricities, axis points and positions, the pattern's pitch, Q and W, the tolerance, the
//! clearances and lead distance, every point of the loops and leads and the travels; the feed per
//! minute. Unchanged: angles, the parameter along a segment, times, spindle speeds and counts.

use super::Deburr;
use super::answer::{DeburrPoint, DeburrSummary, LeadMove};
use super::capability::{DeburrAnswer, HoleAnswer, VisitingOrder};
use super::request::{CentreDistance, DeburrRequest, Hole, HolePattern, PlacedHole, Workpiece};
use crate::units::{Scale, Scaling};

impl Scale for DeburrRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            tool,
            workpiece,
            hole,
            holes,
            pattern,
            edge: _,
            inner_tool,
            cut_amount,
            width,
            tolerance,
            method: _,
            start_deg: _,
            direction: _,
            feed,
            spindle_rpm: _,
            clearance,
            lead_distance,
            safe_z,
            machine: _,
            block_time_ms: _,
            units: _,
            verification,
        } = self;
        verification.scale(scaling);
        tool.scale(scaling);
        inner_tool.scale(scaling);
        workpiece.scale(scaling);
        hole.scale(scaling);
        holes.scale(scaling);
        pattern.scale(scaling);
        for value in [cut_amount, width, tolerance, feed, clearance, lead_distance, safe_z] {
            value.scale(scaling);
        }
    }
}

impl Scale for Workpiece {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Tube {
                origin,
                arrangement_angle_deg: _,
                inner_radius,
                inner_diameter,
                outer_radius,
                outer_diameter,
            } => {
                origin.scale(scaling);
                for value in [inner_radius, inner_diameter, outer_radius, outer_diameter] {
                    value.scale(scaling);
                }
            }
            Self::BoreBlock { origin, arrangement_angle_deg: _, bore_radius, face_distance } => {
                origin.scale(scaling);
                bore_radius.scale(scaling);
                face_distance.scale(scaling);
            }
        }
    }
}

impl Scale for CentreDistance {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Along(distance) => distance.scale(scaling),
            Self::AcrossAlong(distances) => distances.scale(scaling),
        }
    }
}

impl Scale for Hole {
    fn scale(&mut self, scaling: Scaling) {
        let Self { shape: _, radius, diameter, centre_distance, eccentricity, penetration_angle_deg: _, axis_point } =
            self;
        for value in [radius, diameter, eccentricity] {
            value.scale(scaling);
        }
        centre_distance.scale(scaling);
        axis_point.scale(scaling);
    }
}

impl Scale for PlacedHole {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            shape: _,
            radius,
            diameter,
            centre_distance,
            eccentricity,
            penetration_angle_deg: _,
            arrangement_angle_deg: _,
            axial_position,
        } = self;
        for value in [radius, diameter, eccentricity, axial_position] {
            value.scale(scaling);
        }
        centre_distance.scale(scaling);
    }
}

impl Scale for HolePattern {
    fn scale(&mut self, scaling: Scaling) {
        let Self { around_deg: _, pitch, count: _ } = self;
        pitch.scale(scaling);
    }
}

/// The echoed tools and machine, the cycle time's dynamics, every loop, the travels and the
/// verification of the program.
impl Scale for DeburrAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self { tool, inner_tool, machine, cycle_time, holes, visiting_order, result, verification } = self;
        verification.scale(scaling);
        tool.scale(scaling);
        inner_tool.scale(scaling);
        machine.scale(scaling);
        cycle_time.scale(scaling);
        holes.scale(scaling);
        visiting_order.scale(scaling);
        result.scale(scaling);
    }
}

impl Scale for HoleAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            field: _,
            index: _,
            tool_field: _,
            turned: _,
            penetration_angle_deg: _,
            arrangement_angle_deg: _,
            axial_position,
            result,
        } = self;
        axial_position.scale(scaling);
        result.scale(scaling);
    }
}

impl Scale for VisitingOrder {
    fn scale(&mut self, scaling: Scaling) {
        let Self { loops: _, travel, request_order_travel, tool_changes: _, turns: _ } = self;
        travel.scale(scaling);
        request_order_travel.scale(scaling);
    }
}

/// A loop's points, leads and summary; what its program needs (the ball radius, the header and
/// the blocker's message) stays in mm, as the program is written before the answer is converted.
impl Scale for Deburr {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            edge: _,
            method: _,
            points,
            lead_in,
            lead_out,
            summary,
            warnings,
            program_blocker: _,
            description: _,
            ball_radius: _,
        } = self;
        warnings.scale(scaling);
        points.scale(scaling);
        lead_in.scale(scaling);
        lead_out.scale(scaling);
        summary.scale(scaling);
    }
}

impl Scale for DeburrPoint {
    fn scale(&mut self, scaling: Scaling) {
        let Self { target, centre, tip, wedge_angle_deg: _, segment: _, parameter: _, phi_deg: _, centre_offset } =
            self;
        target.scale(scaling);
        centre.scale(scaling);
        tip.scale(scaling);
        centre_offset.scale(scaling);
    }
}

impl Scale for LeadMove {
    fn scale(&mut self, scaling: Scaling) {
        let Self { motion: _, centre, tip } = self;
        centre.scale(scaling);
        tip.scale(scaling);
    }
}

impl Scale for DeburrSummary {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            count: _,
            path_length,
            max_deviation,
            tolerance,
            cut_amount,
            width,
            true_width_min,
            true_width_max,
            swept_width_min,
            swept_width_max,
            wedge_angle_min_deg: _,
            wedge_angle_max_deg: _,
            max_exact_offset,
            feed,
            spindle_rpm: _,
            safe_centre_z,
            estimated_time_s: _,
            block_time_ms: _,
            block_length,
            blocks: _,
            min_block_length,
            short_blocks: _,
        } = self;
        for value in [
            path_length,
            max_deviation,
            tolerance,
            cut_amount,
            width,
            true_width_min,
            true_width_max,
            swept_width_min,
            swept_width_max,
            feed,
        ] {
            value.scale(scaling);
        }
        for value in [max_exact_offset, safe_centre_z, block_length, min_block_length] {
            value.scale(scaling);
        }
    }
}
