use kerf_solver::predict::{self, Method};
#[path = "../tests/predict_support/mod.rs"]
mod support;
fn main() {
    let method =
        if std::env::args().nth(1).as_deref() == Some("depth") { Method::DepthBuffer } else { Method::Sampling };
    let (mut request, tool, moves) = support::raster_request(160.0, 0.5, 0.5, method, 256);
    let middle = moves / 2;
    request.pass_range = Some([middle, middle]);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let started = std::time::Instant::now();
    pool.install(|| predict::solve(&request, &tool, None).unwrap());
    let setup = started.elapsed().as_secs_f64();
    request.pass_range = Some([middle, middle + 3000]);
    let started = std::time::Instant::now();
    let answer = pool.install(|| predict::solve(&request, &tool, None).unwrap());
    let total = started.elapsed().as_secs_f64();
    eprintln!(
        "{:.3} ms per pass (setup {setup:.2} s), max {:?}",
        (total - setup) * 1000.0 / 3000.0,
        answer.summary.max_error
    );
}
