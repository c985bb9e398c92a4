//! Benchmark of target construction and foot-point queries (being written).
fn main() {}
