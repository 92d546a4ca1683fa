//! Lengths of verify requests and answers and of the verification section of the other
//! capabilities' answers, for the request's units (docs/spec/verify.md §9, docs/spec/api.md Units).
//! Volumes keep the mm³ their names say.

use super::capability::VerifyAnswer;
use super::request::{CrossHole, Hollow, Solid, VerifyRequest};
use super::simulate::Cut;
use crate::units::{Scale, Scaling};

/// A verify request's tools, solids, spacing and depths; the program keeps its own G20/G21.
impl Scale for VerifyRequest {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            program: _,
            tools,
            stock,
            part,
            resolution,
            tolerance,
            allowance,
            air_share_limit: _,
            block_delete: _,
            material: _,
            machine: _,
            units: _,
        } = self;
        tools.scale(scaling);
        stock.scale(scaling);
        part.scale(scaling);
        for value in [resolution, tolerance, allowance] {
            value.scale(scaling);
        }
    }
}

impl Scale for Solid {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Tube(tube) => tube.scale(scaling),
            Self::Stock(stock) => stock.scale(scaling),
        }
    }
}

impl Scale for Hollow {
    fn scale(&mut self, scaling: Scaling) {
        let Self::Tube { start, end, outer_radius, inner_radius, holes } = self;
        start.scale(scaling);
        end.scale(scaling);
        outer_radius.scale(scaling);
        inner_radius.scale(scaling);
        holes.scale(scaling);
    }
}

impl Scale for CrossHole {
    fn scale(&mut self, scaling: Scaling) {
        let Self { start, end, radius } = self;
        start.scale(scaling);
        end.scale(scaling);
        radius.scale(scaling);
    }
}

/// The echoed tools and the cut.
impl Scale for VerifyAnswer {
    fn scale(&mut self, scaling: Scaling) {
        let Self { tools, assumed, cut } = self;
        tools.scale(scaling);
        for sentence in assumed {
            sentence.scale(scaling);
        }
        cut.scale(scaling);
    }
}

/// The findings and the dexel spacing (volumes, times, rates and counts are not lengths).
impl Scale for Cut {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            ok: _,
            findings,
            findings_left_off: _,
            resolution,
            rays: _,
            stock_volume_mm3: _,
            part_volume_mm3: _,
            removed_volume_mm3: _,
            final_volume_mm3: _,
            cutting_time_s: _,
            air_time_s: _,
            air_share: _,
            moves: _,
            moves_unplaced: _,
            dexel_updates: _,
            blocks: _,
        } = self;
        findings.scale(scaling);
        resolution.scale(scaling);
    }
}

/// The verification of a capability's own program: the findings' positions and depths, the grid
/// spacing and the tolerances, and the note and the model's sentence restated in the answer's
/// units. Volumes keep the mm³ their names say.
impl Scale for crate::verify::Verification {
    fn scale(&mut self, scaling: Scaling) {
        let Self {
            ok: _,
            findings,
            findings_left_off: _,
            note,
            model,
            assumed,
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
        note.scale(scaling);
        model.scale(scaling);
        for sentence in assumed {
            sentence.scale(scaling);
        }
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
