"""saresgs from Python: datasets, rendering, training, view scoring and active runs.

A thin layer over the C++ libraries (the `_core` extension, pybind11): NumPy arrays in and
out, the GIL released during long calls, Ctrl-C honoured at every training iteration.

    import saresgs
    ds = saresgs.load_dataset("out/builtin")
    run = saresgs.ActiveRun(ds, selector=lambda ctx: ctx.candidates[0], seed=0)
    print(run.run()["final_fit"]["psnr"])

Reference: docs/PYTHON.md; every function and class has a docstring (help(saresgs.X)).
"""
import sys as _sys

try:
    import numpy as _numpy  # noqa: F401  (the module's arrays are NumPy arrays)
except ImportError as _e:
    raise ImportError(
        f"saresgs needs NumPy in this interpreter ({_sys.executable}): on Debian, "
        "`apt install python3-numpy` and run Debian's /usr/bin/python3, the interpreter the module "
        "is built for (build/python/interpreter.txt names it)") from _e
if _sys.version_info[:2] != (3, 11):
    raise ImportError(f"saresgs was built for Python 3.11, this is {_sys.version.split()[0]} ({_sys.executable}); "
                      "rebuild with -DPython3_EXECUTABLE=... or use /usr/bin/python3")

from ._core import (  # noqa: F401,E402
    ActiveRun,
    Camera,
    Dataset,
    Gaussians,
    InputError,
    SelectionContext,
    Trainer,
    active_settings,
    coverage,
    fisher_scores,
    fvs_scores,
    load_dataset,
    loss_and_gradient,
    make_scene,
    methods,
    psnr,
    render,
    render_gradient,
    ssim,
    train_settings,
)

__all__ = [
    "ActiveRun", "Camera", "Dataset", "Gaussians", "InputError", "SelectionContext", "Trainer",
    "active_settings", "coverage", "fisher_scores", "fvs_scores", "load_dataset", "loss_and_gradient", "make_scene",
    "methods", "psnr", "render", "render_gradient", "ssim", "train_settings",
]
