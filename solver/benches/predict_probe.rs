use kerf_solver::predict::{self, Method};
use std::time::Instant;
#[path = "../tests/predict_support/mod.rs"]
mod support;
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap()
        .split_whitespace()
        .collect();
    (fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap()) / 100.0
}
fn main() {
    let method = if std::env::var("DB").is_ok() {
        Method::DepthBuffer
    } else {
        Method::Sampling
    };
    let (mut request, tool, moves) = support::raster_request(160.0, 0.5, 0.5, method, 256);
    let threads: usize = std::env::var("T")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let middle = moves / 2;
    let n: usize = std::env::var("N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1000);
    request.pass_range = Some([middle, middle]);
    let (t, c) = (Instant::now(), cpu_seconds());
    pool.install(|| predict::solve(&request, &tool, None).unwrap());
    let (setup_wall, setup_cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    request.pass_range = Some([middle, middle + n]);
    let (t, c) = (Instant::now(), cpu_seconds());
    let a = pool.install(|| predict::solve(&request, &tool, None).unwrap());
    let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    eprintln!(
        "{n} passes: wall {:.3} ms/pass, cpu {:.3} ms/pass (setup wall {setup_wall:.3}s cpu {setup_cpu:.2}s); predicted {} cut {} fin {}",
        (wall - setup_wall) / n as f64 * 1e3,
        (cpu - setup_cpu) / n as f64 * 1e3,
        a.summary.predicted,
        a.passes[middle].cut_count,
        a.passes[middle].finished_count
    );
}
