//! Progress bars on stderr (hidden automatically when stderr is not a terminal) and file
//! reading with progress.

use std::io::Read;
use std::path::Path;
use std::sync::OnceLock;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Files smaller than this are read without a bar.
const BAR_THRESHOLD: u64 = 8 << 20;

/// Environment variable: when set (to anything but empty or `0`), the start of every phase is
/// printed on stderr as `subfit: phase: NAME`, for tests and scripts that need to know where a
/// run is (e.g. to interrupt it in a given phase).
pub const PHASE_LOG_ENV: &str = "SUBFIT_PHASE_LOG";

/// Environment variable for tests of the interruption: `SUBFIT_INTERRUPT_AT=PHASE[:SIGNAL]`
/// makes the run send itself `SIGNAL` (`INT`, the default, `TERM` or `HUP`) when the phase
/// named `PHASE` starts (the names [`PHASE_LOG_ENV`] prints), and go on once the signal handler
/// has cancelled the run ([`crate::interrupt::raise`]): the whole signal path, from the
/// handler to the exit code and the clean-up, at a known step and with no timing.
pub const INTERRUPT_AT_ENV: &str = "SUBFIT_INTERRUPT_AT";

/// Announces the start of a phase (see [`PHASE_LOG_ENV`], [`INTERRUPT_AT_ENV`]); spinners and
/// bars call it.
pub fn phase(name: &str) {
    static ON: OnceLock<bool> = OnceLock::new();
    static AT: OnceLock<Option<(String, String)>> = OnceLock::new();
    let on = *ON
        .get_or_init(|| std::env::var_os(PHASE_LOG_ENV).is_some_and(|v| !v.is_empty() && v != "0"));
    if on {
        eprintln!("subfit: phase: {name}");
    }
    let at = AT.get_or_init(|| {
        let v = std::env::var(INTERRUPT_AT_ENV)
            .ok()
            .filter(|v| !v.is_empty())?;
        let (phase, signal) = v.rsplit_once(':').unwrap_or((&v, "INT"));
        Some((phase.to_string(), signal.to_string()))
    });
    if let Some((phase, signal)) = at {
        if phase == name {
            crate::interrupt::raise(signal);
        }
    }
}

/// A spinner with a message, on stderr.
pub fn spinner(msg: &str) -> ProgressBar {
    phase(msg);
    let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    pb.set_style(
        ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("valid template"),
    );
    pb.set_message(msg.to_string());
    pb.enable_steady_tick(Duration::from_millis(120));
    pb
}

/// A bar counting `len` items, on stderr.
pub fn bar(len: u64, msg: &str) -> ProgressBar {
    phase(msg);
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    pb.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} [{elapsed}<{eta}]")
            .expect("valid template")
            .progress_chars("=> "),
    );
    pb.set_message(msg.to_string());
    pb
}

/// Reads a whole file, with a byte progress bar for large files.
pub fn read_with_progress(path: &Path) -> Result<Vec<u8>, subfit::io::Error> {
    use subfit::io::{Error, ErrorKind};
    if path.is_dir() {
        return Err(Error::file(path, ErrorKind::IsDirectory));
    }
    let io = |e| Error::file(path, ErrorKind::Io(e));
    let file = std::fs::File::open(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    if len < BAR_THRESHOLD {
        return subfit::io::read_all(path);
    }
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    pb.set_style(
        ProgressStyle::with_template(
            "reading {msg} [{bar:40}] {bytes}/{total_bytes} ({bytes_per_sec})",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    pb.set_message(path.display().to_string());
    let mut buf = Vec::with_capacity(len as usize);
    pb.wrap_read(file).read_to_end(&mut buf).map_err(io)?;
    pb.finish_and_clear();
    Ok(buf)
}

/// Reads and parses a mesh or point-cloud file, with progress for large files; the reader's
/// warnings are printed on stderr.
pub fn load(
    path: &Path,
) -> Result<(subfit::mesh::PolyMesh, subfit::io::FileInfo), subfit::io::Error> {
    let bytes = read_with_progress(path)?;
    let sp = (bytes.len() as u64 >= BAR_THRESHOLD).then(|| spinner("parsing"));
    let out = subfit::io::read_bytes(&bytes, path, &subfit::io::ReadOptions::default());
    if let Some(sp) = sp {
        sp.finish_and_clear();
    }
    if let Ok((_, info)) = &out {
        print_read_warnings(path, &info.warnings);
    }
    out
}

/// Prints what a reader decided about a file it read ([`subfit::io::FileInfo::warnings`]) on
/// stderr, one `subfit: warning: FILE: …` line each.
pub fn print_read_warnings(path: &Path, warnings: &[String]) {
    for w in warnings {
        eprintln!("subfit: warning: {}: {w}", path.display());
    }
}
