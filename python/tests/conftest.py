"""Shared fixtures: the build tree's CLI and a small built-in scene made once per session."""
import os
import pathlib
import subprocess

import pytest

import saresgs

REPO = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(os.environ.get("SARESGS_BUILD", REPO / "build"))
CLI = BUILD / "apps" / "saresgs"


def run_cli(*args):
    """Runs the `saresgs` command line; raises with its output when it fails."""
    r = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    if r.returncode != 0:
        raise AssertionError(f"saresgs {' '.join(map(str, args))} failed ({r.returncode}):\n{r.stdout}\n{r.stderr}")
    return r


@pytest.fixture(scope="session")
def room(tmp_path_factory):
    """room360 at 64 x 48 with 40 views: small enough for seconds-long runs."""
    out = tmp_path_factory.mktemp("room360") / "scene"
    return saresgs.make_scene("room360", str(out), width=64, height=48, seed=0, views=40)
