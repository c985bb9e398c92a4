//! Interrupted runs (Ctrl-C, SIGTERM, SIGHUP) leave no partial output.
//!
//! Every file is written to a temporary name beside its destination and renamed
//! ([`subfit::io::write_atomic`]), so an interruption can only leave such a temporary file, or,
//! for `subfit fit`, a staging directory holding a complete set of outputs not yet moved into
//! place. The commands register where they write ([`watch_dir`], [`Staging`]); the signal handler
//! removes this process's temporary files there and the staging directories, then exits with
//! code 130 (128 + SIGINT, as shells report an interrupted command).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// What the handler cleans up.
enum Watched {
    /// Temporary files of this process (`.NAME.PID.tmp`) in a directory.
    TempFilesIn(PathBuf),
    /// A staging directory, removed whole.
    Staging(PathBuf),
}

static WATCHED: Mutex<Vec<Watched>> = Mutex::new(Vec::new());

/// Exit code of an interrupted run.
pub const EXIT_INTERRUPTED: i32 = 130;

/// Installs the handler (once, at start-up). Failure to install (e.g. a handler already set)
/// only loses the clean-up, so it is ignored.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        clean_up();
        eprintln!("subfit: interrupted; no partial output left");
        std::process::exit(EXIT_INTERRUPTED);
    });
}

fn watched() -> std::sync::MutexGuard<'static, Vec<Watched>> {
    // A panic while holding the lock cannot leave the list inconsistent: keep using it.
    WATCHED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Registers the directory that `path` (a file about to be written) lives in: on interruption,
/// this process's temporary files there are removed.
pub fn watch_dir(path: &Path) {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut w = watched();
    if !w
        .iter()
        .any(|x| matches!(x, Watched::TempFilesIn(d) if *d == dir))
    {
        w.push(Watched::TempFilesIn(dir));
    }
}

/// Removes everything registered (called by the handler; also used by tests).
fn clean_up() {
    let suffix = format!(".{}.tmp", std::process::id());
    for w in watched().iter() {
        match w {
            Watched::Staging(d) => {
                let _ = std::fs::remove_dir_all(d);
            }
            Watched::TempFilesIn(d) => {
                let Ok(entries) = std::fs::read_dir(d) else {
                    continue;
                };
                for e in entries.flatten() {
                    let name = e.file_name();
                    let name = name.to_string_lossy();
                    if name.starts_with('.') && name.ends_with(&suffix) {
                        let _ = std::fs::remove_file(e.path());
                    }
                }
            }
        }
    }
}

/// A hidden directory inside an output directory where a set of outputs is written before
/// being moved into place together ([`Staging::commit`]); removed on interruption or drop.
pub struct Staging {
    dir: PathBuf,
    out: PathBuf,
}

impl Staging {
    /// Creates `OUT/.subfit-PID/` (and `OUT` if needed) and registers it.
    pub fn new(out: &Path) -> std::io::Result<Self> {
        let dir = out.join(format!(".subfit-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        watched().push(Watched::Staging(dir.clone()));
        Ok(Self {
            dir,
            out: out.to_path_buf(),
        })
    }

    /// Where to write the output `name` for now.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Moves the staged files `names` into the output directory (one rename each, in order)
    /// and removes the staging directory.
    pub fn commit(self, names: &[&str]) -> std::io::Result<()> {
        for n in names {
            std::fs::rename(self.dir.join(n), self.out.join(n))?;
        }
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
        watched().retain(|w| !matches!(w, Watched::Staging(d) if *d == self.dir));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clean_up_removes_only_this_process_temporaries_and_commit_moves_staged_files() {
        let d = tempfile::tempdir().unwrap();
        let pid = std::process::id();
        let ours = d.path().join(format!(".limit.ply.{pid}.tmp"));
        let other = d
            .path()
            .join(format!(".limit.ply.{}.tmp", pid.wrapping_add(1)));
        let kept = d.path().join("limit.ply");
        for f in [&ours, &other, &kept] {
            std::fs::write(f, b"x").unwrap();
        }
        watch_dir(&kept);
        let s = Staging::new(&d.path().join("out")).unwrap();
        std::fs::write(s.path("report.json"), b"{}").unwrap();
        let staged = s.path("");
        clean_up();
        assert!(!ours.exists());
        assert!(other.exists() && kept.exists());
        assert!(!staged.exists());
        drop(s);
        watched().clear();

        // One test only: the registry is process-wide, and a parallel test's clean-up would
        // remove this staging directory.
        let d = tempfile::tempdir().unwrap();
        let s = Staging::new(d.path()).unwrap();
        std::fs::write(s.path("a"), b"1").unwrap();
        std::fs::write(s.path("b"), b"2").unwrap();
        let staged = s.path("");
        s.commit(&["a", "b"]).unwrap();
        assert_eq!(std::fs::read(d.path().join("a")).unwrap(), b"1");
        assert_eq!(std::fs::read(d.path().join("b")).unwrap(), b"2");
        assert!(!staged.exists());
    }
}
