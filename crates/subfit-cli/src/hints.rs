//! Hints for common mistakes in what a user typed: a path with a typo gets the nearest file
//! name of the same folder ("no such file; did you mean X?").

use std::path::{Path, PathBuf};

/// Least similarity (normalized Damerau-Levenshtein, 1 = equal) of two names' stems (of the
/// whole names when their extensions differ) for one to be suggested: 0.6 accepts a character
/// or two wrong in a short name (`bunyy` for `bunny`: 0.8; `armadilo` for `armadillo`: 0.89)
/// and refuses unrelated names (`lucy` for `bunny`: 0.2).
const MIN_SIMILARITY: f64 = 0.6;

/// How near `other` is to the name typed, in `[0, 1]`: 1 for the same stem in any case (the
/// wrong extension, `Bunny.PLY`), else the similarity of the stems when the extensions agree,
/// of the whole names when not.
fn similarity(typed: &Path, other: &Path) -> f64 {
    let stem = |p: &Path| p.file_stem().map(|s| s.to_string_lossy().to_lowercase());
    let ext = |p: &Path| p.extension().map(|s| s.to_string_lossy().to_lowercase());
    let (a, b) = (
        stem(typed).unwrap_or_default(),
        stem(other).unwrap_or_default(),
    );
    if a == b {
        1.0
    } else if ext(typed) == ext(other) {
        strsim::normalized_damerau_levenshtein(&a, &b)
    } else {
        let name = |p: &Path| p.file_name().map(|s| s.to_string_lossy().to_lowercase());
        strsim::normalized_damerau_levenshtein(
            &name(typed).unwrap_or_default(),
            &name(other).unwrap_or_default(),
        )
    }
}

/// The file of `path`'s folder whose name is nearest to `path`'s, if one is near enough
/// ([`MIN_SIMILARITY`]).
pub fn did_you_mean(path: &Path) -> Option<PathBuf> {
    path.file_name()?;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut best: Option<(f64, PathBuf)> = None;
    for entry in std::fs::read_dir(folder).ok()?.flatten() {
        if !entry.file_type().is_ok_and(|t| t.is_file()) {
            continue;
        }
        let other = path.with_file_name(entry.file_name());
        let score = similarity(path, &other);
        if score >= MIN_SIMILARITY && best.as_ref().is_none_or(|(b, _)| score > *b) {
            best = Some((score, other));
        }
    }
    best.map(|(_, p)| p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_typo_finds_the_file_and_an_unrelated_name_does_not() {
        let d = tempfile::tempdir().unwrap();
        for f in ["bunny.ply", "igea.ply", "armadillo.obj"] {
            std::fs::write(d.path().join(f), b"").unwrap();
        }
        let near =
            |n: &str| did_you_mean(&d.path().join(n)).map(|p| p.file_name().unwrap().to_owned());
        assert_eq!(near("bunyy.ply").unwrap(), "bunny.ply");
        assert_eq!(near("Igea.PLY").unwrap(), "igea.ply");
        assert_eq!(near("armadilo.obj").unwrap(), "armadillo.obj");
        assert_eq!(near("bunny.obj").unwrap(), "bunny.ply");
        assert_eq!(near("lucy.ply"), None);
        assert_eq!(near("x"), None);
    }
}
