//! Lengths of the verification section of an answer, for the request's units (docs/spec/verify.md §9).

use crate::units::{Scale, Scaling};

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
