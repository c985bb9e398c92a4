#![no_main]
//! Feeds arbitrary bytes to the stl reader: it must return Ok or Err, never panic.

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use subfit_io::{read_bytes, Format, ReadOptions};

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions {
        format: Some(Format::Stl),
        ..ReadOptions::default()
    };
    if let Ok((mesh, _)) = read_bytes(data, Path::new("fuzz.stl"), &opts) {
        // Whatever is accepted must be internally consistent.
        let n = mesh.positions.len();
        assert!(mesh.faces.indices().iter().all(|&i| (i as usize) < n));
        assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
    }
});
