"""``subfit.fit`` from Python beside the CLI on Igea (Cheng 2007 Tab. IV settings, the row
``igea`` of ``subfit bench fit``): same file, same options, outputs written by both.

    python crates/subfit-py/bench/igea.py [--cli target/release/subfit] [--repeat 3]

Igea comes from ``$SUBFIT_DATA/igea.ply`` (default ``../shared/data`` beside the repository).
Runs alternate (CLI, Python, CLI, …) so both see the same machine load; the medians and their
ratio are printed with the cages' sizes and errors (which must agree). Wall-clock times of
whole runs: the CLI's include process start and reading the file, Python's include
``subfit.fit(path)`` (it reads the file natively) and ``Fit.save``.

Measured 2026-12-02 (2 cores shared with another build, load 4–7; release builds of both):
CLI 23.27 / 23.46 / 25.13 s, Python 19.64 / 21.03 / 26.31 s (fit alone 18.93 / 20.24 /
25.45 s), same cage (2,247 control points, two-sided E_rms 4.302e-4); median Python/CLI 0.90.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import subfit

REPO = Path(__file__).resolve().parents[3]
OPTIONS = dict(as_points=True, tolerance=5e-4, max_error=0.0036, max_control_points=2385)
FLAGS = ["--as-points", "--tolerance", "5e-4", "--max-error", "0.0036", "--max-control-points", "2385"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", type=Path, default=REPO / "target" / "release" / "subfit")
    ap.add_argument("--data", type=Path, default=Path(os.environ.get("SUBFIT_DATA", REPO.parent / "shared" / "data")))
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    scan = a.data / "igea.ply"
    if not scan.is_file():
        sys.exit(f"{scan}: not found (set SUBFIT_DATA)")
    if not a.cli.is_file():
        sys.exit(f"{a.cli}: no CLI binary (cargo build --release)")
    print(f"subfit {subfit.__version__}; {scan}; options {OPTIONS}")
    cli_t, py_t, py_fit_t = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(a.repeat):
            out = Path(tmp) / f"cli{k}"
            t = time.perf_counter()
            r = subprocess.run([str(a.cli), "fit", str(scan), *FLAGS, "-o", str(out)], capture_output=True, text=True)
            cli_t.append(time.perf_counter() - t)
            if r.returncode not in (0, 1):
                sys.exit(f"CLI failed: {r.stderr}")
            cli_report = json.loads((out / "report.json").read_text())

            t = time.perf_counter()
            f = subfit.fit(scan, **OPTIONS)
            py_fit_t.append(time.perf_counter() - t)
            f.save(Path(tmp) / f"py{k}")
            py_t.append(time.perf_counter() - t)
            print(f"run {k + 1}: CLI {cli_t[-1]:.2f} s ({cli_report['control_points']} cp, two-sided E_rms "
                  f"{cli_report['final']['two_sided']['e_rms']:.3e}); Python {py_t[-1]:.2f} s, of which fit "
                  f"{py_fit_t[-1]:.2f} s ({f.num_control_points} cp, two-sided E_rms "
                  f"{f.report['final']['two_sided']['e_rms']:.3e})")
    c, p = statistics.median(cli_t), statistics.median(py_t)
    print(f"median: CLI {c:.2f} s, Python {p:.2f} s (fit alone {statistics.median(py_fit_t):.2f} s): "
          f"Python/CLI = {p / c:.3f}")


if __name__ == "__main__":
    main()
