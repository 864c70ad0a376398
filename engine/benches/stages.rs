//! Criterion benchmarks of the pipeline (filled in with the bench work).
fn main() {}
