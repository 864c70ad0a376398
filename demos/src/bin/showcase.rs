//! The showcase (placeholder until the showcase work lands).
fn main() {}
