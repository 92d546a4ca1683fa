//! The patent's experiment (chord.md §3, case A): R50 circle at 10 000 mm/min on a control with a
//! 4 ms block time, cut by the block-time rule and by a fixed 0.01 mm tolerance; prints the
//! comparison figures. Run: `cargo run -p kerf-solver --example chord_patent`.

use kerf_solver::chord::{self, BlockStats, SegmentRequest};

fn row(name: &str, stats: &BlockStats, deviation: f64) {
    println!(
        "{name:<26} {:>6} {:>10.6} {:>10.6} {:>6} {:>6} {:>9.4} {:>9.4} {:>10.6} {:>8.3}",
        stats.blocks,
        stats.min_block_length,
        stats.last_block_length,
        stats.short_blocks,
        stats.short_end_blocks,
        stats.estimated_time_s,
        stats.path_time_s,
        deviation,
        stats.max_vertex_angle_deg,
    );
}

fn main() {
    let request: SegmentRequest = serde_json::from_value(serde_json::json!({
        "curve": {"kind": "circle", "centre": [0, 0], "radius": 50},
        "feed": 10000, "block_time_ms": 4, "mode": "window", "margin": 1.0,
        "min_chord_error": 0.0, "compare_tolerance": 0.01
    }))
    .expect("request");
    let answer = chord::solve(&request, None).expect("solve");
    println!(
        "C_ep = {:.10} mm, block length F*Tb = {:.6} mm",
        answer.chord_error, answer.stats.block_length
    );
    println!(
        "{:<26} {:>6} {:>10} {:>10} {:>6} {:>6} {:>9} {:>9} {:>10} {:>8}",
        "cut",
        "blocks",
        "shortest",
        "last",
        "short",
        "s_end",
        "t_est_s",
        "t_path_s",
        "max_dev",
        "max_ang"
    );
    row(
        "block-time rule (C_ep)",
        &answer.stats,
        answer.max_deviation,
    );
    if let Some(comparison) = &answer.comparison {
        row(
            &format!("fixed {} mm", comparison.tolerance),
            &comparison.stats,
            comparison.max_deviation,
        );
    }
    println!(
        "warnings: {:?}",
        answer.warnings.iter().map(|w| w.code).collect::<Vec<_>>()
    );
    let program = chord::program(
        &answer,
        &chord::Post {
            dialect: kerf_solver::gcode::Dialect::Fanuc,
            tool: kerf_solver::gcode::ToolCall::Table(1),
        },
    )
    .expect("program");
    for line in program.lines().take(16) {
        println!("{line}");
    }
}
