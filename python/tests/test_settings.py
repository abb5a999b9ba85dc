"""ActiveRun's keywords are the settings table that `saresgs active`'s flags come from."""
import re

import numpy as np
import pytest

import saresgs
from conftest import run_cli


def test_every_setting_is_a_flag_of_the_command_line_and_a_keyword():
    settings = saresgs.active_settings()
    names = [s["name"] for s in settings]
    assert len(names) == len(set(names)) and "max_views" in names and "plain_refit" in names
    help_text = run_cli("active", "--help").stdout
    flags = set(re.findall(r"^\s+(--[a-z0-9-]+)", help_text, re.M))
    for s in settings:
        assert s["flag"] in flags, s["flag"]
        assert s["flag"].replace("--no-", "--").lstrip("-").replace("-", "_") == s["name"]
    # What the command line has beyond the table describes where a run reads and writes.
    extra = flags - {s["flag"] for s in settings}
    assert extra == {"--dataset", "--out", "--memory-budget", "--replay", "--downscale", "--background",
                     "--resume"}, extra
    by_name = {s["name"]: s for s in settings}
    assert by_name["plain_refit"]["default"] is True and by_name["max_views"]["default"] is None
    assert by_name["fvs_metric"]["choices"] == ["euclidean", "great-circle"]


def test_a_keyword_outside_the_table_or_its_range_is_refused_by_name(room):
    with pytest.raises(TypeError, match="max_view"):
        saresgs.ActiveRun(room, max_view=5)
    with pytest.raises(saresgs.InputError, match=r"max_views.*>= 1"):
        saresgs.ActiveRun(room, max_views=0)
    with pytest.raises(saresgs.InputError, match=r"gate_keep.*\[0, 1\]"):
        saresgs.ActiveRun(room, gate_keep=2.0)
    with pytest.raises(saresgs.InputError, match="fvs_metric"):
        saresgs.ActiveRun(room, fvs_metric="manhattan")
    with pytest.raises(saresgs.InputError, match="prefilter_set"):
        saresgs.ActiveRun(room, prefilter_set="sphere")
    with pytest.raises(TypeError, match="interval"):
        saresgs.ActiveRun(room, interval=object())


def test_numpy_numbers_count_as_the_numbers_they_hold(room):
    run = saresgs.ActiveRun(room, method="random", seed=np.int64(2), max_views=np.int32(6), gate_keep=np.float32(0.25),
                            threads=1)
    assert run.method == "random"


def test_the_trainers_keywords_are_the_train_commands_flags(room):
    settings = saresgs.train_settings()
    help_text = run_cli("train", "--help").stdout
    flags = set(re.findall(r"^\s+(--[a-z0-9-]+)", help_text, re.M))
    assert {s["flag"] for s in settings} <= flags
    by_name = {s["name"]: s for s in settings}
    assert by_name["max_sh_degree"]["flag"] == "--sh-degree" and by_name["max_sh_degree"]["default"] == 3
    t = saresgs.Trainer(room, seed=1, threads=1, densify_until=50, schedule_scale=0.5)
    t.train(room.train[:3], 2)
    assert t.iteration == 2
    with pytest.raises(TypeError, match="sh_degree"):
        saresgs.Trainer(room, sh_degree=2)
    with pytest.raises(saresgs.InputError, match="max_sh_degree"):
        saresgs.Trainer(room, max_sh_degree=4)
