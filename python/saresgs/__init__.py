"""saresgs from Python: datasets, rendering, training, view scoring and active runs.

A thin layer over the C++ libraries (the `_core` extension, pybind11): NumPy arrays in and
out, the GIL released during long calls, Ctrl-C honoured at every training iteration.

    import saresgs
    ds = saresgs.load_dataset("out/builtin")
    run = saresgs.ActiveRun(ds, selector=lambda ctx: ctx.candidates[0], seed=0)
    print(run.run()["final_fit"]["psnr"])

Reference: docs/PYTHON.md; every function and class has a docstring (help(saresgs.X)).
"""
from ._core import (  # noqa: F401
    ActiveRun,
    Camera,
    Dataset,
    Gaussians,
    InputError,
    SelectionContext,
    Trainer,
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
)

__all__ = [
    "ActiveRun", "Camera", "Dataset", "Gaussians", "InputError", "SelectionContext", "Trainer",
    "coverage", "fisher_scores", "fvs_scores", "load_dataset", "loss_and_gradient", "make_scene",
    "methods", "psnr", "render", "render_gradient", "ssim",
]
