//! One `subfit` command run as a user runs it: a child process of the `subfit` executable with
//! its exit code, wall time and peak memory, killed when it outlives its time limit.
//!
//! Peak memory is the child's `VmHWM` (its resident high-water mark, Linux `/proc`), read every
//! [`POLL`] while it runs: the figure misses only growth within the last poll before it exits.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// How often a running child is looked at (exit, peak memory, time limit).
pub const POLL: Duration = Duration::from_millis(10);

/// How a child ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Exit {
    /// It exited with this code (0 success, 1 tolerance not reached, 2 bad input, …).
    Code(i32),
    /// It was killed at the time limit.
    Timeout,
    /// It died of a signal (a crash).
    Signal,
}

impl Exit {
    /// The short form used in tables: the code, `timeout` or `crash`.
    pub fn label(self) -> String {
        match self {
            Exit::Code(c) => c.to_string(),
            Exit::Timeout => "timeout".into(),
            Exit::Signal => "crash".into(),
        }
    }

    /// Whether outputs can be expected (exit 0 or 1: a fit was written).
    pub fn wrote(self) -> bool {
        matches!(self, Exit::Code(0) | Exit::Code(1))
    }
}

/// What a child run measured.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Run {
    /// How it ended.
    pub exit: Exit,
    /// Wall time, seconds.
    pub seconds: f64,
    /// Peak resident memory in MiB, when the platform tells.
    pub peak_memory_mb: Option<f64>,
    /// The last lines of its standard error (for the table's notes).
    pub stderr_tail: String,
}

/// The `subfit` executable and how to run it.
#[derive(Clone, Debug)]
pub struct Runner {
    /// The `subfit` executable.
    pub exe: PathBuf,
    /// Time limit of one run.
    pub timeout: Duration,
    /// Threads of each child (`RAYON_NUM_THREADS`); `None`: the child's default (all cores).
    pub threads: Option<usize>,
}

impl Runner {
    /// Runs `exe ARGS`, its standard output and error kept in `log_dir` (`stdout.txt`,
    /// `stderr.txt`). Errors: the executable cannot be started, or the logs not written.
    pub fn run(&self, args: &[String], log_dir: &Path) -> std::io::Result<Run> {
        std::fs::create_dir_all(log_dir)?;
        let stdout = std::fs::File::create(log_dir.join("stdout.txt"))?;
        let stderr_path = log_dir.join("stderr.txt");
        let stderr = std::fs::File::create(&stderr_path)?;
        let mut cmd = Command::new(&self.exe);
        cmd.args(args)
            .stdin(Stdio::null())
            .stdout(stdout)
            .stderr(stderr);
        if let Some(t) = self.threads {
            cmd.env("RAYON_NUM_THREADS", t.to_string());
        }
        let t0 = Instant::now();
        let mut child = cmd.spawn()?;
        let mut peak_kb: Option<u64> = None;
        let exit = loop {
            if let Some(kb) = high_water_kb(child.id()) {
                peak_kb = Some(peak_kb.map_or(kb, |p| p.max(kb)));
            }
            if let Some(status) = child.try_wait()? {
                break match status.code() {
                    Some(c) => Exit::Code(c),
                    None => Exit::Signal,
                };
            }
            if t0.elapsed() > self.timeout {
                // Already gone is fine: it ended between the look and the kill.
                let _ = child.kill();
                let _ = child.wait();
                break Exit::Timeout;
            }
            std::thread::sleep(POLL);
        };
        let seconds = t0.elapsed().as_secs_f64();
        let text = std::fs::read_to_string(&stderr_path).unwrap_or_default();
        Ok(Run {
            exit,
            seconds,
            peak_memory_mb: peak_kb.map(|kb| kb as f64 / 1024.0),
            stderr_tail: tail(&text, 6),
        })
    }
}

/// The last `n` non-empty lines of `text`.
pub fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// `VmHWM` of process `pid` in KiB (Linux); `None` elsewhere or once it has exited.
fn high_water_kb(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_keeps_the_last_lines() {
        assert_eq!(tail("a\n\nb\nc\n", 2), "b\nc");
        assert_eq!(tail("", 3), "");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_child_reports_its_exit_code_and_memory() {
        let dir = tempfile::tempdir().unwrap();
        let r = Runner {
            exe: "/bin/sh".into(),
            timeout: Duration::from_secs(600),
            threads: None,
        };
        let run = r
            .run(&["-c".into(), "echo oops >&2; exit 3".into()], dir.path())
            .unwrap();
        assert_eq!(run.exit, Exit::Code(3));
        assert_eq!(run.stderr_tail, "oops");
        assert!(!run.exit.wrote());
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_child_past_its_limit_is_killed() {
        let dir = tempfile::tempdir().unwrap();
        let r = Runner {
            exe: "/bin/sh".into(),
            timeout: Duration::ZERO,
            threads: Some(1),
        };
        let run = r
            .run(&["-c".into(), "sleep 600".into()], dir.path())
            .unwrap();
        assert_eq!(run.exit, Exit::Timeout);
        assert_eq!(run.exit.label(), "timeout");
    }
}
