//! No import circles between the files of any crate (STYLE.md rule 7; the checker is
//! `tools/import_cycles.py`, which names them when run alone).

#![allow(clippy::print_stderr)] // a skipped test says so

use std::path::PathBuf;
use std::process::Command;

#[test]
fn no_crate_has_import_circles() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let script = root.join("tools/import_cycles.py");
    let out = match Command::new("python3").arg(&script).output() {
        Ok(out) => out,
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("python3 is needed to run {}: {e}", script.display())
        }
        Err(e) => {
            eprintln!("skipped: python3 could not be run ({e})");
            return;
        }
    };
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "import circles:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("0 import circle(s)"), "{text}");
}

#[test]
fn the_checker_finds_a_circle() {
    // Two files that use each other, and a third used by both (no circle).
    let dir = std::env::temp_dir().join(format!("subfit-circles-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(&src).unwrap();
    std::fs::write(
        src.join("lib.rs"),
        "mod a;\nmod b;\nmod c;\npub use a::A;\n",
    )
    .unwrap();
    std::fs::write(
        src.join("a.rs"),
        "use crate::b::B;\nuse crate::c::C;\npub struct A(B, C);\n",
    )
    .unwrap();
    std::fs::write(
        src.join("b.rs"),
        "// crate::c::C in a comment is no edge\npub struct B;\npub fn f() -> Option<crate::A> { None }\n",
    )
    .unwrap();
    std::fs::write(src.join("c.rs"), "pub struct C;\n").unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tools/import_cycles.py");
    let Ok(out) = Command::new("python3").arg(&script).arg(&dir).output() else {
        eprintln!("skipped: python3 could not be run");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    std::fs::remove_dir_all(&dir).ok();
    assert!(!out.status.success(), "{text}");
    assert!(text.contains("circle of 2 modules: a, b"), "{text}");
    assert!(text.contains("1 import circle(s)"), "{text}");
}
