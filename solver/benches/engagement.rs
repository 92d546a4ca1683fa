//! Benchmarks for solver::engagement (not written yet).

fn main() {}
