//! The patent's experiment (chord.md §3, case A): R50 circle at 10 000 mm/min on a control with a
//! 4 ms block time, cut by the block-time rule and by fixed 0.01 and 0.0005 mm tolerances; then
//! the quarter ellipse of cases B and C against fixed 0.01 and 0.001 mm. Prints the comparison
//! figures and the head of the program. Run: `cargo run -p kerf-solver --example chord_patent`.

use kerf_solver::chord::{self, SegmentAnswer, SegmentRequest};
use kerf_solver::gcode::{Dialect, ToolCall};
use kerf_solver::machine::BlockStats;
use serde_json::{Value, json};

fn row(name: &str, stats: &BlockStats, deviation: f64) {
    println!(
        "{name:<18} {:>6} {:>9.6} {:>9.6} {:>6} {:>6} {:>8.4} {:>8.4} {:>9.6} {:>8.3}",
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

/// Solves `request` once per fixed tolerance and prints the rule's row and each fixed one.
fn table(title: &str, request: &Value, fixed: &[f64]) -> SegmentAnswer {
    println!("\n{title}");
    println!(
        "{:<18} {:>6} {:>9} {:>9} {:>6} {:>6} {:>8} {:>8} {:>9} {:>8}",
        "cut", "blocks", "shortest", "last", "short", "s_end", "t_est_s", "t_path_s", "max_dev", "max_ang"
    );
    let mut first: Option<SegmentAnswer> = None;
    for &tolerance in fixed {
        let mut with_fixed = request.clone();
        with_fixed["compare_tolerance"] = json!(tolerance);
        let parsed: SegmentRequest = serde_json::from_value(with_fixed).expect("request");
        let answer = chord::solve(&parsed, None).expect("solve");
        if first.is_none() {
            row("block-time rule", &answer.stats, answer.max_deviation);
        }
        if let Some(comparison) = &answer.comparison {
            let name = format!("fixed {} mm", comparison.tolerance);
            row(&name, &comparison.stats, comparison.max_deviation);
        }
        first.get_or_insert(answer);
    }
    let answer = first.expect("at least one tolerance");
    println!(
        "C_ep {:.10} mm (windows {:.6} to {:.6}); F*Tb = {:.6} mm; warnings {:?}",
        answer.chord_error,
        answer.min_window_chord_error,
        answer.chord_error,
        answer.stats.block_length,
        answer.warnings.iter().map(|w| w.code).collect::<Vec<_>>()
    );
    answer
}

fn main() {
    let answer = table(
        "A: the patent's experiment, R50 circle, F 10000, Tb 4 ms, on the surface (k_f 1)",
        &json!({
            "curve": {"kind": "circle", "centre": [0, 0], "radius": 50},
            "feed": 10000, "block_time_ms": 4, "mode": "window", "margin": 1.0, "min_chord_error": 0.0
        }),
        &[0.01, 0.0005],
    );
    let ellipse = json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "start_deg": 0, "end_deg": 90});
    table(
        "B: quarter ellipse, embodiment 4 (r_min, F_max), F 10000, Tb 4 ms, k_f 1.1",
        &json!({"curve": ellipse, "feed": 10000, "block_time_ms": 4, "margin": 1.1,
                "mode": "curve", "rule": "extremes"}),
        &[0.01, 0.001],
    );
    table(
        "C: quarter ellipse, windows of 5 mm, F 12000, Tb 4 ms, k_f 1.05, C_emin 0.001",
        &json!({"curve": ellipse, "feed": 12000, "block_time_ms": 4, "margin": 1.05,
                "min_chord_error": 0.001, "window": 5}),
        &[0.01, 0.001],
    );
    println!("\nProgram head (case A, Fanuc):");
    let post = kerf_solver::gcode::Post {
        reference: kerf_solver::gcode::Reference::Tip,
        dialect: Dialect::Fanuc,
        tool: ToolCall::Table(1),
        arcs: kerf_solver::gcode::Arcs::Chords,
        plunge_feed: None,
    };
    let program = chord::program(&answer, &post).expect("program");
    for line in program.lines().take(18) {
        println!("{line}");
    }
}
