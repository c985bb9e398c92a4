#!/usr/bin/env python3
"""The peers of the scoreboard: for every row of `subfit bench corpus`'s result file, the
best-known alternatives a user would run, at the same size as our cage, written for the bench to
judge with its own judge.

    pip install -r tools/peers/requirements.txt
    python3 tools/peers/peers.py --ours OURS.json --out PEERS_DIR [--subfit BIN] [--jobs N]
                                 [--only ENTRY ...] [--force] [--compare]

Per row (PEERS_DIR/<entry>/): poisson-qem.ply (MeshLab screened Poisson + quadric edge
collapse), instant-meshes.obj and quadriflow.obj (the remeshes fitted as Catmull-Clark cages by
least squares with `subfit fit`); PEERS_DIR/peers.json lists them, rewritten after every entry.
README.md beside this file says how each peer is run and why.
"""
import argparse
import concurrent.futures
import json
import os
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import threading
import time

from meshes import atomic_write_text
from poisson_qem import DEPTH, TRIM_QUANTILE
from worker import PEERS, clear

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[1]
ENTRY_NAME = re.compile(r"^[A-Za-z0-9_.-]+(/[A-Za-z0-9_.-]+)*$")
ROW_KEYS = ("entry", "input", "category", "kind")
DIED = "the worker died"
"""How the error of a peer whose process crashed or timed out starts: such a peer is redone by
the next run, where a peer's own failure (e.g. a remesh subfit refuses) is kept."""


def fail(message):
    """Bad input or usage: the message on stderr, exit status 2, nothing written."""
    print(f"peers: {message}", file=sys.stderr)
    sys.exit(2)


class Runner:
    """Runs the peers of entries in worker processes, prints progress, keeps peers.json."""

    def __init__(self, args, subfit, existing):
        self.args, self.subfit = args, subfit
        self.rows = existing  # {(entry, peer): row}
        self.lock = threading.Lock()
        self.children = set()
        self.order = []

    def say(self, text):
        with self.lock:
            print(text, flush=True)

    def is_done(self, row):
        """Whether every peer of `row` has a row for the same input and size, with its file."""
        for peer in PEERS:
            old = self.rows.get((row["entry"], peer))
            if old is None or old.get("target_vertices") != row["control_points"]:
                return False
            if old.get("input") != row["input"]:
                return False
            if old.get("error") is None and not (self.args.out / old["file"]).exists():
                return False
            if (old.get("error") or "").startswith(DIED):
                return False
        return True

    def run_entry(self, row):
        """All peers of one entry; returns their rows (errors included)."""
        entry_dir = self.args.out / row["entry"]
        entry_dir.mkdir(parents=True, exist_ok=True)
        (entry_dir / "log.txt").write_text(f"peers of {row['entry']} ({row['input']})\n")
        scratch = entry_dir / ".scratch"
        scratch.mkdir(exist_ok=True)
        try:
            job = self.prepare(row, entry_dir, scratch)
        except RuntimeError as e:
            job, failure = None, str(e)
        rows = []
        for peer in PEERS:
            if job is None:
                result = {"error": failure, "seconds": None}
            else:
                result = self.run_peer(peer, job, entry_dir)
            result = self.finish(row, peer, result)
            rows.append(result)
            self.progress(row, result)
        shutil.rmtree(scratch, ignore_errors=True)
        return rows

    def prepare(self, row, entry_dir, scratch):
        """The worker's job: the model read once by subfit (the reader the bench uses) and
        written as PLY for MeshLab, and the settings. Raises RuntimeError on a bad row."""
        # A cage pair's input is its dense mesh: the peers remesh it at the given cage's count.
        kind = "mesh" if row["kind"] == "cage-pair" else row["kind"]
        if kind not in ("mesh", "points"):
            raise RuntimeError(f"kind `{row['kind']}`: the peers need a mesh or a point cloud")
        source = pathlib.Path(row["input"])
        if not source.is_file():
            raise RuntimeError(f"{source}: no such file")
        ply = scratch / "input.ply"
        cmd = [str(self.subfit), "convert", str(source), str(ply), "--to", "ply"]
        run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"subfit convert failed: {run.stdout.strip()[-300:]}")
        trim = self.args.trim_points if kind == "points" else self.args.trim_mesh
        job = {
            "entry": row["entry"], "input": str(source), "input_ply": str(ply),
            "kind": kind, "category": row["category"],
            "vertices": row["control_points"], "subfit": str(self.subfit),
            "depth": self.args.depth, "threads": 1,
            "trim_quantile": trim, "fit_method": self.args.fit_method,
            "entry_dir": str(entry_dir),
        }  # fmt: skip
        atomic_write_text(scratch / "job.json", json.dumps(job, indent=1))
        return job

    def run_peer(self, peer, job, entry_dir):
        """One worker process; its output goes to the entry's log.txt."""
        scratch = entry_dir / ".scratch"
        result_path = scratch / f"result-{peer}.json"
        result_path.unlink(missing_ok=True)
        clear(peer, entry_dir)
        cmd = [sys.executable, str(HERE / "worker.py"), peer, str(scratch / "job.json")]
        cmd.append(str(result_path))
        start = time.perf_counter()
        with open(entry_dir / "log.txt", "a") as log:
            log.write(f"\n=== {peer}\n")
            log.flush()
            child = subprocess.Popen(cmd, stdout=log, stderr=log, start_new_session=True)
            with self.lock:
                self.children.add(child)
            try:
                code = child.wait(timeout=self.args.timeout)
            except subprocess.TimeoutExpired:
                os.killpg(child.pid, signal.SIGKILL)
                child.wait()
                code = f"killed after the {self.args.timeout} s timeout"
            finally:
                with self.lock:
                    self.children.discard(child)
        if result_path.exists():
            return json.loads(result_path.read_text())
        seconds = time.perf_counter() - start
        return {"error": f"{DIED} ({code}); see {peer} in log.txt", "seconds": seconds}

    def finish(self, row, peer, result):
        """The peers.json row: contract fields first, paths relative to the peers folder."""
        entry = row["entry"]
        out = {"entry": entry, "peer": peer, "kind": None, "scheme": None, "file": None}
        out.update({k: None for k in ("seconds", "vertices", "faces", "quad_fraction")})
        out.update({"irregular_vertices": None, "note": None, "error": None})
        out.update(result)
        if out["file"] is not None:
            out["file"] = f"{entry}/{out['file']}"
        if isinstance(out["seconds"], float):
            out["seconds"] = round(out["seconds"], 3)
        out["target_vertices"] = row["control_points"]
        out["input"] = row["input"]
        if self.args.compare and out["error"] is None:
            out_compare = self.compare(row, out)
            if out_compare is not None:
                self.save_compare(row, peer, out_compare)
        return out

    def compare(self, row, out):
        """The sanity figures of `subfit compare PEER INPUT --json` (not the bench's judge)."""
        cmd = [str(self.subfit), "compare", str(self.args.out / out["file"]), row["input"]]
        cmd.append("--json")
        if out["scheme"]:
            cmd += ["--scheme", out["scheme"]]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            return {"error": run.stderr.strip()[-300:]}
        return json.loads(run.stdout)

    def save_compare(self, row, peer, figures):
        path = self.args.out / row["entry"] / "compare.json"
        with self.lock:
            old = json.loads(path.read_text()) if path.exists() else {}
            old[peer] = figures
            atomic_write_text(path, json.dumps(old, indent=1))

    def progress(self, row, r):
        head = f"{row['entry']:36} {r['peer']:15}"
        secs = f"{r['seconds']:7.1f} s" if isinstance(r["seconds"], (int, float)) else "      - s"
        if r["error"]:
            self.say(f"{head} {secs}  error: {r['error']}")
            return
        text = (
            f"{head} {secs}  {r['vertices']:5d} v (ours {row['control_points']}), "
            f"{r['faces']:5d} f, {100 * r['quad_fraction']:3.0f}% quads, "
            f"{r['irregular_vertices']} irregular"
        )
        path = self.args.out / row["entry"] / "compare.json"
        if self.args.compare and path.exists():
            c = json.loads(path.read_text()).get(r["peer"], {})
            if "two_sided_rms_fraction" in c:
                text += (
                    f"  [compare: RMS {c['two_sided_rms_fraction']:.2e}, "
                    f"Hausdorff {c['hausdorff_fraction']:.2e} of the diagonal]"
                )
        self.say(text)

    def save(self):
        """Rewrite peers.json atomically: this run's entries in OURS order, then older rows."""
        with self.lock:
            keys = [(e, p) for e in self.order for p in PEERS if (e, p) in self.rows]
            keys += [k for k in self.rows if k not in set(keys)]
            rows = [self.rows[k] for k in keys]
            atomic_write_text(self.args.out / "peers.json", json.dumps({"peers": rows}, indent=1))

    def kill_children(self):
        with self.lock:
            for child in self.children:
                try:
                    os.killpg(child.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass


def read_ours(path, only):
    """The rows of OURS.json to give peers to; exits with status 2 naming the row and field on
    a malformed file."""
    try:
        data = json.loads(pathlib.Path(path).read_text())
    except (OSError, ValueError) as e:
        fail(f"{path}: cannot read it as JSON ({e})")
    if not isinstance(data, dict) or not isinstance(data.get("rows"), list):
        fail(f'{path}: expected an object with a "rows" list')
    rows, seen = [], set()
    for i, row in enumerate(data["rows"]):
        where = f"{path}: rows[{i}]"
        if not isinstance(row, dict):
            fail(f"{where}: not an object")
        missing = [k for k in ROW_KEYS if k not in row]
        if missing:
            fail(f"{where}: missing {', '.join(missing)}")
        # `subfit bench corpus` leaves the cage's fields out of a row without a cage.
        entry, cp = row["entry"], row.get("control_points")
        if not isinstance(entry, str) or not ENTRY_NAME.match(entry) or ".." in entry.split("/"):
            fail(f"{where}: entry {entry!r} is not a usable folder name")
        if entry in seen:
            fail(f"{where}: entry {entry!r} appears twice")
        seen.add(entry)
        if cp is not None and (not isinstance(cp, int) or isinstance(cp, bool) or cp < 4):
            fail(f"{where}: control_points {cp!r} is not a count of at least 4")
        if only and entry not in only:
            continue
        if cp is None:
            print(f"{entry:36} skipped: no cage of ours (control_points absent or null)", flush=True)
            continue
        rows.append(row)
    unknown = set(only or ()) - seen
    if unknown:
        fail(f"--only {', '.join(sorted(unknown))}: no such entry in {path}")
    return rows


def find_subfit(given):
    """`--subfit`, else the repository's target/release/subfit, else `subfit` on PATH."""
    candidates = [given] if given else [str(REPO / "target/release/subfit"), "subfit"]
    for c in candidates:
        found = shutil.which(c)
        if found:
            return pathlib.Path(found).resolve()
    if given:
        fail(f"--subfit {given}: not an executable")
    fail("no subfit binary: `cargo build --release -p subfit-cli`, or pass --subfit")


def load_existing(out):
    path = out / "peers.json"
    if not path.exists():
        return {}
    try:
        rows = json.loads(path.read_text())["peers"]
        return {(r["entry"], r["peer"]): r for r in rows}
    except (OSError, ValueError, KeyError, TypeError) as e:
        fail(f"{path}: exists but is not a peers file ({e}); move it away or fix it")


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--ours", type=pathlib.Path, required=True, help="the bench's result JSON")
    p.add_argument("--out", type=pathlib.Path, required=True, help="folder of the peers")
    p.add_argument("--subfit", help="the subfit binary (default: target/release/subfit, PATH)")
    p.add_argument("--jobs", type=int, default=1, help="entries run at once (processes)")
    p.add_argument("--only", nargs="+", metavar="ENTRY", help="only these entries")
    p.add_argument("--force", action="store_true", help="redo entries whose outputs exist")
    p.add_argument("--compare", action="store_true",
                   help="sanity check: also run `subfit compare` on each peer (compare.json)")
    p.add_argument("--depth", type=int, default=DEPTH, help="Poisson octree depth (MeshLab's 8)")
    p.add_argument("--trim-mesh", type=float, default=TRIM_QUANTILE["mesh"],
                   help="density quantile below which an open mesh's Poisson surface is trimmed")
    p.add_argument("--trim-points", type=float, default=TRIM_QUANTILE["points"],
                   help="density quantile below which a point cloud's Poisson surface is trimmed")
    p.add_argument("--fit-method", choices=("pdm", "sdm"), default="pdm",
                   help="error term of the remeshes' least-squares fit (pdm: plain)")
    p.add_argument("--timeout", type=float, default=3600.0,
                   help="seconds after which one peer of one entry is stopped")  # fmt: skip
    a = p.parse_args(argv)
    if a.jobs < 1:
        p.error("--jobs must be at least 1")
    if not (0.0 < a.trim_mesh < 1.0 and 0.0 < a.trim_points < 1.0):
        p.error("--trim-mesh and --trim-points must be in (0, 1)")
    if not 1 <= a.depth <= 14:
        p.error("--depth must be between 1 and 14")
    return a


def main(argv=None):
    args = parse_args(argv)
    subfit = find_subfit(args.subfit)
    rows = read_ours(args.ours, set(args.only) if args.only else None)
    args.out.mkdir(parents=True, exist_ok=True)
    args.out = args.out.resolve()
    runner = Runner(args, subfit, load_existing(args.out))
    runner.order = [r["entry"] for r in rows]
    todo = [r for r in rows if args.force or not runner.is_done(r)]
    for r in rows:
        if r not in todo:
            runner.say(f"{r['entry']:36} done before (--force redoes it)")
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs)
    try:
        futures = [pool.submit(runner.run_entry, r) for r in todo]
        for future in concurrent.futures.as_completed(futures):
            for peer_row in future.result():
                runner.rows[(peer_row["entry"], peer_row["peer"])] = peer_row
            runner.save()
    except KeyboardInterrupt:
        pool.shutdown(wait=False, cancel_futures=True)
        runner.kill_children()
        print("peers: interrupted; peers.json holds the entries finished", file=sys.stderr)
        return 130
    pool.shutdown()
    runner.save()
    errors = sum(1 for r in runner.rows.values() if r["entry"] in runner.order and r["error"])
    print(f"peers: wrote {args.out / 'peers.json'} ({len(rows)} entries, {errors} peer errors)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
