"""Opens a subfit report.html in headless Chromium (Debian's /usr/bin/chromium, driven by
Playwright; no browser download) and checks what a person would see:

* no console error and no uncaught exception;
* no network request (everything is inlined: only the file itself and data:/blob: URLs);
* the WebGL canvas draws (SwiftShader): many distinct colours, not one flat colour;
* the texts given with --expect are on the page (e.g. the final E_rms);
* at least --figures SVG plots;
* the layer check boxes change the picture.

Prints one JSON line (open time, colours, plots, ...) and exits 1 with the reasons when a
check fails, 2 when Playwright or Chromium is missing. A screenshot goes to --screenshot.

Usage: python3 browser_report.py REPORT.html [--screenshot PNG] [--expect TEXT]... [--figures N]
       [--viewport WIDTHxHEIGHT]
"""

import argparse
import json
import pathlib
import sys
import time

CHROMIUM_ARGS = [
    "--no-sandbox",
    "--use-gl=swiftshader",
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
    # SwiftShader renders on the CPU: under load a frame can outlast the GPU watchdog, which
    # then kills the GPU process and the page's WebGL context with it (a blank canvas).
    "--disable-gpu-watchdog",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]

# Distinct colours among the sampled pixels of the canvas, and the share that is not the
# background (#f4f4f4).
CANVAS_STATS = """
() => {
  const gl = document.querySelector('#subfit-viewer canvas');
  if (!gl) return null;
  const c = document.createElement('canvas');
  c.width = gl.width; c.height = gl.height;
  const ctx = c.getContext('2d');
  ctx.drawImage(gl, 0, 0);
  const d = ctx.getImageData(0, 0, c.width, c.height).data;
  const seen = new Set();
  let foreground = 0, total = 0;
  for (let i = 0; i < d.length; i += 4 * 7) {
    total++;
    seen.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
    if (Math.abs(d[i] - 244) + Math.abs(d[i + 1] - 244) + Math.abs(d[i + 2] - 244) > 12) foreground++;
  }
  return { colors: seen.size, foreground: foreground / Math.max(total, 1), width: c.width, height: c.height };
}
"""


# A browser that dies while starting, before it has opened anything, says nothing about the
# report: start it again (at most this many times), and say so on stderr. A loaded CI machine
# once refused the fork of Chromium's GPU process ("Zygote could not fork: process_type
# gpu-process"), which took the browser down at launch. (--in-process-gpu, which avoids that
# fork, leaves SwiftShader's page load hanging: not an option.)
LAUNCH_ATTEMPTS = 3


def launch(playwright, chromium):
    """Starts headless Chromium, again if it died while starting (a refused fork under load)."""
    for attempt in range(1, LAUNCH_ATTEMPTS + 1):
        try:
            return playwright.chromium.launch(
                executable_path=chromium, headless=True, args=CHROMIUM_ARGS
            )
        except Exception as e:  # noqa: BLE001 - retried, then raised
            if attempt == LAUNCH_ATTEMPTS:
                raise
            first = str(e).splitlines()[0] if str(e) else type(e).__name__
            print(
                f"Chromium did not start (attempt {attempt} of {LAUNCH_ATTEMPTS}): {first}",
                file=sys.stderr,
            )
            time.sleep(1.0)
    raise AssertionError("unreachable")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("report")
    parser.add_argument("--screenshot")
    parser.add_argument("--expect", action="append", default=[])
    parser.add_argument("--figures", type=int, default=1)
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    parser.add_argument("--viewport", default="1400x1000", help="WIDTHxHEIGHT of the page")
    args = parser.parse_args()
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        print("playwright (pip install playwright) is not installed", file=sys.stderr)
        return 2
    if not pathlib.Path(args.chromium).exists():
        print(f"{args.chromium} is missing (apt-get install chromium)", file=sys.stderr)
        return 2
    report = pathlib.Path(args.report).resolve()
    url = report.as_uri()
    failures = []
    console_errors = []
    requests = []
    result = {"report": str(report), "bytes": report.stat().st_size}
    with sync_playwright() as p:
        browser = launch(p, args.chromium)
        width, height = (int(v) for v in args.viewport.split("x"))
        page = browser.new_page(viewport={"width": width, "height": height})
        page.on(
            "console",
            lambda m: console_errors.append(m.text) if m.type == "error" else None,
        )
        page.on("pageerror", lambda e: console_errors.append(f"uncaught: {e}"))
        context_events = []
        page.on(
            "console",
            lambda m: context_events.append(m.text) if "context" in m.text.lower() else None,
        )
        page.on(
            "request",
            lambda r: requests.append(r.url)
            if not (r.url == url or r.url.startswith(("data:", "blob:")))
            else None,
        )
        start = time.perf_counter()
        page.goto(url, wait_until="load", timeout=120_000)
        try:
            page.wait_for_selector(
                '#subfit-viewer[data-ready="true"]', state="attached", timeout=120_000
            )
        except Exception as e:  # noqa: BLE001 - reported as a failed check
            failures.append(f"the viewer did not become ready: {e}")
        result["open_s"] = round(time.perf_counter() - start, 3)
        # The first frame is drawn before the viewer says it is ready; a software renderer
        # under load may still be compositing it (or restoring a lost context): give it time.
        drawn = (
            "() => { const s = (%s)(); return s && s.colors >= 16 && s.foreground >= 0.05; }"
            % CANVAS_STATS.strip()
        )
        try:
            page.wait_for_function(drawn, timeout=60_000, polling=250)
        except Exception:  # noqa: BLE001 - judged below
            pass
        stats = page.evaluate(CANVAS_STATS)
        result["canvas"] = stats
        if not stats:
            failures.append("no canvas in #subfit-viewer")
        elif stats["colors"] < 16 or stats["foreground"] < 0.05:
            failures.append(f"the canvas looks flat: {stats}")
        text = page.inner_text("body")
        for expected in args.expect:
            if expected not in text:
                failures.append(f"text {expected!r} is not on the page")
        figures = page.locator("figure svg").count()
        result["figures"] = figures
        if figures < args.figures:
            failures.append(f"{figures} plots, expected at least {args.figures}")
        boxes = page.locator("#subfit-viewer-controls input[type=checkbox]")
        result["toggles"] = boxes.count()
        if boxes.count() >= 1 and stats:
            # The viewer redraws on the next animation frame: wait for the picture to change
            # (and to come back), however slow the software renderer is under load.
            changed = (
                "(before) => { const s = (%s)(); return s && (s.colors !== before.colors"
                " || Math.abs(s.foreground - before.foreground) > 1e-3); }" % CANVAS_STATS.strip()
            )
            same = (
                "(before) => { const s = (%s)(); return s && s.colors === before.colors"
                " && Math.abs(s.foreground - before.foreground) <= 1e-3; }" % CANVAS_STATS.strip()
            )
            boxes.nth(0).click()
            try:
                page.wait_for_function(changed, arg=stats, timeout=60_000, polling=100)
            except Exception:  # noqa: BLE001 - reported as a failed check
                failures.append("hiding the first layer did not change the picture")
            boxes.nth(0).click()
            try:
                page.wait_for_function(same, arg=stats, timeout=60_000, polling=100)
            except Exception:  # noqa: BLE001 - reported as a failed check
                failures.append("showing the first layer again did not restore the picture")
        else:
            failures.append("no layer check boxes")
        if args.screenshot:
            pathlib.Path(args.screenshot).parent.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=args.screenshot, full_page=False)
            result["screenshot"] = args.screenshot
        browser.close()
    if context_events:
        result["webgl_context"] = context_events[:5]
    if console_errors:
        failures.append(f"console errors: {console_errors[:5]}")
    if requests:
        failures.append(f"network requests: {requests[:5]}")
    result["failures"] = failures
    print(json.dumps(result))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
