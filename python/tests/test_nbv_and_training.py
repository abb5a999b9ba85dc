"""Training with Ctrl-C, scoring against the CLI, and active runs driven from Python."""
import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import saresgs
from conftest import run_cli

# A short active run on the small room: 4 initial views, 7 at the end.
SHORT = dict(seed=3, preset="quick", threads=1, max_views=7, interval=10, min_iterations=120, final_iterations=40)
SHORT_CLI = ["--seed", 3, "--preset", "quick", "--threads", 1, "--max-views", 7, "--interval", 10,
             "--min-iterations", 120, "--final-iterations", 40]


def test_keyboard_interrupt_stops_a_long_train_cleanly(room):
    t = saresgs.Trainer(room, seed=0, threads=1)
    # SIGINT from another thread while train() runs with the GIL released: the call must
    # raise KeyboardInterrupt after a whole iteration, long before its 10^6 iterations.
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        t.train(room.train[:4], 1_000_000)
    timer.join()
    assert time.monotonic() - start < 30
    assert 0 < t.iteration < 1_000_000
    # The model is intact and training goes on from where it stopped.
    done = t.iteration
    ev = t.evaluate()
    assert np.isfinite(ev["psnr"]) and len(ev["views"]) == len(room.test)
    seen = []
    t.train(room.train[:4], 5, callback=lambda p: seen.append(p["iteration"]))
    assert seen == list(range(done + 1, done + 6))


def test_python_random_selector_is_the_builtin_random_bit_for_bit(room, tmp_path):
    builtin = saresgs.ActiveRun(room, method="random", **SHORT).run()
    custom = saresgs.ActiveRun(room, selector=lambda ctx: ctx.random_choice(), **SHORT).run()
    assert custom["method"] == "custom" and builtin["method"] == "random"
    for key in ("selected_view_indices", "psnr", "ssim", "final_fit", "iterations"):
        assert custom[key] == builtin[key], key
    # And the built-in one from Python is the command line's run.
    run_cli("active", "--dataset", room.source, "--method", "random", *SHORT_CLI, "--out", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "results.json").read_text())
    for key in ("selected_view_indices", "psnr", "ssim", "final_fit", "background", "settings"):
        assert cli[key] == builtin[key], key
    assert builtin["settings"]["max_views"] == 7 and builtin["settings"]["gate_keep"] is None
    # A room's manifest says it has no background; every view of the path is evaluated.
    assert builtin["background"] == {"color": None, "random": False, "from": "manifest: none"}
    assert len(builtin["final_fit"]["path"]) == len(room)
    # Said black, the run renders against black and records it.
    black = saresgs.ActiveRun(room, method="random", background="black", **SHORT).run()
    assert black["background"] == {"color": [0.0, 0.0, 0.0], "random": False, "from": "background="}


def test_final_residual_is_the_clis_and_keeps_the_selection(room, tmp_path):
    plain = saresgs.ActiveRun(room, method="random", **SHORT).run()
    res = saresgs.ActiveRun(room, method="random", final_residual=True, **SHORT).run()
    assert res["selected_view_indices"] == plain["selected_view_indices"] and res["psnr"] == plain["psnr"]
    assert res["final_fit"]["residual"] is True and plain["final_fit"]["residual"] is False
    assert res["final_fit_views"] == plain["final_fit"] and res["final_fit"]["psnr"] != plain["final_fit"]["psnr"]
    run_cli("active", "--dataset", room.source, "--method", "random", *SHORT_CLI, "--final-residual",
            "--out", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "results.json").read_text())
    assert cli["final_fit"] == res["final_fit"] and cli["final_fit_views"] == res["final_fit_views"]


def test_stepping_equals_run_and_accepts_overrides(room):
    whole = saresgs.ActiveRun(room, method="fvs", **SHORT).run()
    run = saresgs.ActiveRun(room, method="fvs", **SHORT)
    proposals = []
    while True:
        run.train_phase()
        if run.finished:
            break
        proposal = run.next_view()
        assert proposal["view"] in proposal["candidates"] and len(proposal["scores"]) == len(proposal["candidates"])
        assert run.next_view()["view"] == proposal["view"]  # computed once per phase
        proposals.append(proposal["view"])
        run.add_view(proposal["view"])
    stepped = run.finish()
    assert stepped["selected_view_indices"] == whole["selected_view_indices"]
    assert stepped["final_fit"] == whole["final_fit"] and stepped["psnr"] == whole["psnr"]
    # A caller may hold a view of its own instead of the method's.
    other = saresgs.ActiveRun(room, method="fvs", **SHORT)
    choice = other.next_view()["view"]
    mine = next(v for v in room.train if v not in other.held and v != choice)
    other.add_view(mine)
    assert other.held[-1] == mine
    with pytest.raises(ValueError, match="held"):
        other.add_view(mine)
    with pytest.raises(RuntimeError, match="add views"):
        other.finish()


def test_selector_errors_are_clear(room):
    with pytest.raises(ValueError, match="not a candidate"):
        saresgs.ActiveRun(room, selector=lambda ctx: ctx.held[0], **SHORT).run()
    with pytest.raises(ZeroDivisionError):
        saresgs.ActiveRun(room, selector=lambda ctx: 1 // 0, **SHORT).run()
    kept = []
    saresgs.ActiveRun(room, selector=lambda ctx: kept.append(ctx) or ctx.candidates[0], **dict(SHORT, max_views=5)).run()
    with pytest.raises(RuntimeError, match="during the call"):
        kept[0].held


def test_selector_sees_the_model_and_scores(room):
    seen = {}

    def fisher_like(ctx):
        scores = ctx.fisher_scores()
        seen["n"] = len(ctx.gaussians)
        rgb, depth, alpha = ctx.render(ctx.candidates[0])
        seen["shape"] = rgb.shape
        best = int(np.argmax(scores))
        return ctx.candidates[best], scores

    custom = saresgs.ActiveRun(room, selector=fisher_like, **SHORT).run()
    fisher = saresgs.ActiveRun(room, method="fisher", **SHORT).run()
    # argmax of the same scores with ties to the lowest index: fisher's own choices.
    assert custom["selected_view_indices"] == fisher["selected_view_indices"]
    assert custom["steps"][0]["scores"] == fisher["steps"][0]["scores"]
    assert seen["n"] > 0 and seen["shape"] == (48, 64, 3)


def test_prefilter_scores_equal_the_cli(room, tmp_path):
    views = room.train[:3]
    # By name: the CLI reads numbers in --views as positions in the train list.
    run_cli("coverage", "--dataset", room.source, "--views", ",".join(room.names[v] for v in views), "--out", tmp_path / "cov")
    cli = json.loads((tmp_path / "cov" / "coverage.json").read_text())
    py = saresgs.coverage(room, views)
    names = room.names
    assert [c["view"] for c in cli["candidates"]] == [names[v] for v in py["candidates"]]
    assert [c["score"] for c in cli["candidates"]] == py["scores"]
    assert [c["rank"] for c in cli["candidates"]] == py["ranks"]
    assert cli["observed_voxels"] == py["observed_voxels"] and cli["scene_voxels"] == py["scene_voxels"]
    assert cli["prefilter_regime"] == py["prefilter_regime"]
    exact = saresgs.coverage(room, views, encoding="exact", score="new")
    assert exact["prefilter_regime"]["encoding"] == "exact" and max(exact["scores"]) > 0


def test_write_leaves_the_clis_files_and_the_run_page(room, tmp_path):
    run = saresgs.ActiveRun(room, method="fvs", **SHORT)
    run.run()
    out = tmp_path / "w"
    page = run.write(str(out))
    for name in ("results.json", "point_cloud.ply", "final_fit.ply", "cameras.json", "report.html"):
        assert (out / name).exists(), name
    assert page["path"] == str(out / "report.html")
    assert page["bytes"] == (out / "report.html").stat().st_size
    # the page carries the run's results.json as written
    html = (out / "report.html").read_text()
    start = html.index('id="saresgs-data">') + len('id="saresgs-data">')
    data = json.loads(html[start:html.index("</script>", start)])
    assert data["kind"] == "run"
    assert data["results"] == json.loads((out / "results.json").read_text())
    assert [v["name"] for v in data["views"]] == [v["name"] for v in data["results"]["final_fit"]["views"]]
    assert all(v["render"].startswith("data:image/jpeg;base64,") for v in data["views"])
    # without it: the files only
    assert run.write(str(tmp_path / "plain"), report=False) is None
    assert not (tmp_path / "plain" / "report.html").exists()
