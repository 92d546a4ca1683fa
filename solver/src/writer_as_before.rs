//! Test only: every capability's example program written by the G-code writer is what the old
//! writer (`gcode/reference.rs`) wrote. Apart from `gcode`, which the capabilities import.

use std::cell::Cell;

/// Each capability's example program (segment, contour, deburr with a tool change, engagement)
/// written in both old posts, with arcs as chords and as G02/G03, by both writers.
#[test]
fn every_capability_writes_as_before() {
    use serde_json::json;

    use crate::capability::{self, Capability, Control, OutputOptions, Purpose, Resolved, Run};
    use crate::gcode::reference::COMPARED;
    use crate::gcode::{Arcs, Dialect};
    use crate::tool::{Tool, ToolKind};

    fn both_ways<C: Capability>(request: serde_json::Value, tool: C::Tool, other_tools: Vec<Tool>) {
        let request: C::Request = serde_json::from_value(request).expect("the example reads");
        let context = Resolved { tool, machine: None, material: None, other_tools };
        let answer = C::solve(&request, context, &Run { purpose: Purpose::Program, ..Run::default() })
            .unwrap_or_else(|error| panic!("{} solves: {error:?}", C::NAME));
        for dialect in [Dialect::Fanuc, Dialect::Linuxcnc] {
            for arcs in [Arcs::Chords, Arcs::G2g3] {
                let output = OutputOptions { dialect: Some(dialect), arcs: Some(arcs), ..OutputOptions::default() };
                let before = COMPARED.with(Cell::get);
                let text = capability::program::<C>(&request, &answer, &output, Control::default())
                    .unwrap_or_else(|error| panic!("{} writes: {error:?}", C::NAME));
                assert!(text.lines().count() > 10, "{}: {text}", C::NAME);
                // More than once where the program's verification warnings name lines: the Fanuc
                // program is written again to find them in this post's.
                assert!(COMPARED.with(Cell::get) > before, "{} was compared with the old writer", C::NAME);
            }
        }
    }

    let mut numbered = Tool::new(ToolKind::Ball, 3.0);
    numbered.number = Some(7);
    let mut flat = Tool::new(ToolKind::Flat, 3.0);
    flat.number = Some(3);
    both_ways::<crate::segment::SegmentCapability>(
        json!({"curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [40, 15]}, "feed": 3000,
               "block_time_ms": 4, "mode": "guarantee"}),
        None,
        Vec::new(),
    );
    both_ways::<crate::contour::ContourCapability>(
        json!({"tool": 3, "contour": [[0, 10], [40, 10], [40, 0], [80, 25], [40, 50], [40, 40], [0, 40]],
               "side": "outside", "depths": {"top": 0, "bottom": -2, "step": 1},
               "corner_loop": {"style": "arc"}, "inside_corner_relief": "dogbone",
               "feed": 800, "loop_feed": 2000, "stock_allowance": 0.5, "spindle_rpm": 8000,
               "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}]}),
        flat.clone(),
        Vec::new(),
    );
    let mut inner = Tool::new(ToolKind::Ball, 2.0);
    inner.number = Some(9);
    both_ways::<crate::deburr::DeburrCapability>(
        json!({"tool": 7, "inner_tool": 9,
               "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
               "holes": [{"shape": "round", "radius": 4, "penetration_angle_deg": 90, "axial_position": 0},
                         {"shape": "round", "radius": 4, "penetration_angle_deg": 90, "axial_position": 30}],
               "edge": "both", "cut_amount": 0.3, "tolerance": 0.01}),
        numbered,
        vec![inner],
    );
    both_ways::<crate::engagement::EngagementCapability>(
        json!({"tool": 3, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
               "path": [[-10, 5], [70, 5], [70, 15], [-10, 15], [-10, 25], [70, 25]],
               "spindle_rpm": 8000, "feed_per_tooth": 0.05, "axial_depth": 2}),
        flat,
        Vec::new(),
    );
}
