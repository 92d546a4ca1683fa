//! Lengths and feeds of machine profiles and block figures, for answers in the request's units (docs/spec/api.md, units).

use super::MachineProfile;
use super::cycle::CycleTime;
use super::stats::BlockStats;
use crate::units::{Scale, Scaling};

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
