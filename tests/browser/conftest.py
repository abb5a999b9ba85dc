"""Fixtures for the report's browser tests: the build's CLI, a small finished active run,
and a probe that opens a page in headless Chromium (tests/browser/page_probe.mjs)."""
import json
import os
import pathlib
import shutil
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("SARESGS_BUILD", REPO / "build"))
CLI = BUILD / "apps" / "saresgs"
PROBE = pathlib.Path(__file__).with_name("page_probe.mjs")
CHROMIUM = os.environ.get("SARESGS_CHROMIUM", shutil.which("chromium") or "/usr/bin/chromium")
VIEWER = pathlib.Path(os.environ.get("SARESGS_REPORT_VIEWER", REPO / "build" / "node_tools" / "report" / "viewer.js"))


def run_cli(*args, check=True):
    r = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"saresgs {' '.join(map(str, args))} failed ({r.returncode}):\n{r.stdout}\n{r.stderr}")
    return r


def require_tools():
    """The tests fail (never skip) without their browser and viewer: the test command installs both."""
    missing = []
    if not pathlib.Path(CHROMIUM).exists():
        missing.append(f"chromium at {CHROMIUM} (scripts/install_deps.sh installs Debian's chromium)")
    if not VIEWER.exists():
        missing.append(f"the report viewer at {VIEWER} (scripts/install_node_tools.sh bundles it)")
    if missing:
        raise AssertionError("missing: " + "; ".join(missing))


def probe(page, expression="null", tmp_path=None, timeout_ms=240000, screenshot=None, width=1280, height=900):
    """Opens `page` from file://, evaluates `expression` there, and returns what the probe saw:
    {console, requests, dialogs, result}."""
    require_tools()
    out = pathlib.Path(tmp_path or page.parent) / f"probe-{os.getpid()}-{abs(hash(expression)) % 10**8}.json"
    cmd = ["node", "--experimental-websocket", str(PROBE), "--chromium", CHROMIUM, "--url",
           pathlib.Path(page).resolve().as_uri(), "--eval", expression, "--out", str(out),
           "--timeout-ms", str(timeout_ms), "--width", str(width), "--height", str(height)]
    if screenshot:
        cmd += ["--screenshot", str(screenshot)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_ms / 1000 + 60)
    seen = json.loads(out.read_text()) if out.exists() else None
    if r.returncode != 0:
        raise AssertionError(f"page probe failed ({r.returncode}): {r.stderr[-3000:]}\nseen: {json.dumps(seen)[:3000] if seen else None}")
    if seen.get("evalError"):
        raise AssertionError(f"the page's expression threw: {seen['evalError']}\nconsole: {seen['console']}")
    return seen


def problems(seen, page):
    """Console errors and requests that leave the file (data: and blob: stay inside it)."""
    errors = [m for m in seen["console"] if m["level"] in ("error", "exception", "assert")]
    me = pathlib.Path(page).resolve().as_uri()
    outside = [u for u in seen["requests"] if not (u == me or u.startswith("data:") or u.startswith("blob:"))]
    return errors, outside


@pytest.fixture(scope="session")
def small_run(tmp_path_factory):
    """A finished active run at 256 x 192: 24 views of the object layout, 6 chosen."""
    base = tmp_path_factory.mktemp("report")
    scene = base / "scene"
    run_cli("scene", "--layout", "object", "--out", scene, "--views", 24, "--width", 256, "--height", 192, "--seed", 1)
    run = base / "run"
    run_cli("active", "--dataset", scene, "--out", run, "--method", "fvs", "--max-views", 6, "--interval", 80, "--min-iterations", 480,
            "--final-iterations", 400, "--threads", 2, "--seed", 0)
    return {"scene": scene, "run": run}
