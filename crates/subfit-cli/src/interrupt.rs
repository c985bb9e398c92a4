//! Interrupted runs (Ctrl-C, SIGTERM, SIGHUP) stop within a second and leave no partial output.
//!
//! Every file is written to a temporary name beside its destination and renamed
//! ([`subfit::io::write_atomic`]), so an interruption can only leave such a temporary file, or,
//! for `subfit fit`, a staging directory holding outputs not yet moved into place. The commands
//! register where they write ([`watch_dir`], [`Staging`]).
//!
//! On a signal the handler cancels the process-wide [`token`], which the commands put into the
//! options of every long phase (target analysis, initial mesh, fitting): the phase returns its
//! `Interrupted` error, the command returns, and `main` calls [`conclude`], which removes this
//! process's temporary files and the staging directories and exits with code 130 (128 + SIGINT,
//! as shells report an interrupted command). As a safety net for a phase that does not poll the
//! token, the handler itself cleans up and exits 130 when the process is still there
//! [`GRACE`] after the signal.
//!
//! All of it is serialized by one lock over the registry: creating and registering a staging
//! directory, moving the staged outputs into place, and cleaning up then exiting each happen
//! while holding it, and the clean-up keeps it until the process is gone. So an interruption
//! sees a staging directory either not yet created or registered, and the outputs either all
//! moved or none; and once `main` has concluded a finished run, a late signal can no longer
//! remove anything.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Mutex, MutexGuard, OnceLock};
use std::time::Duration;

use subfit::mesh::Cancel;

/// What the handler cleans up.
enum Watched {
    /// Temporary files of this process (`.NAME.PID.tmp`) in a directory.
    TempFilesIn(PathBuf),
    /// A staging directory, removed whole.
    Staging(PathBuf),
}

static WATCHED: Mutex<Vec<Watched>> = Mutex::new(Vec::new());

static TOKEN: OnceLock<Cancel> = OnceLock::new();

/// Exit code of an interrupted run.
pub const EXIT_INTERRUPTED: i32 = 130;

/// How long after a signal the handler waits for the command to stop by itself before it cleans
/// up and exits on its own.
pub const GRACE: Duration = Duration::from_millis(500);

/// The process-wide cancellation token that the signal handler cancels; the commands put clones
/// of it into the options of their long phases.
pub fn token() -> Cancel {
    TOKEN.get_or_init(Cancel::new).clone()
}

/// Installs the handler (once, at start-up). Failure to install (e.g. a handler already set)
/// only loses the clean-up, so it is ignored.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        token().cancel();
        // The command normally notices within milliseconds and `main` exits through
        // `conclude`; this only runs on when a phase does not poll the token.
        std::thread::sleep(GRACE);
        exit_interrupted(watched(), " (the running step did not stop in time)");
    });
}

/// Sends `signal` (`INT`, `TERM` or `HUP`) to this process, as a user's Ctrl-C or `kill`
/// would, and returns once the handler has cancelled the [`token`] (or after 10 s at most,
/// when no handler is installed): used by [`crate::progress::INTERRUPT_AT_ENV`] so tests
/// interrupt a run at a named phase without racing it. Unix only (`kill`); elsewhere it does
/// nothing but say so.
pub fn raise(signal: &str) {
    let sent = std::process::Command::new("kill")
        .args([format!("-{signal}"), std::process::id().to_string()])
        .status()
        .is_ok_and(|s| s.success());
    if !sent {
        eprintln!("subfit: could not send SIG{signal} to itself (kill -{signal})");
        return;
    }
    // The handler runs on its own thread: wait for it, so the phase starts cancelled.
    let token = token();
    for _ in 0..10_000 {
        if token.is_cancelled() {
            return;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}

fn watched() -> MutexGuard<'static, Vec<Watched>> {
    // A panic while holding the lock cannot leave the list inconsistent: keep using it.
    WATCHED.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes everything registered and exits with [`EXIT_INTERRUPTED`], holding the registry
/// lock (`w`) until the process is gone. `how` completes the message on stderr.
fn exit_interrupted(w: MutexGuard<'static, Vec<Watched>>, how: &str) -> ! {
    clean_up(&w);
    eprintln!("subfit: interrupted{how}; no partial output left");
    std::process::exit(EXIT_INTERRUPTED);
}

/// Ends a run, given what the command returned: when the run was interrupted (the token is
/// cancelled) and the command failed, cleans up and exits 130; otherwise returns `result`,
/// keeping the registry locked for good, so that a signal arriving from now on waits for the
/// process to exit instead of removing finished outputs.
pub fn conclude(result: anyhow::Result<ExitCode>) -> anyhow::Result<ExitCode> {
    let w = watched();
    if token().is_cancelled() && result.is_err() {
        exit_interrupted(w, "");
    }
    std::mem::forget(w);
    result
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

/// Removes everything registered in `w`. A staging directory is first renamed (to
/// `.subfit-PID.removing` beside it), so that files the command may still be writing under the
/// old name cannot reappear in it while it is removed.
fn clean_up(w: &[Watched]) {
    let suffix = format!(".{}.tmp", std::process::id());
    for x in w {
        match x {
            Watched::Staging(d) => {
                let trash = d.with_extension("removing");
                let gone = if std::fs::rename(d, &trash).is_ok() {
                    &trash
                } else {
                    d
                };
                let _ = std::fs::remove_dir_all(gone);
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
    /// Creates `OUT/.subfit-PID/` (and `OUT` if needed) and registers it, both under the
    /// registry lock: an interruption sees it either registered or not created.
    pub fn new(out: &Path) -> std::io::Result<Self> {
        let dir = out.join(format!(".subfit-{}", std::process::id()));
        let mut w = watched();
        std::fs::create_dir_all(&dir)?;
        w.push(Watched::Staging(dir.clone()));
        Ok(Self {
            dir,
            out: out.to_path_buf(),
        })
    }

    /// Where to write the output `name` for now.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Moves the staged files `names` into the output directory (one rename each, in order) and
    /// removes the staging directory, under the registry lock: an interruption sees all of them
    /// moved or none. Refuses (an `Interrupted` I/O error, nothing moved) once the run has been
    /// interrupted.
    pub fn commit(self, names: &[&str]) -> std::io::Result<()> {
        let mut w = watched();
        if token().is_cancelled() {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "interrupted",
            ));
        }
        for n in names {
            std::fs::rename(self.dir.join(n), self.out.join(n))?;
        }
        let _ = std::fs::remove_dir_all(&self.dir);
        w.retain(|x| !matches!(x, Watched::Staging(d) if *d == self.dir));
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let mut w = watched();
        let _ = std::fs::remove_dir_all(&self.dir);
        w.retain(|x| !matches!(x, Watched::Staging(d) if *d == self.dir));
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
        clean_up(&watched());
        assert!(!ours.exists());
        assert!(other.exists() && kept.exists());
        assert!(!staged.exists());
        assert_eq!(std::fs::read_dir(d.path().join("out")).unwrap().count(), 0);
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
        assert!(watched().is_empty());
    }
}
