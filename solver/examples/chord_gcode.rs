//! Writes the G-code of the patent's R50 circle (case A) in both dialects to the files named on
//! the command line (Fanuc, then LinuxCNC), e.g. to check them with LinuxCNC's `rs274`.

use kerf_solver::chord::{self, SegmentRequest};
use kerf_solver::gcode::{Dialect, Post, ToolCall};

fn main() {
    let request: SegmentRequest = serde_json::from_value(serde_json::json!({
        "curve": {"kind": "circle", "centre": [0, 0], "radius": 50},
        "feed": 10000, "block_time_ms": 4
    }))
    .expect("request");
    let answer = chord::solve(&request, None).expect("solve");
    let mut files = std::env::args().skip(1);
    for dialect in [Dialect::Fanuc, Dialect::Linuxcnc] {
        let program = chord::program(
            &answer,
            &Post {
                reference: kerf_solver::gcode::Reference::Tip,
                dialect,
                tool: ToolCall::Table(1),
                arcs: kerf_solver::gcode::Arcs::Chords,
                plunge_feed: None,
            },
        )
        .expect("program");
        match files.next() {
            Some(path) => std::fs::write(path, program).expect("write"),
            None => print!("{program}"),
        }
    }
}
