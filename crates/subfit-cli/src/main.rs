//! The `subfit` command-line tool.
fn main() {}
