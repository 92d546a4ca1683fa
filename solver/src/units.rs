//! The units a request is written in and its answer is given in (docs/spec/api.md, Units):
//! millimetres or inches for every length, mm/min or inch/min for every feed. The solvers compute
//! in millimetres only; a request in inches is converted once before it is solved and its answer
//! once after, each type listing its lengths and feeds in its [`Scale`] implementation. Angles,
//! times, spindle speeds, counts, forces and stiffnesses are not scaled.

use serde::{Deserialize, Serialize};

use crate::machine::MachineProfile;
use crate::machine::cycle::CycleTime;
use crate::machine::stats::BlockStats;
use crate::tool::{ShapeErrorPoint, Tool, ToolRef};

/// Millimetres in one inch, exactly.
pub const MM_PER_INCH: f64 = 25.4;

/// The units of lengths (and of feeds, per minute) in a request and its answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres, feeds in mm/min.
    #[default]
    Mm,
    /// Inches, feeds in inch/min; programs in G20 with 4 decimals (0.0001 in).
    Inch,
}

impl Units {
    /// The name used in JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Mm => "mm",
            Self::Inch => "inch",
        }
    }

    /// Millimetres in one of these units.
    pub fn mm_per_unit(self) -> f64 {
        match self {
            Self::Mm => 1.0,
            Self::Inch => MM_PER_INCH,
        }
    }

    /// The conversion of a request in these units into millimetres (`None` for millimetres).
    pub fn into_mm(self) -> Option<Scaling> {
        (self != Self::Mm).then_some(Scaling { mm_per_unit: self.mm_per_unit(), into_mm: true })
    }

    /// The conversion of an answer in millimetres into these units (`None` for millimetres).
    pub fn from_mm(self) -> Option<Scaling> {
        (self != Self::Mm).then_some(Scaling { mm_per_unit: self.mm_per_unit(), into_mm: false })
    }

    /// `value` in mm, given in these units (for messages that quote a request's value).
    pub fn of_mm(self, value_mm: f64) -> f64 {
        value_mm / self.mm_per_unit()
    }
}

/// One conversion of lengths: from the request's units into mm (multiplied by the millimetres
/// in a unit), or from mm into the answer's (divided by them, so 25.4 mm is exactly 1 inch).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    mm_per_unit: f64,
    into_mm: bool,
}

impl Scaling {
    /// `value` converted.
    #[must_use]
    pub fn apply(self, value: f64) -> f64 {
        if self.into_mm { value * self.mm_per_unit } else { value / self.mm_per_unit }
    }
}

/// A value whose lengths and feeds are converted by a [`Scaling`]: each implementation lists
/// every length and feed field of its type (and only those), so none is missed or scaled twice.
pub trait Scale {
    /// Converts every length and feed in place.
    fn scale(&mut self, scaling: Scaling);
}

impl Scale for f64 {
    fn scale(&mut self, scaling: Scaling) {
        *self = scaling.apply(*self);
    }
}

impl<T: Scale> Scale for Option<T> {
    fn scale(&mut self, scaling: Scaling) {
        if let Some(value) = self {
            value.scale(scaling);
        }
    }
}

impl<T: Scale> Scale for Vec<T> {
    fn scale(&mut self, scaling: Scaling) {
        for value in self {
            value.scale(scaling);
        }
    }
}

impl<T: Scale, const N: usize> Scale for [T; N] {
    fn scale(&mut self, scaling: Scaling) {
        for value in self {
            value.scale(scaling);
        }
    }
}

impl<T: Scale> Scale for Box<T> {
    fn scale(&mut self, scaling: Scaling) {
        (**self).scale(scaling);
    }
}

impl Scale for crate::geometry::Vec3 {
    fn scale(&mut self, scaling: Scaling) {
        self.x.scale(scaling);
        self.y.scale(scaling);
        self.z.scale(scaling);
    }
}

/// Lengths and feeds of a tool; `helix_deg`, `flutes` and the stiffness (N/mm) are not.
impl Scale for Tool {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            number: _,
            kind: _,
            radius,
            corner_radius,
            flutes: _,
            name: _,
            helix_deg: _,
            stickout,
            flute_length,
            plunge_feed,
            centre_cutting: _,
            neck_radius,
            neck_length,
            shank_radius,
            holder_diameter,
            holder_length,
            shape_error,
            stiffness: _,
        } = self;
        radius.scale(scaling);
        for value in [
            corner_radius,
            stickout,
            flute_length,
            plunge_feed,
            neck_radius,
            neck_length,
            shank_radius,
            holder_diameter,
            holder_length,
        ] {
            value.scale(scaling);
        }
        shape_error.scale(scaling);
    }
}

impl Scale for ShapeErrorPoint {
    fn scale(&mut self, scaling: Scaling) {
        self.error.scale(scaling);
    }
}

/// An inline tool is scaled; a tool-table number refers to a stored tool, which is in mm.
impl Scale for ToolRef {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Number(_) => {}
            Self::Inline(tool) => tool.scale(scaling),
        }
    }
}

/// A machine profile's lengths and feeds, for an answer that echoes it (profiles are stored in
/// mm; their `units` only sets the default of the requests that name them).
impl Scale for MachineProfile {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            name: _,
            block_time_ms: _,
            max_feed,
            dialect: _,
            margin: _,
            min_chord_error,
            description: _,
            mode: _,
            spindle_power_kw: _,
            spindle_torque_nm: _,
            max_spindle_rpm: _,
            spindle_power_curve: _,
            arcs: _,
            plunge_feed,
            max_accel,
            max_jerk,
            rapid_feed,
            tool_change_s: _,
            units: _,
            haas_smoothing: _,
        } = self;
        max_feed.scale(scaling);
        for value in [min_chord_error, plunge_feed, max_accel, max_jerk, rapid_feed] {
            value.scale(scaling);
        }
    }
}

impl Scale for BlockStats {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            blocks: _,
            block_length,
            min_block_length,
            max_block_length,
            last_block_length,
            short_blocks: _,
            short_end_blocks: _,
            min_block_ratio: _,
            path_length,
            estimated_time_s: _,
            path_time_s: _,
            max_vertex_angle_deg: _,
            mean_vertex_angle_deg: _,
        } = self;
        for value in [block_length, min_block_length, max_block_length, last_block_length, path_length] {
            value.scale(scaling);
        }
    }
}

impl Scale for CycleTime {
    fn scale(&mut self, scaling: Scaling) {
        self.max_accel.scale(scaling);
        self.max_jerk.scale(scaling);
    }
}

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

/// An area, mm²: scaled by the square of the length's conversion.
fn scale_area(area: &mut f64, scaling: Scaling) {
    *area = scaling.apply(scaling.apply(*area));
}

impl Scale for crate::machine::PathBlocks {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            block_time_ms: _,
            block_length,
            blocks: _,
            min_block_length,
            short_blocks: _,
            short_end_blocks: _,
            estimated_time_s: _,
            finest_arc_tolerance,
        } = self;
        block_length.scale(scaling);
        min_block_length.scale(scaling);
        finest_arc_tolerance.scale(scaling);
    }
}

/// A DXF drawing's tolerances (its geometry is in the drawing's own units, `$INSUNITS` or `units`).
impl Scale for crate::dxf::Drawing {
    fn scale(&mut self, scaling: Scaling) {
        let Self { units: _, layer: _, island: _, join_tolerance, chord_tolerance } = self;
        join_tolerance.scale(scaling);
        chord_tolerance.scale(scaling);
    }
}

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

/// The verification of a capability's own program: the findings' positions and depths, the grid
/// spacing and the tolerances. Volumes keep the mm³ their names say; the model's sentence is
/// written in mm.
impl Scale for crate::verify::Verification {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            ok: _,
            findings,
            findings_left_off: _,
            note: _,
            model: _,
            resolution,
            rays: _,
            tolerance,
            allowance,
            wall_tolerance,
            stock_volume_mm3: _,
            part_volume_mm3: _,
            removed_volume_mm3: _,
            air_share: _,
            moves: _,
            dexel_updates: _,
        } = self;
        findings.scale(scaling);
        for value in [resolution, tolerance, allowance, wall_tolerance] {
            value.scale(scaling);
        }
    }
}

/// A finding's position and depth (its volume keeps the mm³ its name says).
impl Scale for crate::verify::Finding {
    fn scale(&mut self, scaling: Scaling) {
        let Self { kind: _, line: _, tool: _, position, depth, volume_mm3: _, share: _, power_kw: _, limit_kw: _ } =
            self;
        position.scale(scaling);
        depth.scale(scaling);
    }
}

/// The spacing a request asks its verification to cut at.
impl Scale for crate::verify::VerificationOptions {
    fn scale(&mut self, scaling: Scaling) {
        let Self { enabled: _, resolution } = self;
        resolution.scale(scaling);
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

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    proptest! {
        #[test]
        fn inch_to_mm_and_back_is_the_same_value(value in -1.0e6f64..1.0e6) {
            let mut scaled = value;
            scaled.scale(Units::Inch.into_mm().unwrap());
            prop_assert!((scaled - value * 25.4).abs() <= 1e-12 * scaled.abs().max(1.0));
            scaled.scale(Units::Inch.from_mm().unwrap());
            prop_assert!((scaled - value).abs() <= 1e-15 * value.abs().max(1e-300) * 4.0);
        }

        #[test]
        fn a_tool_round_trips(radius in 0.01f64..100.0, stickout in 1.0f64..500.0, feed in 1.0f64..1e5) {
            let mut tool: Tool = serde_json::from_value(serde_json::json!({
                "kind": "flat", "radius": radius, "flutes": 2, "stickout": stickout, "plunge_feed": feed,
                "helix_deg": 30.0
            })).unwrap();
            let original = tool.clone();
            tool.scale(Units::Inch.from_mm().unwrap());
            prop_assert!((tool.radius * 25.4 - radius).abs() <= 1e-12 * radius);
            prop_assert_eq!(tool.helix_deg, Some(30.0));
            tool.scale(Units::Inch.into_mm().unwrap());
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * b.abs();
            prop_assert!(close(tool.radius, original.radius));
            prop_assert!(close(tool.stickout.unwrap(), original.stickout.unwrap()));
            prop_assert!(close(tool.plunge_feed.unwrap(), original.plunge_feed.unwrap()));
        }
    }
}
