//! Benchmarks for solver::corners (not written yet).

fn main() {}
