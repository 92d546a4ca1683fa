//! Lengths and feeds of predict requests and answers, for the request's units (docs/spec/api.md,
//! Units). Forces (N), stiffnesses (N/mm), compliances (mm/N) and cutting coefficients (N/mm²,
//! N/mm) keep their units: they describe the tool and the material, not the geometry.

use super::Predict;
use super::answer::{MergeSummary, PassHistory, PredictSummary, PredictedPass, RoundSummary, WorstPass};
use super::capability::PredictAnswer;
use super::request::{CorrectionOptions, PathInput, PredictRequest, PrescribedDeflection};
use crate::units::{Scale, Scaling};

/// A predict request's lengths and feeds: the inline tool, the stock, a path of points, the feed,
/// the arc and merge tolerances, a prescribed deflection and the correction's clamp.
impl Scale for PredictRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            tool,
            stock,
            path,
            reference: _,
            spindle_rpm: _,
            spindle_direction: _,
            feed,
            cutting: _,
            deflection,
            method: _,
            resolution: _,
            tooth_feed_gap: _,
            view_correction: _,
            view_correction_deg: _,
            flute_zero_deg: _,
            samples_per_revolution: _,
            edge_elements: _,
            arc_tolerance,
            block_delete: _,
            correction,
            history: _,
            pass_range: _,
            exclusion_deg: _,
            exclusion_shape_error: _,
            merge_similar_passes: _,
            merge_tolerance,
            units: _,
            verification,
        } = self;
        tool.scale(scaling);
        stock.scale(scaling);
        path.scale(scaling);
        for value in [feed, arc_tolerance, merge_tolerance] {
            value.scale(scaling);
        }
        deflection.scale(scaling);
        correction.scale(scaling);
        verification.scale(scaling);
    }
}

/// A path of points is scaled; a program keeps its own G20/G21, which the reader converts.
impl Scale for PathInput {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Points { points } => points.scale(scaling),
            Self::Gcode { program: _ } => {}
        }
    }
}

impl Scale for PrescribedDeflection {
    fn scale(&mut self, scaling: Scaling) {
        let Self { x, y } = self;
        x.scale(scaling);
        y.scale(scaling);
    }
}

impl Scale for CorrectionOptions {
    fn scale(&mut self, scaling: Scaling) {
        let Self { max_correction, iterations: _ } = self;
        max_correction.scale(scaling);
    }
}

/// A predict answer: the echoed tool, the prediction and the verification of its program (its
/// timings are times).
impl Scale for PredictAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self { tool, result, timings: _, verification } = self;
        tool.scale(scaling);
        result.scale(scaling);
        verification.scale(scaling);
    }
}

/// The passes, the summary and the warnings; the corrections are the program's, written in mm
/// before the answer is converted, and not part of the JSON.
impl Scale for Predict {
    fn scale(&mut self, scaling: Scaling) {
        let Self { passes, summary, warnings, corrections: _ } = self;
        passes.scale(scaling);
        summary.scale(scaling);
        warnings.scale(scaling);
    }
}

/// A pass's position along it, centre, errors, generation point, deflection, correction and
/// corrected end point and merge bound (not its unit normal and view direction, nor its angles).
impl Scale for PredictedPass {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            index: _,
            line: _,
            block_number: _,
            status: _,
            flags: _,
            position,
            centre,
            error,
            error_deflection,
            error_shape,
            contact_angle_deg: _,
            azimuth_deg: _,
            rotation_angle_deg: _,
            generation_point,
            normal: _,
            deflection,
            cut_count: _,
            finished_count: _,
            view: _,
            residual_error,
            correction,
            corrected,
            history,
            merged_with: _,
            merge_bound,
        } = self;
        for value in [position, error, error_deflection, error_shape, residual_error, merge_bound] {
            value.scale(scaling);
        }
        centre.scale(scaling);
        generation_point.scale(scaling);
        deflection.scale(scaling);
        correction.scale(scaling);
        corrected.scale(scaling);
        history.scale(scaling);
    }
}

/// The deflection over one revolution (its forces are in N).
impl Scale for PassHistory {
    fn scale(&mut self, scaling: Scaling) {
        let Self { step_deg: _, force: _, deflection } = self;
        deflection.scale(scaling);
    }
}

impl Scale for PredictSummary {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            passes: _,
            predicted: _,
            no_cut: _,
            no_surface: _,
            outside_stock: _,
            skipped_small_angle: _,
            min_error,
            max_error,
            mean_error,
            rms_error,
            worst,
            max_correction,
            clamped: _,
            rounds,
            method: _,
            resolution: _,
            pixel_size,
            samples_per_revolution: _,
            edge_elements: _,
            merge,
        } = self;
        for value in [min_error, max_error, mean_error, rms_error] {
            value.scale(scaling);
        }
        max_correction.scale(scaling);
        pixel_size.scale(scaling);
        worst.scale(scaling);
        rounds.scale(scaling);
        merge.scale(scaling);
    }
}

impl Scale for WorstPass {
    fn scale(&mut self, scaling: Scaling) {
        let Self { index: _, line: _, error } = self;
        error.scale(scaling);
    }
}

impl Scale for RoundSummary {
    fn scale(&mut self, scaling: Scaling) {
        let Self { predicted: _, max_abs_error, rms_error } = self;
        max_abs_error.scale(scaling);
        rms_error.scale(scaling);
    }
}

impl Scale for MergeSummary {
    fn scale(&mut self, scaling: Scaling) {
        let Self { tolerance, simulated: _, merged: _, max_bound } = self;
        tolerance.scale(scaling);
        max_bound.scale(scaling);
    }
}
