//! Benchmarks for solver::predict (not written yet).

fn main() {}
