//! Benchmark for re-segmenting a CAM program (docs/spec/resegment.md): a program of 1 000 000
//! lines of dense G01 points (0.01 mm steps on concentric circles of 100 mm radius and smaller at
//! 6000 mm/min, one run each between a rapid and a plunge) read, cut again for a 4 ms control and
//! written, in the program's own post and re-posted for Sinumerik; criterion reports lines per
//! second (`thrpt`, in elements/s).
//!
//! Run: `cargo bench -p kerf-solver --bench resegment -- --warm-up-time 1 --measurement-time 20`.
//! The program is also written to `$TMPDIR/kerf-resegment-1m.ngc`, to time another reader on the
//! same file (`time rs274 -g $TMPDIR/kerf-resegment-1m.ngc > /dev/null`).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::Control;
use kerf_solver::gcode::Dialect;
use kerf_solver::segment::resegment::{ResegmentRequest, resegment, write, write_posted};

/// Lines of the program.
const LINES: usize = 1_000_000;

fn dense_program() -> String {
    let mut text =
        String::from("%\nO1000 (DENSE CIRCLES)\nG21 G17 G90 G40 G49 G80 G94\nT1 M06\nG00 G43 H1 Z25.\nS8000 M03\n");
    let mut lines = text.lines().count();
    let mut radius = 100.0_f64;
    'circles: loop {
        text.push_str(&format!("G00 X{radius:.4} Y0.0000\nG00 Z2.\nG01 Z-1. F300\n"));
        lines += 3;
        let steps = (std::f64::consts::TAU * radius / 0.01).round() as usize;
        for k in 1..=steps {
            if lines + 4 >= LINES {
                break 'circles;
            }
            let angle = std::f64::consts::TAU * k as f64 / steps as f64;
            let feed = if k == 1 { " F6000" } else { "" };
            text.push_str(&format!("X{:.4} Y{:.4}{feed}\n", radius * angle.cos(), radius * angle.sin()));
            lines += 1;
        }
        text.push_str("G00 Z25.\n");
        lines += 1;
        radius -= 2.0;
    }
    text.push_str("G00 Z25.\nM05\nM30\n%");
    text
}

fn bench(c: &mut Criterion) {
    let program = dense_program();
    let lines = program.lines().count();
    let path = std::env::temp_dir().join("kerf-resegment-1m.ngc");
    std::fs::write(&path, &program).expect("write the program");
    let request = ResegmentRequest {
        program,
        machine: None,
        block_time_ms: Some(4.0),
        margin: None,
        min_chord_error: None,
        tolerance: None,
        corner_angle_deg: None,
        program_dialect: None,
        units: None,
    };
    let answer = resegment(&request, None, Control::default()).expect("resegments");
    eprintln!(
        "{lines} lines ({}): {} runs; feed blocks {} -> {}, short {} -> {}, time {:.1} s -> {:.1} s, deviation {:.6} mm",
        path.display(),
        answer.runs,
        answer.before.blocks,
        answer.after.blocks,
        answer.before.short_blocks,
        answer.after.short_blocks,
        answer.before.estimated_time_s,
        answer.after.estimated_time_s,
        answer.max_deviation,
    );
    let mut group = c.benchmark_group("resegment");
    group.sample_size(10);
    group.throughput(Throughput::Elements(lines as u64));
    group.bench_function("dense_1m_lines", |b| {
        b.iter(|| {
            let answer = resegment(&request, None, Control::default()).expect("resegments");
            write(&request.program, &answer.cuts, Control::default()).expect("writes")
        });
    });
    group.bench_function("dense_1m_lines_reposted_for_sinumerik", |b| {
        b.iter(|| {
            let answer = resegment(&request, None, Control::default()).expect("resegments");
            write_posted(&request.program, &answer.cuts, Dialect::Fanuc, Dialect::Sinumerik, Control::default())
                .expect("re-posts")
        });
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
