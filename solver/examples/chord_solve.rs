//! Solves a segment request from a JSON file (api.md, Segment) and prints the block figures and
//! warnings, or the error: `cargo run -p kerf-solver --example chord_solve -- request.json`.

use kerf_solver::chord::{self, SegmentRequest};

fn main() {
    let path = std::env::args().nth(1).expect("usage: chord_solve request.json");
    let text = std::fs::read_to_string(path).expect("read the request");
    let request: SegmentRequest = serde_json::from_str(&text).expect("a segment request");
    match chord::solve(&request, None) {
        Ok(answer) => {
            let stats = &answer.stats;
            println!(
                "{} blocks ({} windows), chord error {:.6} to {:.6} mm, shortest {:.6} mm, {} short, \
                 max deviation {:.6} mm, {:.3} s",
                stats.blocks,
                answer.windows.len(),
                answer.min_window_chord_error,
                answer.chord_error,
                stats.min_block_length,
                stats.short_blocks,
                answer.max_deviation,
                stats.estimated_time_s
            );
            for warning in &answer.warnings {
                println!("  {} {}", warning.code, warning.message);
            }
        }
        Err(error) => println!("{} at {:?}: {}", error.code(), error.field(), error.message()),
    }
}
