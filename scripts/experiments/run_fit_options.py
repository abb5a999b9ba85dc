#!/usr/bin/env python3
"""Print a finished active run's final-fit options on one line, for the refit scripts beside it.

Read by scripts/experiments/refit_final_fit.sh and scripts/experiments/residual_refit.sh:

    dataset views seed final_fit_psnr final_fit_residual final_fit_iterations preset max_gaussians

views: the run's initial then selected views, comma-separated; the PSNR as repr(), so that a
refit can be compared to the last digit. Exits non-zero when the run has no final fit.

    python3 scripts/experiments/run_fit_options.py RUN/results.json
"""
import json
import sys

r = json.load(open(sys.argv[1]))
f = r["final_fit"]
print(r["dataset"], ",".join(r["initial_views"] + r["selected_views"]), r["seed"], repr(f["psnr"]), f["residual"],
      f["iterations"], r["preset"], r["options"]["max_gaussians"])
