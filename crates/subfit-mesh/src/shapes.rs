//! Generated shapes for the demo, tests and benchmarks (placeholder until implemented).
