//! Lengths and feeds of segment requests and answers, for the request's units (docs/spec/api.md, units).

use crate::units::{Scale, Scaling};

/// A segment request's lengths and feeds: the curve, the feeds, the chord errors and lengths of
/// its rules, the inline tool and the clearance plane (not its times, factors or angles).
impl Scale for crate::segment::SegmentRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            curve,
            feed,
            block_time_ms: _,
            mode: _,
            window,
            rule: _,
            min_radius,
            radius_estimate: _,
            margin: _,
            chord_error_factor: _,
            radius_factor: _,
            block_time_factor: _,
            allow_unsafe_margin: _,
            sagitta_approximation: _,
            min_chord_error,
            tolerance,
            compare_tolerance,
            machine: _,
            tool,
            spindle_rpm: _,
            plunge_feed,
            safe_z,
            units: _,
        } = self;
        curve.scale(scaling);
        for value in [feed, window, min_radius, min_chord_error, tolerance, compare_tolerance, plunge_feed, safe_z] {
            value.scale(scaling);
        }
        tool.scale(scaling);
    }
}

/// A curve's points, centres, radii and semi-axes (knots and weights are not lengths).
impl Scale for crate::segment::Curve {
    fn scale(&mut self, scaling: Scaling) {
        use crate::segment::Curve;
        match self {
            Curve::Circle { centre, radius, .. } | Curve::Arc { centre, radius, .. } => {
                centre.scale(scaling);
                radius.scale(scaling);
            }
            Curve::Ellipse { centre, semi_axes, .. } => {
                centre.scale(scaling);
                semi_axes.scale(scaling);
            }
            Curve::Polyline { points, .. } => points.scale(scaling),
            Curve::Bspline { control_points, .. } => control_points.scale(scaling),
            // The drawing's geometry is in the drawing's own units; its tolerances are the request's.
            Curve::Drawing { join_tolerance, chord_tolerance, .. } => {
                join_tolerance.scale(scaling);
                chord_tolerance.scale(scaling);
            }
        }
    }
}

/// A segment answer: the echoed machine and tool, the solution and the cycle time's dynamics.
impl Scale for crate::segment::SegmentAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self { machine, tool, result, cycle_time } = self;
        machine.scale(scaling);
        tool.scale(scaling);
        result.scale(scaling);
        cycle_time.scale(scaling);
    }
}

impl Scale for crate::segment::SegmentSolution {
    fn scale(&mut self, scaling: Scaling) {
        for value in [&mut self.chord_error, &mut self.min_window_chord_error, &mut self.max_deviation] {
            value.scale(scaling);
        }
        for value in [&mut self.curve_length, &mut self.feed, &mut self.min_chord_error, &mut self.safe_z] {
            value.scale(scaling);
        }
        for value in [&mut self.min_radius, &mut self.feed_limit, &mut self.tolerance_feed] {
            value.scale(scaling);
        }
        self.windows.scale(scaling);
        self.points.scale(scaling);
        self.s.scale(scaling);
        self.stats.scale(scaling);
        self.comparison.scale(scaling);
        self.warnings.scale(scaling);
    }
}

impl Scale for crate::segment::SegmentWindow {
    fn scale(&mut self, scaling: Scaling) {
        let Self { s_start, s_end, radius, chord_error, rule_chord_error, status: _, blocks: _ } = self;
        for value in [s_start, s_end, chord_error, rule_chord_error] {
            value.scale(scaling);
        }
        radius.scale(scaling);
    }
}

impl Scale for crate::segment::CommandPoint {
    fn scale(&mut self, scaling: Scaling) {
        let mut point = self.to_vec3();
        Scale::scale(&mut point, scaling);
        *self = Self::new(&point, self.dimension());
    }
}

impl Scale for crate::segment::Comparison {
    fn scale(&mut self, scaling: Scaling) {
        let Self { tolerance, max_deviation, stats } = self;
        tolerance.scale(scaling);
        max_deviation.scale(scaling);
        stats.scale(scaling);
    }
}
