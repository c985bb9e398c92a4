//! README.md's scoreboard summary is the committed baseline's, not figures typed by hand: the
//! "Per category" table of `bench/corpus-baseline.md` appears in README.md as it is.

use std::path::Path;

/// The lines of the Markdown table that follows `heading` in `text`.
fn table_after<'a>(text: &'a str, heading: &str) -> Vec<&'a str> {
    text.lines()
        .skip_while(|l| l.trim() != heading)
        .skip(1)
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .collect()
}

#[test]
fn readme_shows_the_baselines_per_category_summary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let baseline = std::fs::read_to_string(root.join("bench/corpus-baseline.md"))
        .expect("bench/corpus-baseline.md is committed");
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let table = table_after(&baseline, "## Per category");
    assert!(
        table.len() > 2,
        "no per-category table in bench/corpus-baseline.md"
    );
    let block = table.join("\n");
    assert!(
        readme.contains(&block),
        "README.md's scoreboard summary is not the baseline's: copy the \"Per category\" table of \
         bench/corpus-baseline.md into README.md's Scoreboard section\n{block}"
    );
}
