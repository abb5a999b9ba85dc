"""The run report (saresgs report RUN_DIR) opened in a real browser: headless Chromium with
software WebGL, driven through the DevTools protocol (page_probe.mjs)."""
import base64
import json
import pathlib
import shutil

import numpy as np
import pytest

from conftest import problems, probe, run_cli

import saresgs


def test_report_loads_offline_without_errors(small_run, tmp_path):
    page = small_run["run"] / "report.html"  # written by `saresgs active` itself
    assert page.exists()
    seen = probe(page, "saresgsReport.ready.then((v) => ({viewer: !!v, rows: "
                       "document.querySelectorAll('#views-table tbody tr').length}))", tmp_path)
    errors, outside = problems(seen, page)
    assert errors == [], errors
    assert outside == [], f"requests outside the file: {outside}"
    assert seen["dialogs"] == []
    results = json.loads((small_run["run"] / "results.json").read_text())
    assert seen["result"] == {"viewer": True, "rows": len(results["final_fit"]["views"])}


def decode(capture):
    a = np.frombuffer(base64.b64decode(capture["rgba"]), np.uint8)
    return a.reshape(capture["height"], capture["width"], 4)[..., :3].astype(np.float64) / 255.0


def test_viewer_draws_the_model_as_our_rasterizer_does(small_run, tmp_path):
    """The splat viewer (Spark) is a second renderer of our .ply: from a test camera, set by
    the page's own camera control, its picture matches saresgs's render of that view."""
    page = small_run["run"] / "report.html"
    results = json.loads((small_run["run"] / "results.json").read_text())
    test_name = results["final_fit"]["views"][0]["name"]
    expr = ("saresgsReport.ready.then(async (v) => { const d = saresgsReport.data; "
            f"const i = d.cameras.findIndex((c) => c.name === {json.dumps(test_name)}); "
            "const free = await v.capture(i, {raw: true}); "
            "return {i, shot: free}; })")
    seen = probe(page, expr, tmp_path)
    got = decode(seen["result"]["shot"])
    assert got.shape == (192, 256, 3)
    assert got.std() > 0.02, "the viewer's canvas is blank"

    dataset = saresgs.load_dataset(str(small_run["scene"]))
    model = saresgs.Gaussians.read_ply(str(small_run["run"] / "final_fit.ply")).from_world(dataset)
    view = dataset.names.index(test_name)
    bg = dataset.background or [0.0, 0.0, 0.0]
    rgb, _, _ = saresgs.render(model, dataset.camera(view), background=list(bg))
    ref = np.clip(np.asarray(rgb, np.float64), 0, 1)
    psnr = 10 * np.log10(1.0 / np.mean((got - ref) ** 2))
    assert psnr >= 25.0, f"viewer vs rasterizer: {psnr:.2f} dB"
    # and it is a picture of the model, not of anything: the same comparison against
    # another view's render is far worse
    other = dataset.names.index(results["final_fit"]["views"][-1]["name"])
    rgb2, _, _ = saresgs.render(model, dataset.camera(other), background=list(bg))
    psnr_other = 10 * np.log10(1.0 / np.mean((got - np.clip(np.asarray(rgb2), 0, 1)) ** 2))
    assert psnr_other < psnr - 5


def test_curve_and_table_equal_results_json(small_run, tmp_path):
    page = small_run["run"] / "report.html"
    expr = ("({curve: Array.from(document.querySelectorAll('#curve circle')).map((c) => "
            "[c.getAttribute('data-series'), Number(c.getAttribute('data-x')), Number(c.getAttribute('data-y'))]), "
            "rows: Array.from(document.querySelectorAll('#views-table tbody tr')).map((tr) => "
            "[tr.getAttribute('data-view'), Number(tr.children[1].getAttribute('data-value')), "
            "Number(tr.children[2].getAttribute('data-value')), tr.children[1].textContent]), "
            "warnings: Array.from(document.querySelectorAll('#warnings li')).map((li) => li.textContent)})")
    seen = probe(page, expr, tmp_path)
    r = json.loads((small_run["run"] / "results.json").read_text())
    loop = [(x, y) for s, x, y in seen["result"]["curve"] if s.startswith("in the loop")]
    assert loop == [(s["views_before"], s["progress_psnr"]) for s in r["steps"]]
    finals = {s: (x, y) for s, x, y in seen["result"]["curve"] if s.startswith("final fit")}
    assert list(finals.values()) == [(len(r["selected_view_indices"]), r["final_fit"]["psnr"])]
    rows = seen["result"]["rows"]
    want = sorted(((v["name"], v["psnr"], v["ssim"]) for v in r["final_fit"]["views"]), key=lambda t: t[1])
    assert [(n, p, s) for n, p, s, _ in rows] == want  # worst first
    assert all(text == f"{p:.2f}" for _, p, _, text in rows)
    # what the run printed before it started, as results.json keeps it
    assert seen["result"]["warnings"] == r["warnings"]


def test_incomplete_runs_say_what_is_missing(small_run, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(small_run["run"], run)
    # no final fit file: the page still loads, says so and shows the loop's model
    (run / "final_fit.ply").unlink()
    (run / "final_fit_views.ply").unlink(missing_ok=True)
    run_cli("report", run)
    seen = probe(run / "report.html", "saresgsReport.ready.then((v) => ({viewer: !!v, "
                 "missing: document.getElementById('missing').textContent, info: document.getElementById('model-info').textContent}))",
                 tmp_path)
    errors, outside = problems(seen, run / "report.html")
    assert errors == [] and outside == []
    assert "final_fit.ply is missing" in seen["result"]["missing"]
    assert "point_cloud.ply" in seen["result"]["info"] and seen["result"]["viewer"]
    # no model at all and no viewer script: a page without the 3D view, saying both
    (run / "point_cloud.ply").write_bytes(b"ply\nformat ascii 1.0\nend_header\n")
    r = run_cli("report", run, "--viewer-script", tmp_path / "absent.js")
    assert "without the 3D viewer" in r.stdout
    seen = probe(run / "report.html", "saresgsReport.ready.then((v) => ({viewer: v, "
                 "missing: document.getElementById('missing').textContent, "
                 "rows: document.querySelectorAll('#views-table tbody tr').length}))", tmp_path)
    errors, _ = problems(seen, run / "report.html")
    assert errors == []
    assert seen["result"]["viewer"] is None
    assert "point_cloud.ply could not be read" in seen["result"]["missing"]
    assert "viewer's script is not installed" in seen["result"]["missing"]
    assert seen["result"]["rows"] > 0  # the numbers are still there
    # interrupted: no results.json but a checkpoint: a clear error, no page
    (run / "results.json").unlink()
    (run / "report.html").unlink()
    r = run_cli("report", run, check=False)
    assert r.returncode != 0
    assert "results.json" in r.stderr and "interrupted" in r.stderr
    assert not (run / "report.html").exists()
    # not a run folder at all
    r = run_cli("report", tmp_path / "nowhere", check=False)
    assert r.returncode != 0 and "nowhere" in r.stderr


HOSTILE_DIR = "scene \"q' <script>alert(1)<"
HOSTILE_SUBDIR = "a<"
HOSTILE_FILE = "script><img src=x onerror=alert(2)>\"'"


def test_names_from_the_data_stay_text(tmp_path):
    """A dataset whose folder, image names and transforms.json strings hold <script>, quotes
    and </script>: the page shows them as text and runs none of them."""
    scene = tmp_path / HOSTILE_DIR
    run_cli("scene", "--layout", "object", "--out", scene, "--views", 12, "--width", 64, "--height", 48,
            "--format", "blender", "--seed", 2)
    # move one train and one test image under a name that holds "</script>" and quotes
    for split in ("train", "test"):
        tf = scene / f"transforms_{split}.json"
        meta = json.loads(tf.read_text())
        frame = meta["frames"][0]
        old = (scene / frame["file_path"]).with_suffix(".png")
        new_rel = f"./{split}/{HOSTILE_SUBDIR}/{HOSTILE_FILE}{split}"
        (scene / split / HOSTILE_SUBDIR).mkdir(exist_ok=True)
        old.rename((scene / new_rel).with_suffix(".png"))
        frame["file_path"] = new_rel
        tf.write_text(json.dumps(meta))
    run = tmp_path / "run </script><script>alert(3)</script>"
    run.mkdir(parents=True)  # "run <" / "script><script>alert(3)<" / "script>"
    run_cli("active", "--dataset", scene, "--out", run, "--method", "fvs", "--max-views", 4, "--interval", 20, "--min-iterations", 80,
            "--final-iterations", 40, "--threads", 2)
    page = run / "report.html"
    seen = probe(page, "saresgsReport.ready.then(() => ({text: document.body.innerText, "
                       "scripts: document.scripts.length, imgs: Array.from(document.images).map((i) => i.getAttribute('src').slice(0, 5)), "
                       "title: document.title}))", tmp_path)
    assert seen["dialogs"] == [], seen["dialogs"]
    errors, outside = problems(seen, page)
    assert errors == [] and outside == []
    text = seen["result"]["text"]
    assert HOSTILE_DIR in text  # the dataset path, as text
    # a view's name is its file name (the loader drops the folder "a<", so the "</script>"
    # of its transforms.json path does not reach the page; the run folder's does, below)
    assert f"{HOSTILE_FILE}test.png" in text
    assert "</script><script>alert(3)</script>" in text  # the run folder
    # the page's own scripts only: data, model, viewer, app
    assert seen["result"]["scripts"] == 4
    assert all(src == "data:" for src in seen["result"]["imgs"])


def test_a_500k_gaussian_model_keeps_the_page_under_40_mb(small_run, tmp_path):
    """A large model travels as a .splat (degree 0, 8-bit): the page says so and its size."""
    run = tmp_path / "run"
    shutil.copytree(small_run["run"], run)
    n = 500_000
    rng = np.random.default_rng(0)
    big = saresgs.Gaussians(rng.uniform(-1, 1, (n, 3)).astype(np.float32),
                            rng.uniform(-5, -3, (n, 3)).astype(np.float32),
                            rng.normal(size=(n, 4)).astype(np.float32),
                            rng.uniform(-3, 3, n).astype(np.float32),
                            rng.uniform(-1, 1, (n, 4, 3)).astype(np.float32))
    big.write_ply(str(run / "final_fit.ply"))  # degree 1: 58 MB
    assert (run / "final_fit.ply").stat().st_size > 50e6
    r = run_cli("report", run)
    page = run / "report.html"
    assert page.stat().st_size < 40 * 2**20, page.stat().st_size
    data = page.read_text()
    start = data.index('id="saresgs-data">') + len('id="saresgs-data">')
    meta = json.loads(data[start:data.index("</script>", start)])
    assert meta["model"]["format"] == "splat" and meta["model"]["gaussians"] == n
    assert meta["model"]["bytes"] == 32 * meta["model"].get("shown_gaussians", n)
    assert "MB" in r.stdout


def test_the_splat_form_draws_the_same_picture(small_run, tmp_path):
    """The small model forced into the .splat form (a tiny budget) still matches the
    rasterizer in the browser: the compressed path is a real consumer too."""
    run = tmp_path / "run"
    shutil.copytree(small_run["run"], run)
    ply = (run / "final_fit.ply").stat().st_size
    run_cli("report", run, "--model-budget-bytes", ply - 1)  # below the .ply's size, above the .splat's (about half)
    results = json.loads((run / "results.json").read_text())
    name = results["final_fit"]["views"][0]["name"]
    seen = probe(run / "report.html", "saresgsReport.ready.then(async (v) => { const d = saresgsReport.data; "
                 f"return {{format: d.model.format, shot: await v.capture(d.cameras.findIndex((c) => c.name === {json.dumps(name)}), {{raw: true}})}}; }})",
                 tmp_path)
    errors, outside = problems(seen, run / "report.html")
    assert errors == [] and outside == []
    assert seen["result"]["format"] == "splat"
    got = decode(seen["result"]["shot"])
    dataset = saresgs.load_dataset(str(small_run["scene"]))
    model = saresgs.Gaussians.read_ply(str(run / "final_fit.ply")).from_world(dataset)
    bg = dataset.background or [0.0, 0.0, 0.0]
    rgb, _, _ = saresgs.render(model, dataset.camera(dataset.names.index(name)), background=list(bg))
    psnr = 10 * np.log10(1.0 / np.mean((got - np.clip(np.asarray(rgb, np.float64), 0, 1)) ** 2))
    assert psnr >= 25.0, f"viewer (.splat) vs rasterizer: {psnr:.2f} dB"


def test_a_click_on_a_camera_looks_through_it(small_run, tmp_path):
    """A click (pointer down and up, as a mouse gives them) on a camera's marker moves the
    viewer to that camera and names it on the page."""
    page = small_run["run"] / "report.html"
    expr = """saresgsReport.ready.then(async (v) => {
      const d = saresgsReport.data, canvas = document.getElementById('viewer');
      const r = canvas.getBoundingClientRect();
      // from outside the capture (the page's button), every marker in view
      document.getElementById('overview').click();
      await new Promise((res) => requestAnimationFrame(() => requestAnimationFrame(res)));
      const start = v.position();
      // the on-screen marker nearest the viewer: no other marker can hide it
      let pick = -1, at = null, best = Infinity;
      for (let i = 0; i < d.cameras.length; ++i) {
        const p = v.markerOnScreen(i);
        if (!p || p.x < 5 || p.y < 5 || p.x > r.width - 5 || p.y > r.height - 5) continue;
        const c = d.cameras[i], R = c.R, t = c.t;
        const centre = [0, 1, 2].map((k) => -(R[0][k] * t[0] + R[1][k] * t[1] + R[2][k] * t[2]));
        const dist = Math.hypot(centre[0] - start[0], centre[1] - start[1], centre[2] - start[2]);
        if (dist < best) { best = dist; pick = i; at = p; }
      }
      if (pick < 0) return {pick};
      const opts = {clientX: r.left + at.x, clientY: r.top + at.y, bubbles: true, pointerId: 1, isPrimary: true, button: 0, buttons: 1};
      canvas.dispatchEvent(new PointerEvent('pointerdown', opts));
      canvas.dispatchEvent(new PointerEvent('pointerup', Object.assign({}, opts, {buttons: 0})));
      return {pick, name: d.cameras[pick].name, start, now: v.position(), text: document.getElementById('picked').textContent};
    })"""
    seen = probe(page, expr, tmp_path)
    res = seen["result"]
    assert res["pick"] >= 0, "no camera marker on screen"
    assert res["name"] in res["text"]
    # the viewer now stands at that camera's centre, -R^T t
    cam = next(c for c in json.loads(_page_data(page))["cameras"] if c["name"] == res["name"])
    R, t = np.array(cam["R"]), np.array(cam["t"])
    assert np.allclose(res["now"], -R.T @ t, atol=1e-6)


def _page_data(page):
    html = page.read_text()
    start = html.index('id="saresgs-data">') + len('id="saresgs-data">')
    return html[start:html.index("</script>", start)]
