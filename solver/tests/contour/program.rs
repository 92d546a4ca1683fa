//! The G-code program of a contour: both dialects, feeds of cuts, loops and links, the reference
//! point, and the refusal for tilted walls. LinuxCNC's `rs274` runs the programs in kerf-tests
//! (`contour::gcode_of_both_dialects_matches_the_json_moves`, whose pocket has dogbones and a loop), where a missing interpreter shows
//! as an ignored test.

use kerf_solver::contour::{self, ContourRequest};
use kerf_solver::gcode::Post;
use kerf_solver::gcode::{Dialect, Reference, ToolCall};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::json;

fn request(extra: serde_json::Value) -> ContourRequest {
    let mut body = json!({
        "tool": 3,
        "contour": [[0, 0], [40, 0], [40, 30], [0, 30]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -6, "step": 2},
        "corner_loop": {"style": "arc"},
        "feed": 800,
        "loop_feed": 3000,
        "stock_allowance": 0.5
    });
    for (key, value) in extra.as_object().unwrap() {
        body[key] = value.clone();
    }
    serde_json::from_value(body).unwrap()
}

fn post(dialect: Dialect, reference: Reference) -> Post {
    Post {
        dialect,
        reference,
        tool: ToolCall::Table(3),
        arcs: kerf_solver::gcode::Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    }
}

#[test]
fn program_has_layers_loop_feeds_and_links() {
    let tool = Tool::new(ToolKind::Flat, 3.0);
    let answer = contour::solve(&request(json!({})), &tool).unwrap();
    let text = contour::program(&answer, &post(Dialect::Fanuc, Reference::Tip)).unwrap();
    assert!(text.starts_with("%\nO1000 (KERF CONTOUR)\n"));
    assert!(text.contains("T3 M06\nG00 G43 H3 Z5.0000\n"));
    assert!(text.contains("F800"));
    assert!(text.contains("F3000"), "loops clear the stock and run at loop_feed");
    for z in ["Z-2.0000", "Z-4.0000", "Z-6.0000"] {
        assert!(text.contains(z), "{z}");
    }
    // Between layers the tool goes up to the clearance plane.
    let rapids_up = text.lines().filter(|l| l.starts_with("G00") && l.ends_with("Z5.0000")).count();
    assert!(rapids_up >= 4, "{rapids_up}");
    assert!(text.ends_with("M05\nG00 Z5.0000\nM30\n%\n"));
    let moves = text.lines().filter(|l| l.starts_with("G0")).count();
    let answer_moves: usize = answer.layers.iter().map(|l| l.moves.len()).sum();
    assert_eq!(moves, answer_moves + 2, "every move plus the tool-length line and the final retract");
    // The same request gives the same bytes.
    let again =
        contour::program(&contour::solve(&request(json!({})), &tool).unwrap(), &post(Dialect::Fanuc, Reference::Tip))
            .unwrap();
    assert_eq!(text, again);
}

#[test]
fn ball_centre_reference_lifts_the_program_and_tilt_is_refused() {
    let mut ball = Tool::new(ToolKind::Ball, 3.0);
    ball.flutes = 2;
    let answer = contour::solve(&request(json!({"tool": {"kind": "ball", "radius": 3}})), &ball).unwrap();
    let text = contour::program(&answer, &post(Dialect::Linuxcnc, Reference::Centre)).unwrap();
    assert!(text.contains("G64 P0.0100"));
    assert!(text.contains("Z1.0000"), "the layer at z = −2 is programmed at the ball centre −2 + 3");
    let tilted = contour::solve(&request(json!({"tilt_deg": 5})), &Tool::new(ToolKind::Flat, 3.0)).unwrap();
    let error = contour::program(&tilted, &post(Dialect::Fanuc, Reference::Tip)).unwrap_err();
    assert_eq!(error.code().as_str(), "E_TILT_NEEDS_5_AXIS");
}
