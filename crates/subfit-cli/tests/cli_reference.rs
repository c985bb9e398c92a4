//! docs/cli.md is the command-line reference generated from the clap definitions
//! (`subfit help-markdown`, clap-markdown): it must match them, and every subcommand's usage
//! line printed by `--help` must be in it. Shell completions come from the same definitions.

mod common;

use std::path::Path;

use common::subfit;

const REGENERATE: &str = "cargo run -p subfit-cli -- help-markdown > docs/cli.md";

fn reference() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/cli.md");
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}; regenerate it with `{REGENERATE}`", path.display()))
}

fn stdout(args: &[&str]) -> String {
    let r = subfit(args);
    assert!(r.status.success(), "subfit {args:?}: {r:?}");
    String::from_utf8(r.stdout).unwrap()
}

#[test]
fn docs_cli_md_is_the_generated_reference() {
    let generated = stdout(&["help-markdown"]);
    let committed = reference();
    if generated.trim_end() != committed.trim_end() {
        let line = generated
            .lines()
            .zip(committed.lines())
            .position(|(a, b)| a != b)
            .map_or_else(|| "the end".to_string(), |i| format!("line {}", i + 1));
        panic!(
            "docs/cli.md differs from the clap definitions (first at {line}); regenerate it with `{REGENERATE}`"
        );
    }
}

#[test]
fn every_usage_line_of_help_is_in_the_reference() {
    let committed = reference();
    let commands: &[&[&str]] = &[
        &[],
        &["info"],
        &["convert"],
        &["demo"],
        &["subdivide"],
        &["analyze"],
        &["eval"],
        &["fit"],
        &["init"],
        &["compare"],
        &["sequence"],
        &["bench", "convergence"],
        &["bench", "fit"],
        &["bench", "sequence"],
        &["bench", "corpus"],
        &["completions"],
    ];
    for c in commands {
        let help = stdout(&[*c, &["--help"][..]].concat());
        let usage = help
            .lines()
            .find_map(|l| l.strip_prefix("Usage: "))
            .unwrap_or_else(|| panic!("no usage line in `subfit {c:?} --help`"));
        assert!(
            committed.contains(&format!("**Usage:** `{usage}`")),
            "docs/cli.md lacks `{usage}`; regenerate it with `{REGENERATE}`"
        );
        // Every long flag --help lists is documented.
        for flag in help.split_whitespace().filter(|w| w.starts_with("--")) {
            let flag = flag.trim_end_matches([',', '.', ')', '`']);
            if flag.len() > 2 && flag != "--help" && flag != "--version" {
                assert!(
                    committed.contains(flag),
                    "docs/cli.md lacks {flag} (subfit {c:?})"
                );
            }
        }
    }
}

#[test]
fn completions_are_generated_for_bash_zsh_and_fish() {
    for shell in ["bash", "zsh", "fish"] {
        let script = stdout(&["completions", shell]);
        for word in ["subfit", "fit", "limit-quads", "json", "sequence"] {
            assert!(script.contains(word), "{shell} completions lack {word}");
        }
    }
    let r = subfit(&["completions", "tcsh"]);
    assert_eq!(
        r.status.code(),
        Some(2),
        "an unknown shell is a usage error"
    );
}
