//! Benchmarks for solver::chord (not written yet).

fn main() {}
