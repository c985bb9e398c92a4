//! No function over 150 lines in the crates' library sources (STYLE.md: a function reads in
//! one sitting); the checker is `tools/long_functions.py`, which names them when run alone.

#![allow(clippy::print_stderr)] // a skipped test says so

use std::path::PathBuf;
use std::process::{Command, Output};

fn checker(args: &[&std::ffi::OsStr]) -> Option<Output> {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tools/long_functions.py");
    match Command::new("python3").arg(&script).args(args).output() {
        Ok(out) => Some(out),
        Err(e) if std::env::var("CI").is_ok_and(|v| v == "true") => {
            panic!("python3 is needed to run {}: {e}", script.display())
        }
        Err(e) => {
            eprintln!("skipped: python3 could not be run ({e})");
            None
        }
    }
}

#[test]
fn no_function_is_over_150_lines() {
    let Some(out) = checker(&[]) else { return };
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "functions over 150 lines:\n{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("0 function(s) over 150 lines"), "{text}");
}

#[test]
fn the_checker_counts_from_fn_to_its_brace() {
    // A 6-line function with a `;` in its signature and braces in a string and a comment, a
    // declaration without a body, and a long function inside a test module (not counted).
    let dir = std::env::temp_dir().join(format!("subfit-long-fns-{}", std::process::id()));
    let src = dir.join("src");
    std::fs::create_dir_all(&src).unwrap();
    let long_test = format!(
        "#[cfg(test)]\nmod tests {{\n    fn long() {{\n{}    }}\n}}\n",
        "        let _ = 1;\n".repeat(20)
    );
    std::fs::write(
        src.join("lib.rs"),
        format!(
            "pub fn six(a: [f64; 3]) -> f64 {{\n    // }} not a brace\n    let s = \"}}\";\n    \
             let _ = s;\n    a[0]\n}}\npub trait T {{\n    fn declared(&self);\n}}\n{long_test}"
        ),
    )
    .unwrap();
    let (over5, over6) = (
        checker(&["--max".as_ref(), "5".as_ref(), dir.as_os_str()]),
        checker(&["--max".as_ref(), "6".as_ref(), dir.as_os_str()]),
    );
    std::fs::remove_dir_all(&dir).ok();
    let (Some(over5), Some(over6)) = (over5, over6) else {
        return;
    };
    let text5 = String::from_utf8_lossy(&over5.stdout);
    assert!(!over5.status.success(), "{text5}");
    assert!(text5.contains("6 ") && text5.contains(":1 six"), "{text5}");
    assert!(text5.contains("1 function(s) over 5 lines"), "{text5}");
    let text6 = String::from_utf8_lossy(&over6.stdout);
    assert!(over6.status.success(), "{text6}");
}
