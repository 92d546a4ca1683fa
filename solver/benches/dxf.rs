//! Benchmark for reading a DXF drawing (docs/spec/dxf.md): 100 000 LINE entities, written in
//! shuffled order and half of them reversed, that join into one 100 000-gon (a 200 mm circle) with
//! 100 CIRCLE islands; criterion reports entities per second (`thrpt`, in elements/s).
//!
//! Run: `cargo bench -p kerf-solver --bench dxf -- --warm-up-time 1 --measurement-time 10`, or
//! `tests/load/dxf.sh`, which also times ezdxf reading the same file (written to
//! `$CARGO_TARGET_TMPDIR/dxf-100k.dxf`).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::dxf::{DxfOptions, read};

const LINES: usize = 100_000;
const ISLANDS: usize = 100;

fn drawing() -> String {
    let point = |k: usize| {
        let angle = std::f64::consts::TAU * (k % LINES) as f64 / LINES as f64;
        (100.0 * angle.cos(), 100.0 * angle.sin())
    };
    let mut text = String::from("0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n");
    // A fixed stride through the lines: every one once, far from its neighbours in the file.
    for index in 0..LINES {
        let k = (index * 7919) % LINES;
        let (mut a, mut b) = (point(k), point(k + 1));
        if index % 2 == 1 {
            std::mem::swap(&mut a, &mut b);
        }
        text.push_str(&format!("0\nLINE\n8\nCUT\n10\n{:.9}\n20\n{:.9}\n11\n{:.9}\n21\n{:.9}\n", a.0, a.1, b.0, b.1));
    }
    for index in 0..ISLANDS {
        let (x, y) = ((index % 10) as f64 * 12.0 - 54.0, (index / 10) as f64 * 12.0 - 54.0);
        text.push_str(&format!("0\nCIRCLE\n8\nCUT\n10\n{x}\n20\n{y}\n40\n3\n"));
    }
    text.push_str("0\nENDSEC\n0\nEOF\n");
    text
}

fn bench(c: &mut Criterion) {
    let text = drawing();
    let profile = read(text.as_bytes(), "file", &DxfOptions::default()).expect("reads");
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("dxf-100k.dxf");
    std::fs::write(&path, &text).expect("the drawing is written for the ezdxf comparison");
    eprintln!("the drawing: {}", path.display());
    eprintln!(
        "{} entities, {} bytes: boundary of {} points, {} islands",
        profile.entities,
        text.len(),
        profile.boundary.len(),
        profile.islands.len()
    );
    let mut group = c.benchmark_group("dxf");
    group.sample_size(10);
    group.throughput(Throughput::Elements((LINES + ISLANDS) as u64));
    group.bench_function("lines_100k", |b| {
        b.iter(|| read(text.as_bytes(), "file", &DxfOptions::default()).expect("reads"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
