"""Datasets, cameras, the model's arrays and rendering, against the CLI and by hand."""
import importlib.util
import json

import numpy as np
import pytest

import saresgs
from conftest import REPO, run_cli


def test_dataset_arrays(room):
    assert len(room) == 40 and len(room.train) + len(room.test) == 40
    cam = room.camera(room.train[0])
    w2c = cam.world_to_camera
    assert w2c.shape == (4, 4)
    np.testing.assert_allclose(w2c[:3, :3], cam.R)
    np.testing.assert_allclose(w2c[:3, 3], cam.t)
    # The centre maps to the camera origin; a point ahead projects inside the image.
    np.testing.assert_allclose(cam.R @ cam.center + cam.t, 0, atol=1e-9)
    img = room.image(room.train[0])
    assert img.shape == (48, 64, 3) and img.dtype == np.uint8 and not img.flags.writeable
    assert room.points.shape[1] == 3 and room.points.shape[0] == room.point_colors.shape[0] > 100
    # A room of metres about the origin is computed in its own world coordinates.
    assert room.frame_scale == 1.0 and np.array_equal(room.frame_center, np.zeros(3))
    assert 1.0 <= room.extent < 10.0


def test_bad_input_is_a_clear_error(tmp_path):
    with pytest.raises(ValueError, match="nowhere"):
        saresgs.load_dataset(str(tmp_path / "nowhere"))
    g = saresgs.Gaussians(np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 4)), np.zeros(2), np.zeros((2, 1, 3)))
    with pytest.raises(ValueError, match="means"):
        g.means = np.zeros((3, 3))
    with pytest.raises(ValueError, match="sh"):
        saresgs.Gaussians(np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 4)), np.zeros(2), np.zeros((2, 5, 3)))


def test_model_views_and_ply_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    n = 50
    g = saresgs.Gaussians(rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) - 2, rng.normal(size=(n, 4)),
                          rng.normal(size=n), rng.normal(size=(n, 16, 3)))
    assert g.max_sh_degree == 3 and len(g) == n
    g.means[0, 0] = 42.0  # a view: writes reach the model
    assert g.means[0, 0] == 42.0
    g.write_ply(str(tmp_path / "m.ply"))
    h = saresgs.Gaussians.read_ply(str(tmp_path / "m.ply"))
    for name in ("means", "log_scales", "rotations", "opacities", "sh"):
        np.testing.assert_array_equal(getattr(g, name), getattr(h, name))


def test_python_render_equals_the_cli(room, tmp_path):
    # The CLI trains a model and scores each test view; Python renders the same .ply from the
    # same cameras: every per-view PSNR must come out identical (a different pixel would not).
    out = tmp_path / "train"
    run_cli("train", "--dataset", room.source, "--iterations", 60, "--threads", 1, "--out", out)
    report = json.loads((out / "results.json").read_text())
    g = saresgs.Gaussians.read_ply(str(out / "point_cloud.ply"))
    per_view = {v["name"]: v["psnr"] for v in report["views"]} if "views" in report else None
    assert per_view, sorted(report)
    names = room.names
    for v in room.test:
        rgb, depth, alpha = saresgs.render(g, room.camera(v), sh_degree=0, background=room.background or (0, 0, 0))
        assert rgb.shape == (48, 64, 3) and depth.shape == alpha.shape == (48, 64)
        assert per_view[names[v]] == saresgs.psnr(rgb, room.image_float(v)), names[v]
    # A trained model loaded into a trainer renders as the function does, and trains on.
    t = saresgs.Trainer(room, seed=0, threads=1)
    t.gaussians = g
    assert len(t.gaussians) == len(g)
    rgb_t, _, _ = t.render(room.camera(room.test[0]))
    rgb_f, _, _ = saresgs.render(g, room.camera(room.test[0]), sh_degree=0, background=room.background or (0, 0, 0))
    np.testing.assert_array_equal(rgb_t, rgb_f)
    t.train(room.train[:2], 3)
    assert t.iteration == 3 and np.isfinite(t.evaluate()["psnr"])


def _small_model(seed=1):
    rng = np.random.default_rng(seed)
    n = 12
    means = np.column_stack([rng.uniform(-0.6, 0.6, n), rng.uniform(-0.4, 0.4, n), rng.uniform(2.5, 4.0, n)])
    return saresgs.Gaussians(means, np.full((n, 3), -1.6) + rng.uniform(-0.3, 0.3, (n, 3)),
                             rng.normal(size=(n, 4)), rng.uniform(-1, 1, n), rng.normal(scale=0.5, size=(n, 4, 3)))


def _smooth_model(seed=4):
    # Wide Gaussians (sigma >= 13 px) near the axis at moderate opacity: every pixel of the
    # 32 x 24 image lies inside every Gaussian's alpha >= 1/255 ellipse and no pixel's
    # transmittance reaches 1e-4, so no threshold of the rasterizer is crossed by the finite
    # differences' steps and the render is smooth in every parameter.
    rng = np.random.default_rng(seed)
    n = 6
    means = np.column_stack([rng.uniform(-0.2, 0.2, n), rng.uniform(-0.15, 0.15, n), rng.uniform(2.8, 3.2, n)])
    return saresgs.Gaussians(means, rng.uniform(0.35, 0.6, (n, 3)), rng.normal(size=(n, 4)), rng.uniform(-1, 0, n),
                             rng.normal(scale=0.5, size=(n, 4, 3)))


def test_render_gradient_matches_finite_differences():
    g = _smooth_model()
    cam = saresgs.Camera(32, 24, 30.0, 30.0, 16.0, 12.0)
    w = np.random.default_rng(2).normal(size=(24, 32, 3)).astype(np.float32)

    def loss(model):
        rgb, _, _ = saresgs.render(model, cam, threads=1)
        return float(np.sum(rgb.astype(np.float64) * w))

    grad = saresgs.render_gradient(g, cam, w, threads=1)
    checked = 0
    for name, eps in (("means", 1e-3), ("log_scales", 1e-3), ("opacities", 1e-3), ("sh", 1e-3)):
        analytic = getattr(grad, name).reshape(-1)
        order = np.argsort(-np.abs(analytic))[:6]  # the largest entries: well above float noise
        for k in order:
            plus, minus = g.copy(), g.copy()
            getattr(plus, name).reshape(-1)[k] += eps
            getattr(minus, name).reshape(-1)[k] -= eps
            fd = (loss(plus) - loss(minus)) / (2 * eps)
            assert fd == pytest.approx(analytic[k], rel=3e-2, abs=2e-2 * np.abs(analytic).max()), (name, k)
            checked += 1
    assert checked == 24


def test_loss_and_gradient_is_consistent():
    g = _small_model()
    cam = saresgs.Camera(32, 24, 30.0, 30.0, 16.0, 12.0)
    target = np.random.default_rng(3).uniform(size=(24, 32, 3)).astype(np.float32)
    loss, grad = saresgs.loss_and_gradient(g, cam, target, threads=1)
    # A small step against the gradient lowers the loss.
    step = g.copy()
    step.sh = g.sh - 1e-2 * grad.sh / (np.abs(grad.sh).max() + 1e-12)
    assert saresgs.loss_and_gradient(step, cam, target, threads=1)[0] < loss


def test_a_dataset_in_millimetres_is_computed_in_its_own_frame(room, tmp_path):
    """The room written in millimetres (scripts/experiments/frame_trials.py's frames) loads into the
    room's own coordinates; a trained model's .ply holds millimetres and maps back."""
    spec = importlib.util.spec_from_file_location("frame_trials", REPO / "scripts" / "experiments" / "frame_trials.py")
    frames = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(frames)
    frames.write_frame(room.source, str(tmp_path / "mm"), [(1e3, (0.0, 0.0, 0.0))])
    mm = saresgs.load_dataset(str(tmp_path / "mm"))
    assert mm.frame_scale == 1e3 and np.array_equal(mm.frame_center, np.zeros(3))
    assert mm.extent == pytest.approx(room.extent, rel=1e-12)
    for i in range(len(room)):
        np.testing.assert_allclose(mm.camera(i).center, room.camera(i).center, atol=1e-9)
    np.testing.assert_allclose(mm.points, room.points, atol=1e-9)
    t = saresgs.Trainer(mm, seed=0)
    t.train(mm.train[:4], 10)
    t.save_ply(str(tmp_path / "mm.ply"))
    world = saresgs.Gaussians.read_ply(str(tmp_path / "mm.ply"))
    internal = t.gaussians
    np.testing.assert_allclose(world.means, 1e3 * internal.means, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(world.log_scales, internal.log_scales + np.log(1e3), atol=1e-5)
    np.testing.assert_allclose(world.from_world(mm).means, internal.means, rtol=1e-6, atol=1e-9)
    np.testing.assert_array_equal(internal.to_world(room).means, internal.means)  # the identity frame


def test_background_is_said_once_for_the_images_and_the_renders(tmp_path):
    """An RGBA object (Blender folder): its images are composited on the background asked
    for, and a Trainer renders against that same one."""
    folder = tmp_path / "object"
    run_cli("scene", "--layout", "object", "--views", 16, "--width", 32, "--height", 24, "--format", "blender",
            "--out", folder)
    white = saresgs.load_dataset(str(folder))
    assert white.background == (1.0, 1.0, 1.0) and white.background_from == "manifest" and not white.random_background
    black = saresgs.load_dataset(str(folder), background="black")
    assert black.background == (0.0, 0.0, 0.0) and black.background_from == "background="
    tinted = saresgs.load_dataset(str(folder), background=(0.2, 0.4, 0.6))
    v = white.train[0]
    iw, ib, it = white.image(v).astype(int), black.image(v).astype(int), tinted.image(v).astype(int)
    # Pixels the object does not cover show the background; covered ones are the same.
    empty = (iw == 255).all(axis=2) & (ib == 0).all(axis=2)
    assert empty.sum() > 50 and (iw != ib).any(axis=2).sum() >= empty.sum()
    np.testing.assert_array_equal(it[empty], np.tile([51, 102, 153], (int(empty.sum()), 1)))
    assert saresgs.load_dataset(str(folder), background="random").random_background
    for bad in ("purple", "1,1", (1, 2), (0, 0, 2)):
        with pytest.raises((ValueError, TypeError), match="background"):
            saresgs.load_dataset(str(folder), background=bad)
    # A Trainer given a background renders against it: white minus black is the uncovered
    # share of each pixel, 1 - alpha.
    tw = saresgs.Trainer(white, seed=0, threads=1)
    tb = saresgs.Trainer(white, seed=0, threads=1, background="black")
    cam = white.camera(v)
    rw, _, alpha = tw.render(cam)
    rb, _, _ = tb.render(cam)
    np.testing.assert_allclose(rw - rb, np.repeat((1 - alpha)[..., None], 3, axis=2), atol=1e-5)
    assert (1 - alpha).max() > 0.5
    # The dataset it was given keeps its own.
    assert white.background == (1.0, 1.0, 1.0)
