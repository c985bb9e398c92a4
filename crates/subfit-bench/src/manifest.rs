//! What a corpus holds: the entries of a `manifest.tsv` (one row per file, one per sequence;
//! categories scan, open, range, cad, cage, seq, refused), or of a plain folder of model files.
//!
//! A plain folder needs no manifest: every model file in it is fitted with defaults (category
//! `folder`); a sub-folder with a `control.*` and a `dense.*` is a cage pair, any other sub-folder
//! of model files a sequence (its files in name order). Nothing here is keyed to a file's name
//! beyond those two conventions.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use subfit::io::Format;

/// What is done with an entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "job", rename_all = "kebab-case")]
pub enum Job {
    /// `subfit fit INPUT` with defaults: a mesh or a point cloud.
    Fit {
        /// The model file.
        input: PathBuf,
    },
    /// A given cage and the dense mesh it stands for: `subfit fit DENSE` at the cage's count in
    /// the cage's scheme, judged next to the given cage.
    CagePair {
        /// The given cage (an artist's).
        control: PathBuf,
        /// The dense mesh (the cage subdivided).
        dense: PathBuf,
    },
    /// `subfit sequence FRAME...`: one cage for every frame.
    Sequence {
        /// The frames in order.
        frames: Vec<PathBuf>,
    },
    /// A file variant: only read, its counts checked against the manifest's.
    Read {
        /// The file.
        input: PathBuf,
    },
}

/// One row of the scoreboard to be: what to run and what the manifest says of the input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// A name unique in the corpus (the file's path without extension, `/` as `-`).
    pub name: String,
    /// The category (`scan`, `open`, `range`, `cad`, `cage`, `seq`, `refused`, or `folder`).
    pub category: String,
    /// What is done with it.
    pub job: Job,
    /// Vertices (points) of the input as the manifest counts them (for a plain folder: `None`).
    pub vertices: Option<usize>,
    /// Faces of the input as the manifest counts them.
    pub faces: Option<usize>,
    /// The input's genus, when the manifest gives one.
    pub genus: Option<u32>,
    /// The input's boundary loops, when the manifest gives them.
    pub boundary_loops: Option<usize>,
    /// Size of the input in bytes (the sum over a pair's or a sequence's files): the order of
    /// the quick subset when no vertex count is known.
    pub bytes: u64,
}

impl Entry {
    /// The size the quick subset orders by: the manifest's vertex count, else the bytes.
    pub fn size_key(&self) -> u64 {
        self.vertices.map_or(self.bytes, |v| v as u64)
    }
}

/// Why a corpus could not be listed.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// The folder or a file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A row of `manifest.tsv` is malformed.
    #[error("{path}: line {line}: {what}")]
    Row {
        /// The manifest.
        path: PathBuf,
        /// Its line (1-based).
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// Nothing to run.
    #[error("{0}: no model files (PLY, OBJ, OFF, STL, XYZ/PTS/TXT) and no manifest.tsv")]
    Empty(PathBuf),
}

/// The entries of `dir`: its `manifest.tsv` when there is one, else its model files.
///
/// Errors: an unreadable folder, a malformed manifest row, or nothing to run.
pub fn load(dir: &Path) -> Result<Vec<Entry>, ManifestError> {
    let manifest = dir.join("manifest.tsv");
    let entries = if manifest.is_file() {
        from_manifest(dir, &manifest)?
    } else {
        from_folder(dir)?
    };
    if entries.is_empty() {
        return Err(ManifestError::Empty(dir.to_path_buf()));
    }
    Ok(entries)
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ManifestError + '_ {
    move |source| ManifestError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn entry_name(rel: &str) -> String {
    let stem = rel.trim_end_matches('/');
    let stem = match stem.rsplit_once('.') {
        Some((s, ext)) if !ext.contains('/') => s,
        _ => stem,
    };
    stem.replace('/', "-")
}

fn file_bytes(paths: &[&Path]) -> u64 {
    paths
        .iter()
        .filter_map(|p| std::fs::metadata(p).ok())
        .map(|m| m.len())
        .sum()
}

fn parse_count(s: &str) -> Option<usize> {
    s.trim().parse().ok()
}

/// Column positions of the manifest's header.
struct Columns {
    file: usize,
    category: usize,
    vertices: Option<usize>,
    faces: Option<usize>,
    loops: Option<usize>,
    genus: Option<usize>,
}

impl Columns {
    fn of(header: &str, path: &Path) -> Result<Self, ManifestError> {
        let names: Vec<&str> = header.split('\t').map(str::trim).collect();
        let find = |n: &str| names.iter().position(|c| *c == n);
        let need = |n: &str| {
            find(n).ok_or_else(|| ManifestError::Row {
                path: path.to_path_buf(),
                line: 1,
                what: format!("the header has no `{n}` column"),
            })
        };
        Ok(Self {
            file: need("file")?,
            category: need("category")?,
            vertices: find("vertices"),
            faces: find("faces"),
            loops: find("loops"),
            genus: find("genus"),
        })
    }
}

/// A cage pair's rows as they are read: its control cage, its dense mesh, the entry.
type PairRows = (Option<PathBuf>, Option<PathBuf>, Option<Entry>);

fn from_manifest(dir: &Path, path: &Path) -> Result<Vec<Entry>, ManifestError> {
    let text = std::fs::read_to_string(path).map_err(io(path))?;
    let mut lines = text.lines();
    let cols = Columns::of(lines.next().unwrap_or(""), path)?;
    let mut entries = Vec::new();
    // Cage pairs come as two rows (`NAME/control.*`, `NAME/dense.*`): gathered by folder.
    let mut pairs: BTreeMap<String, PairRows> = BTreeMap::new();
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split('\t').collect();
        let get = |c: Option<usize>| c.and_then(|c| f.get(c)).copied().unwrap_or("");
        let file = get(Some(cols.file)).trim();
        let category = get(Some(cols.category)).trim().to_string();
        if file.is_empty() || category.is_empty() {
            return Err(ManifestError::Row {
                path: path.to_path_buf(),
                line: i + 2,
                what: "no file or no category".into(),
            });
        }
        let mut entry = Entry {
            name: entry_name(file.split_whitespace().next().unwrap_or(file)),
            category: category.clone(),
            job: Job::Read {
                input: dir.join(file),
            },
            vertices: parse_count(get(cols.vertices)),
            faces: parse_count(get(cols.faces)),
            genus: get(cols.genus).trim().parse().ok(),
            boundary_loops: parse_count(get(cols.loops)),
            bytes: 0,
        };
        let rel = file.split_whitespace().next().unwrap_or(file);
        let full = dir.join(rel);
        if full.is_dir() {
            let frames = model_files(&full)?;
            entry.bytes = file_bytes(&frames.iter().map(PathBuf::as_path).collect::<Vec<_>>());
            entry.job = Job::Sequence { frames };
            entries.push(entry);
            continue;
        }
        entry.bytes = file_bytes(&[&full]);
        match category.as_str() {
            "refused" => entry.job = Job::Read { input: full },
            "cage" => {
                let folder = rel.rsplit_once('/').map_or(rel, |(d, _)| d).to_string();
                let slot = pairs.entry(folder.clone()).or_default();
                let stem = full.file_stem().and_then(|s| s.to_str()).unwrap_or("");
                if stem == "control" {
                    slot.0 = Some(full);
                    entry.name = entry_name(&folder);
                    slot.2 = Some(entry);
                } else {
                    slot.1 = Some(full);
                }
                continue;
            }
            _ => entry.job = Job::Fit { input: full },
        }
        entries.push(entry);
    }
    for (folder, (control, dense, entry)) in pairs {
        match (control, dense, entry) {
            (Some(control), Some(dense), Some(mut entry)) => {
                entry.bytes = file_bytes(&[&control, &dense]);
                entry.job = Job::CagePair { control, dense };
                entries.push(entry);
            }
            _ => {
                return Err(ManifestError::Row {
                    path: path.to_path_buf(),
                    line: 0,
                    what: format!("cage pair `{folder}` needs a control.* and a dense.* row"),
                })
            }
        }
    }
    Ok(entries)
}

fn is_model(p: &Path) -> bool {
    p.is_file() && Format::from_path(p).is_some()
}

/// The model files directly in `dir`, in name order.
fn model_files(dir: &Path) -> Result<Vec<PathBuf>, ManifestError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io(dir))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_model(p))
        .collect();
    files.sort();
    Ok(files)
}

fn from_folder(dir: &Path) -> Result<Vec<Entry>, ManifestError> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io(dir))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    paths.sort();
    let mut entries = Vec::new();
    for p in paths {
        let name = p
            .file_name()
            .map(|n| entry_name(&n.to_string_lossy()))
            .unwrap_or_default();
        let blank = |category: &str, job: Job, bytes: u64| Entry {
            name: name.clone(),
            category: category.into(),
            job,
            vertices: None,
            faces: None,
            genus: None,
            boundary_loops: None,
            bytes,
        };
        if is_model(&p) {
            let bytes = file_bytes(&[&p]);
            entries.push(blank("folder", Job::Fit { input: p }, bytes));
        } else if p.is_dir() {
            let files = model_files(&p)?;
            let stem = |f: &PathBuf, s: &str| f.file_stem().is_some_and(|x| x == s);
            let control = files.iter().find(|f| stem(f, "control")).cloned();
            let dense = files.iter().find(|f| stem(f, "dense")).cloned();
            let bytes = file_bytes(&files.iter().map(PathBuf::as_path).collect::<Vec<_>>());
            match (control, dense) {
                (Some(control), Some(dense)) => {
                    entries.push(blank("cage", Job::CagePair { control, dense }, bytes))
                }
                _ if files.len() >= 2 => {
                    entries.push(blank("seq", Job::Sequence { frames: files }, bytes))
                }
                _ => {}
            }
        }
    }
    Ok(entries)
}

/// The quick subset: a fixed, small part of every category, chosen by size alone (no entry is
/// named): the two smallest inputs of each fitted category, the smallest cage pair, the
/// smallest sequence cut to its first [`QUICK_FRAMES`] frames, and every read check (reading is
/// cheap).
pub fn quick(entries: &[Entry]) -> Vec<Entry> {
    let mut by_category: BTreeMap<&str, Vec<&Entry>> = BTreeMap::new();
    for e in entries {
        by_category.entry(&e.category).or_default().push(e);
    }
    let mut out = Vec::new();
    for (_, mut list) in by_category {
        list.sort_by_key(|e| (e.size_key(), e.name.clone()));
        let take = match list[0].job {
            Job::Read { .. } => list.len(),
            Job::CagePair { .. } | Job::Sequence { .. } => 1,
            Job::Fit { .. } => 2,
        };
        for e in list.into_iter().take(take) {
            let mut e = e.clone();
            if let Job::Sequence { frames } = &mut e.job {
                frames.truncate(QUICK_FRAMES);
            }
            out.push(e);
        }
    }
    out
}

/// Frames of the quick subset's sequence.
pub const QUICK_FRAMES: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_drop_the_extension_and_join_folders() {
        assert_eq!(entry_name("scan-pepper.ply"), "scan-pepper");
        assert_eq!(entry_name("refused/off-binary.off"), "refused-off-binary");
        assert_eq!(entry_name("seq-lion/"), "seq-lion");
        assert_eq!(entry_name("cage-bob"), "cage-bob");
    }

    #[test]
    fn a_manifest_gives_fits_pairs_sequences_and_reads() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for f in ["a.ply", "b.obj", "r.off"] {
            std::fs::write(d.join(f), "x").unwrap();
        }
        std::fs::create_dir_all(d.join("cage-x")).unwrap();
        std::fs::write(d.join("cage-x/control.obj"), "x").unwrap();
        std::fs::write(d.join("cage-x/dense.obj"), "xx").unwrap();
        std::fs::create_dir_all(d.join("seq-y")).unwrap();
        for f in ["f2.obj", "f1.obj", "notes.txt.bak"] {
            std::fs::write(d.join("seq-y").join(f), "x").unwrap();
        }
        std::fs::write(
            d.join("manifest.tsv"),
            "file\tcategory\tvertices\tfaces\tloops\tgenus\n\
             a.ply\tscan\t10\t16\t0\t0\n\
             b.obj\tscan\t5\t6\t0\t1\n\
             cage-x/control.obj\tcage\t8\t6\t0\t0\n\
             cage-x/dense.obj\tcage\t98\t96\t0\t0\n\
             seq-y/ (2 frames)\tseq\t4\t4\tn/a\tn/a\n\
             r.off\trefused\t3\t1\t1\t0\n",
        )
        .unwrap();
        let e = load(d).unwrap();
        let names: Vec<&str> = e.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "seq-y", "r", "cage-x"]);
        assert!(matches!(e[0].job, Job::Fit { .. }));
        assert_eq!((e[1].vertices, e[1].genus), (Some(5), Some(1)));
        match &e[2].job {
            Job::Sequence { frames } => {
                let n: Vec<_> = frames.iter().map(|f| f.file_name().unwrap()).collect();
                assert_eq!(n, ["f1.obj", "f2.obj"]);
            }
            j => panic!("{j:?}"),
        }
        assert!(matches!(e[3].job, Job::Read { .. }));
        assert!(matches!(e[4].job, Job::CagePair { .. }));
        assert_eq!(e[4].vertices, Some(8));
        let q = quick(&e);
        let names: Vec<&str> = q.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["cage-x", "r", "b", "a", "seq-y"]);
    }

    #[test]
    fn a_plain_folder_fits_every_model_file() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("m.stl"), "x").unwrap();
        std::fs::write(d.join("readme.md"), "x").unwrap();
        std::fs::create_dir_all(d.join("pair")).unwrap();
        std::fs::write(d.join("pair/control.obj"), "x").unwrap();
        std::fs::write(d.join("pair/dense.ply"), "x").unwrap();
        let e = load(d).unwrap();
        assert_eq!(e.len(), 2);
        assert_eq!(
            (e[0].name.as_str(), e[0].category.as_str()),
            ("m", "folder")
        );
        assert!(matches!(e[1].job, Job::CagePair { .. }));
        let empty = tempfile::tempdir().unwrap();
        assert!(matches!(load(empty.path()), Err(ManifestError::Empty(_))));
    }
}
