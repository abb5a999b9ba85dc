"""The grid report (saresgs report GRID_DIR) of a committed grid, in a real browser: every
job listed, every Markdown table the grid wrote shown with the same cells."""
import json
import pathlib

from conftest import REPO, problems, probe, run_cli

GRID = REPO / "results" / "small"


def markdown_tables(path):
    """The pipe tables of a Markdown file, cells trimmed, the alignment row dropped."""
    tables, cur = [], None
    for line in path.read_text().splitlines():
        t = line.strip()
        if not t.startswith("|"):
            cur = None
            continue
        cells = [c.strip() for c in t.strip("|").split("|")]
        if cur is None:
            cur = []
            tables.append(cur)
        if len(cur) == 1 and all(c and set(c) <= set(":-") for c in cells):
            continue
        cur.append(cells)
    return tables


def test_grid_report_lists_every_job_and_the_markdown_tables(tmp_path):
    page = tmp_path / "grid.html"
    r = run_cli("report", GRID, "--out", page)
    jobs = sorted(p.name for p in (GRID / "runs").iterdir() if p.is_dir())
    assert f"{len(jobs)} jobs" in r.stdout
    expr = ("({jobs: Array.from(document.querySelectorAll('#jobs-table tbody tr')).map((tr) => tr.getAttribute('data-job')), "
            "links: Array.from(document.querySelectorAll('#jobs-table tbody a')).map((a) => a.getAttribute('href')), "
            "files: Array.from(document.querySelectorAll('.md-file')).map((f) => [f.getAttribute('data-file'), "
            "Array.from(f.querySelectorAll('table')).map((t) => Array.from(t.rows).map((row) => "
            "Array.from(row.cells).map((c) => c.textContent)))]), "
            "curves: Array.from(document.querySelectorAll('.scene-curve')).map((c) => c.getAttribute('data-scene'))})")
    seen = probe(page, expr, tmp_path)
    errors, outside = problems(seen, page)
    assert errors == [] and outside == []
    res = seen["result"]
    assert sorted(res["jobs"]) == jobs
    # every link, relative to the page wherever it was written, reaches the job's page or results
    assert len(res["links"]) == len([j for j in jobs if any((GRID / "runs" / j / f).exists() for f in ("results.json", "sweep.json"))])
    for href in res["links"]:
        target = (page.parent / href).resolve()
        assert target.exists() and target.name in ("results.json", "report.html", "sweep.json"), href
    md = sorted((GRID / "tables").glob("*.md"))
    assert [f for f, _ in res["files"]] == [p.name for p in md]
    for (name, shown), p in zip(res["files"], md):
        assert shown == markdown_tables(p), name
    # one curve per scene with finished active jobs
    scenes = sorted({j.split("__")[0] for j in jobs if (GRID / "runs" / j / "results.json").exists()})
    assert sorted(res["curves"]) == scenes


def test_a_folder_that_is_neither_run_nor_grid_is_refused(tmp_path):
    r = run_cli("report", tmp_path, check=False)
    assert r.returncode != 0
    assert "results.json" in r.stderr
