//! Writes the answer JSON and G-code of a few deburr requests (the typical request of
//! tests/load/deburr-distinct.lua and its neighbours) to the directory
//! given as its argument, so that two builds can be compared byte for byte with `cmp` after a
//! change meant to leave the answers alone:
//! `cargo run --release -p kerf-solver --example deburr_dump -- /tmp/dump`.

use kerf_solver::deburr::{self, DeburrRequest};
use kerf_solver::gcode::{Arcs, Dialect, Post, Reference, ToolCall};
use kerf_solver::tool::{Tool, ToolKind};

fn request(hole: serde_json::Value, edge: &str, cut_amount: f64, method: &str) -> DeburrRequest {
    serde_json::from_value(serde_json::json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
        "hole": hole, "edge": edge, "cut_amount": cut_amount, "tolerance": 0.01, "method": method
    }))
    .expect("valid request")
}

fn main() {
    let directory = std::env::args().nth(1).expect("usage: deburr_dump DIRECTORY");
    std::fs::create_dir_all(&directory).unwrap();
    let round = serde_json::json!({"shape": "round", "radius": 10});
    let slot = serde_json::json!({"shape": "slot", "radius": 6, "centre_distance": 12});
    let rounded_rect = serde_json::json!({"shape": "rounded_rect", "radius": 3, "centre_distance": [14, 10]});
    let cases = [
        ("typical_distinct_0.300123", request(round.clone(), "outer", 0.300123, "tangent")),
        ("typical_distinct_0.3", request(round.clone(), "outer", 0.3, "tangent")),
        ("typical_distinct_0.399999", request(round.clone(), "outer", 0.399999, "tangent")),
        ("case1_0.5", request(round.clone(), "outer", 0.5, "tangent")),
        ("inner_round", request(round.clone(), "inner", 0.3, "tangent")),
        ("outer_slot", request(slot.clone(), "outer", 0.3, "tangent")),
        ("inner_slot", request(slot, "inner", 0.4, "tangent")),
        ("outer_rounded_rect", request(rounded_rect.clone(), "outer", 0.3, "tangent")),
        ("inner_rounded_rect", request(rounded_rect.clone(), "inner", 0.3, "tangent")),
        ("exact_round", request(round.clone(), "outer", 0.300123, "exact")),
        ("exact_inner_round", request(round, "inner", 0.3, "exact")),
        ("exact_rounded_rect", request(rounded_rect, "outer", 0.3, "exact")),
    ];
    let tool = Tool::new(ToolKind::Ball, 3.0);
    let post = Post {
        dialect: Dialect::Fanuc,
        reference: Reference::Tip,
        tool: ToolCall::Table(7),
        arcs: Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    };
    for (name, job) in cases {
        let answer = deburr::solve(&job, &tool);
        let json = match &answer {
            Ok(answer) => serde_json::to_string_pretty(answer).unwrap(),
            Err(error) => format!("{error:?}"),
        };
        std::fs::write(format!("{directory}/{name}.json"), json).unwrap();
        let program = match &answer {
            Ok(answer) => deburr::program(answer, &post).unwrap_or_else(|error| format!("{error:?}")),
            Err(_) => String::new(),
        };
        std::fs::write(format!("{directory}/{name}.nc"), program).unwrap();
    }
}
