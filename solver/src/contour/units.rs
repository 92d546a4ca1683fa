//! Lengths and feeds of contour requests and answers, for the request's units (docs/spec/api.md, units).

use crate::units::{Scale, Scaling, scale_area};

/// A contour request's lengths and feeds: the outline, depths, loop sizes, allowances, feeds,
/// clearances, tolerance and the inline tool (not angles, times or counts).
impl Scale for crate::contour::ContourRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            tool,
            contour,
            drawing,
            side: _,
            depths,
            corner_loop,
            feed,
            loop_feed,
            direction: _,
            fix_orientation: _,
            passes,
            inside_corner_relief: _,
            tbone_edge: _,
            corner_overrides: _,
            clearance,
            safe_z,
            lead,
            start_edge: _,
            tolerance,
            block_time_ms: _,
            machine: _,
            spindle_rpm: _,
            plunge_feed,
            ramp_angle_deg: _,
            stock_allowance,
            tilt_deg: _,
            controller,
            units: _,
            verification,
        } = self;
        verification.scale(scaling);
        tool.scale(scaling);
        contour.scale(scaling);
        if let Some(drawing) = drawing {
            drawing.scale(scaling);
        }
        let crate::contour::Depths { top, bottom, step } = depths;
        for value in [top, bottom, step] {
            value.scale(scaling);
        }
        let crate::contour::CornerLoop {
            style: _,
            radius,
            leg,
            min_leg,
            max_leg,
            min_radius,
            max_radius,
            max_angle_deg: _,
        } = corner_loop;
        for value in [radius, leg, min_leg, max_leg, min_radius, max_radius] {
            value.scale(scaling);
        }
        feed.scale(scaling);
        for value in [loop_feed, clearance, safe_z, lead, tolerance, plunge_feed, stock_allowance] {
            value.scale(scaling);
        }
        if let Some(passes) = passes {
            for crate::contour::PassSpec { allowance, loops: _, join: _ } in passes {
                allowance.scale(scaling);
            }
        }
        if let Some(crate::contour::ControllerModel { blend_radius, servo_time_constant_ms: _ }) = controller {
            blend_radius.scale(scaling);
        }
    }
}

/// A contour answer: the tool, the echoed machine and the solution.
impl Scale for crate::contour::ContourAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self { tool, machine, result, verification } = self;
        tool.scale(scaling);
        machine.scale(scaling);
        result.scale(scaling);
        verification.scale(scaling);
    }
}

impl Scale for crate::contour::ContourSolution {
    fn scale(&mut self, scaling: Scaling) {
        // The program is written from the answer in mm before it is converted: the fields kept
        // for it (`centre_height`, arc spans) are converted too, so the answer stays whole.
        self.layers.scale(scaling);
        self.corners.scale(scaling);
        self.passes.scale(scaling);
        self.summary.scale(scaling);
        self.centre_height.scale(scaling);
        self.warnings.scale(scaling);
    }
}

impl Scale for crate::contour::ContourLayer {
    fn scale(&mut self, scaling: Scaling) {
        self.z.scale(scaling);
        for step in &mut self.moves {
            let crate::contour::ContourMove { kind: _, to, feed, axis: _ } = step;
            to.scale(scaling);
            feed.scale(scaling);
        }
        for span in &mut self.arcs {
            span.start.scale(scaling);
            span.end.scale(scaling);
            span.centre.scale(scaling);
        }
    }
}

impl Scale for crate::contour::ContourCorner {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            index: _,
            vertex,
            angle_deg: _,
            turn_deg: _,
            convexity: _,
            looped: _,
            action: _,
            cl_point,
            corner_loop,
            relief,
            material,
            predicted,
        } = self;
        vertex.scale(scaling);
        cl_point.scale(scaling);
        if let Some(report) = corner_loop {
            let crate::contour::LoopReport {
                style: _,
                leg,
                radius,
                exit_end,
                entry_start,
                centre,
                far_corner,
                sweep_deg: _,
                length,
                clearance,
                at_loop_feed: _,
            } = report;
            for value in [leg, length, clearance] {
                value.scale(scaling);
            }
            radius.scale(scaling);
            exit_end.scale(scaling);
            entry_start.scale(scaling);
            centre.scale(scaling);
            far_corner.scale(scaling);
        }
        if let Some(crate::contour::ReliefReport { style: _, target, along_edge: _ }) = relief {
            target.scale(scaling);
        }
        material.scale(scaling);
        predicted.scale(scaling);
    }
}

/// Material left and cut away at a corner: depths are lengths, areas scale by the square.
impl Scale for crate::contour::MaterialReport {
    fn scale(&mut self, scaling: Scaling) {
        let Self { left_area, left_depth, overcut_area, overcut_depth } = self;
        scale_area(left_area, scaling);
        scale_area(overcut_area, scaling);
        left_depth.scale(scaling);
        overcut_depth.scale(scaling);
    }
}

impl Scale for crate::contour::PassReport {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            allowance,
            offset,
            loops: _,
            join: _,
            start,
            looped_corners: _,
            cut_length,
            leg_length,
            loop_length,
            relief_length,
            gouge_min_clearance,
            stock_min_clearance,
        } = self;
        for value in [allowance, offset, cut_length, leg_length, loop_length, relief_length] {
            value.scale(scaling);
        }
        start.scale(scaling);
        gouge_min_clearance.scale(scaling);
        stock_min_clearance.scale(scaling);
    }
}

impl Scale for crate::contour::ContourSummary {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            side: _,
            direction: _,
            tool_radius,
            corners: _,
            layers: _,
            passes: _,
            moves: _,
            feed_length,
            feed,
            loop_feed,
            spindle_rpm: _,
            safe_z,
            lead,
            tolerance,
            estimated_time_s: _,
            blocks,
            cycle_time,
        } = self;
        for value in [tool_radius, feed_length, feed, loop_feed, safe_z, lead, tolerance] {
            value.scale(scaling);
        }
        blocks.scale(scaling);
        cycle_time.scale(scaling);
    }
}
