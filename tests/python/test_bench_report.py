"""Tests of the bench page (`make bench`, reports/caplab_report/bench.py) and of the error series
runner (scripts/bench-error): the Pareto front and the Richardson extrapolation on known inputs,
the checks of the series file, the page from a hand-made bench.json and hand-made run directories,
and the runner with a fake caplab (caplab is not run). Run with
`/usr/bin/python3 -m pytest -q tests/python/test_bench_report.py`."""

from __future__ import annotations

import copy
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "reports"))

import fakes  # noqa: E402
from caplab_report import bench  # noqa: E402
from pages import CHROMIUM, PYTHON, assert_self_contained, parse  # noqa: E402

SERIES = REPO / "solver" / "bench" / "error_series.json"


# ---- Pareto front ----------------------------------------------------------------------------------

def test_pareto_front_known_points():
    pts = [(10.0, 0.10),   # 0 front: cheapest
           (20.0, 0.05),   # 1 front
           (20.0, 0.08),   # 2 dominated by 1 (same cost, larger error)
           (40.0, 0.05),   # 3 dominated by 1 (same error, larger cost)
           (80.0, 0.01),   # 4 front: most accurate
           (50.0, 0.20),   # 5 dominated by everything cheaper
           (float("nan"), 0.001),  # 6 no wall time: never on the front
           (5.0, None)]    # 7 no error
    assert bench.pareto_front(pts) == [0, 1, 4]


def test_pareto_front_ties_all_kept():
    # identical points: neither dominates the other, both stay; a point beaten by the tie goes
    pts = [(10.0, 0.1), (10.0, 0.1), (10.0, 0.2), (30.0, 0.01)]
    assert bench.pareto_front(pts) == [0, 1, 3]
    assert bench.pareto_front([]) == []
    assert bench.pareto_front([(1.0, 0.0)]) == [0]


# ---- Richardson ----------------------------------------------------------------------------------

def test_richardson_observed_order_recovers_limit():
    hs = [0.1, 0.05, 0.025, 0.2]  # unsorted, one coarse point that is not used
    fs = [1.0 + 3.0 * h ** 2 for h in hs]
    r = bench.richardson(hs, fs)
    assert r["value"] == pytest.approx(1.0, abs=1e-9)
    assert r["order"] == pytest.approx(2.0, abs=1e-6)
    # non-constant ratios
    hs = [1 / 40, 1 / 50, 1 / 70]
    r = bench.richardson(hs, [2.0 - 0.5 * h for h in hs])
    assert r["value"] == pytest.approx(2.0, abs=1e-9) and r["order"] == pytest.approx(1.0, abs=1e-6)


def test_richardson_rejects_what_it_cannot_extrapolate():
    assert bench.richardson([0.1, 0.05, 0.025], [1.0, 1.1, 1.05])["value"] is None  # oscillating
    assert bench.richardson([0.1, 0.05], [1.0, 1.1])["value"] is None               # too few for "observed"
    fixed = bench.richardson([0.1, 0.05], [1.2, 1.1], order=1)
    assert fixed["value"] == pytest.approx(1.0)
    assert bench.richardson([0.1, 0.1, 0.05], [1.0, 1.0, 1.1])["value"] is None     # repeated spacing


# ---- the series file -------------------------------------------------------------------------------

def test_real_series_file_loads_and_names_levels():
    data = bench.load_series(SERIES, REPO)
    ids = [f["id"] for f in data["families"]]
    assert ids == ["cylinder_re100", "capsule_circle", "sphere_nh"]
    for fam in data["families"]:
        assert bench.points_of(fam, True), f"{fam['id']}: no quick points"
        levels = {p["level"] for p in fam["points"] if "level" in p}
        assert levels == {"quick", "standard", "thesis"}, fam["id"]


def _bad(tmp_path, mutate) -> str:
    data = json.loads(SERIES.read_text())
    mutate(data)
    path = tmp_path / "series.json"
    path.write_text(json.dumps(data))
    with pytest.raises(bench.SeriesError) as err:
        bench.load_series(path, REPO)
    return str(err.value)


@pytest.mark.parametrize("mutate, pointer, value", [
    (lambda d: d["families"][0].update(case="catalogue/ch2/nope.json"), "/families/0/case", '"catalogue/ch2/nope.json"'),
    (lambda d: d["families"][1]["points"][0].update(label="a14"), "/families/1/points/1/label", '"a14"'),
    (lambda d: d["families"][2]["points"][1].update(colour="red"), "/families/2/points/1/colour", '"red"'),
    (lambda d: d["families"][0]["points"][0]["set"].update({"numerics.grid": {"x": 1}}),
     "/families/0/points/0/set/numerics.grid", '{"x": 1}'),
    (lambda d: d["families"][0]["metrics"][0]["references"][0].update(value="1.438"),
     "/families/0/metrics/0/references/0/value", '"1.438"'),
    (lambda d: d["families"][0]["metrics"][0]["references"][1]["points"].append("h99"),
     "/families/0/metrics/0/references/1/points/4", '"h99"'),
    (lambda d: d["families"][2]["points"][0].update(level="standard"), "/families/2/points/0/level", None),
    (lambda d: d["families"][1].update(fidelity="best"), "/families/1/fidelity", '"best"'),
    (lambda d: d.update(families=[]), "/families", "[]"),
])
def test_series_errors_name_file_path_and_value(tmp_path, mutate, pointer, value):
    message = _bad(tmp_path, mutate)
    assert message.startswith(str(tmp_path / "series.json") + ": " + pointer + ":"), message
    if value is not None:
        assert f"(got {value}" in message, message


def test_series_not_json(tmp_path):
    path = tmp_path / "broken.json"
    path.write_text("{\"families\": [")
    with pytest.raises(bench.SeriesError, match="broken.json: not JSON"):
        bench.load_series(path, REPO)


# ---- hand-made inputs ------------------------------------------------------------------------------

def bench_json() -> dict:
    env = {"build": {"version": "0.1", "git_sha": "feedfacefeedfacefeedface", "git_dirty": True, "compiler": "GNU 12.2.0",
                     "flags": "-O3 -march=native", "build_type": "Release"},
           "host": "benchhost", "cpu_model": "Bench CPU 9000", "hardware_threads": 2, "threads": 2,
           "date_utc": "2026-12-02T10:00:00Z", "usable_processors": 2, "llc_bytes_reported": 0}

    def row(kind, lat, col, prec, t, mlups, roof, **extra):
        q = 9 if lat == "D2Q9" else 19
        size = 8 if prec == "float" else 16
        r = {"kind": kind, "lattice": lat, "collision": col, "precision": prec, "threads": t,
             "size": [64] * (2 if lat == "D2Q9" else 3), "updates_per_step": 4096, "steps": 100, "seconds": 1.0,
             "mlups": mlups, "mlups_best_batch": mlups * 1.05, "cpu_share": 0.97, "bytes_per_update": q * size // 8 * 8,
             "bandwidth_gbs": 20.0, "roofline_mlups": roof, "roofline_mlups_copy": roof * 0.8, "fraction": mlups / roof}
        r.update(extra)
        return r

    return {"schema": "caplab.bench/1", "environment": env, "load_average": {"start": [0.5, 0.4, 0.3], "end": [1.5, 1, 1]},
            "options": {"threads": [1, 2], "quick": False, "stream_repetitions": 10, "stream_array_mib": 64},
            "warnings": ["a test warning from caplab bench"],
            "bandwidth": {"convention": "STREAM counting", "runs": [
                {"threads": 1, "when": "before", "copy_gbs": 10.0, "update_gbs": 12.5},
                {"threads": 1, "when": "after", "copy_gbs": 11.0, "update_gbs": 13.75}],
                "per_threads": [{"threads": 1, "copy_gbs": 11.0, "triad_gbs": 10.5, "update_gbs": 13.75, "validated": True},
                                {"threads": 2, "copy_gbs": 20.0, "triad_gbs": 19.0, "update_gbs": 25.0, "validated": True}]},
            "roofline": "roofline_mlups = copy GB/s / bytes_per_update", "mlups_definition": "steps x updates / s",
            "rows": [row("uniform", "D2Q9", "trt", "double", 1, 61.1, 76.4),
                     row("uniform", "D3Q19", "trt", "float", 2, 98.7, 131.6),
                     row("two_level", "D2Q9", "trt", "double", 1, 40.0, 76.4, fine_size=[32, 32], fine_fraction=0.4,
                         coupling_share=0.3, overhead_vs_uniform=0.5275)]}


def results_tree(root: Path) -> Path:
    """results/standard with a cylinder run (family cylinder), a 2D capsule run and a diverged
    3D run: the moving and ch6 families have none."""
    std = root / "standard"
    fakes.make_run_dir(std / "ch2__cylinder_re100", fakes.cylinder_case(), "standard", "pass")
    fakes.make_capsule_run_dir(std / "ch3__circle_G0.04_Eb0", fakes.capsule_case("ch3/circle_G0.04_Eb0", "circle"),
                               "standard")
    fakes.make_run_dir(std / "ch5__sphere_nh_G0.05", fakes.cylinder_case("ch5/sphere_nh_G0.05"), "standard", "diverged")
    return root


def error_results(root: Path, series: dict) -> Path:
    """Run directories and stamps as scripts/bench-error leaves them, for the cylinder family's
    full points: h30-h70 finished with Cd = 1.43 + 4 h^2 (so Richardson gives 1.43), h20 failed,
    the quick level stale (other overrides in its stamp), the others not run."""
    fam = series["families"][0]
    base = root / fam["id"]
    for p in fam["points"]:
        if p.get("quick"):
            continue
        label = p["label"]
        h = p["set"].get("numerics.grid.fine_spacing")
        stamp = {"case_id": "ch2/cylinder_re100", "case_file": str(REPO / fam["case"]), "fidelity": p["fidelity"],
                 "overrides": bench.point_overrides(p), "threads": 1, "exit_code": 0, "meaning": "ok"}
        if label == "h20":
            stamp.update(exit_code=3, meaning="diverged")
            (base / label).mkdir(parents=True)
            fakes.write_json(base / label / "manifest.json", {"status": "diverged", "error": "NaN at step 812"})
        elif label == "quick":
            stamp["overrides"] = ["numerics.end_time=99"]
            fakes.make_run_dir(base / label, fakes.cylinder_case(), "quick")
        elif label in ("h30", "h40", "h50", "h60", "h70", "h50_u0.1"):
            run = fakes.make_run_dir(base / label, fakes.cylinder_case(), "standard")
            manifest = json.loads((run / "manifest.json").read_text())
            manifest.update(wall_time_s=1000.0 * (0.02 / h) ** 3, mlups=12.5, lattice={"node_updates": 1e9 / h},
                            threads=1)
            fakes.write_json(run / "manifest.json", manifest)
            summary = json.loads((run / "summary.json").read_text())
            cd = 1.43 + 4 * h * h + (0.02 if label == "h50_u0.1" else 0)
            summary["metrics"]["drag_coefficient_mean"]["value"] = cd
            summary["metrics"]["strouhal_number"]["value"] = 0.165 + 0.5 * h * h
            fakes.write_json(run / "summary.json", summary)
        else:
            continue
        base.mkdir(parents=True, exist_ok=True)
        fakes.write_json(base / f"{label}.reproduce.json", stamp)
    return root


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bench")
    (tmp / "bench.json").write_text(json.dumps(bench_json()))
    series = bench.load_series(SERIES, REPO)
    res = error_results(tmp / "error", series)
    results = results_tree(tmp / "results")
    out = tmp / "out"
    built = bench.build_page(tmp / "bench.json", out, results, "standard", SERIES, res, "auto", REPO / "catalogue",
                             pdf=CHROMIUM is not None)
    return {"page": built, "out": out, "html": built.html.read_text(encoding="utf-8"), "tmp": tmp}


def test_page_shows_environment_roofline_and_overhead(page):
    html = page["html"]
    for needle in ("Bench CPU 9000", "feedfacefeed+dirty", "GNU 12.2.0", "-O3 -march=native", "2026-12-02T10:00:00Z",
                   "a test warning from caplab bench", "Timings are not pass/fail"):
        assert needle in html, needle
    assert "80.0 %" in html        # 61.1 / 76.4 roofline fraction
    assert "75.0 %" in html        # 98.7 / 131.6
    assert "+52.8 %" in html       # two-level overhead
    assert "data:image/png;base64," in html
    assert page["page"].problems == [] or all("PDF" not in p for p in page["page"].problems)


def test_page_stage_shares_per_family(page):
    html = page["html"]
    table = parse(page["page"].html).rows
    rows = {r[0]: r for r in table[1:]}
    cyl = rows["ch2 cylinder (fixed bodies)"]
    assert cyl[1].startswith("1 (")
    assert "80.0 %" in cyl[3]                                   # fluid share of fakes.make_run_dir
    caps = rows["2D capsules (ch2-4)"]
    assert "25.0 %" in " ".join(caps)                         # IB + membrane = 0.15 + 0.10
    for fam in ("ch2 moving bodies (prescribed motion)", "3D capsules near walls and other shapes (ch6)",
                "3D capsules (ch5)"):
        assert "not run" in " ".join(rows[fam]), fam
    assert "status &#39;diverged&#39;, not counted" in html or "status 'diverged', not counted" in html


def test_page_error_section(page):
    html = page["html"]
    assert "Shown here: the <b>full</b> set" in html
    assert "make bench-error" in html
    assert "observed order 2.00" in html                      # Richardson on 1.43 + 4 h^2
    assert "1.43" in html
    assert "references/cylinder/table_2_1.csv#Present:cd_re100" in html
    assert "exit code 3 (diverged)" in html and "NaN at step 812" in html
    assert "stale" in html and "not run" in html
    assert "★" in html
    assert 'alt="error against wall time, cylinder_re100"' in html
    for fam in ("capsule_circle", "sphere_nh"):
        assert f'id="error-{fam}"' in html
    assert_self_contained(page["out"])


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed")
def test_page_pdf(page):
    pdf = page["out"] / "index.pdf"
    assert pdf.is_file() and pdf.read_bytes()[:5] == b"%PDF-"


def test_front_marks_the_right_points(tmp_path):
    series = bench.load_series(SERIES, REPO)
    res = error_results(tmp_path, series)
    view = bench.family_view(series["families"][0], res, False, bench.ReferenceLibrary(REPO / "references"))
    rich = view["metrics"][0]["references"][1]
    assert rich["value"] == pytest.approx(1.43, abs=1e-9)
    # the error to 1.43 falls with h while the wall time rises: every finished grid point is on
    # the front; h50_u0.1 (same time as h50, larger error) is not
    assert rich["front"] == ["h30", "h40", "h50", "h60", "h70"]
    by = {p.label: p for p in view["points"]}
    assert by["h20"].state == "failed" and by["quick"].state == "stale" and by["standard"].state == "not run"


def test_page_without_inputs_says_so(tmp_path):
    built = bench.build_page(tmp_path / "missing.json", tmp_path / "out", tmp_path / "none", "standard",
                             tmp_path / "no-series.json", tmp_path / "none", pdf=False)
    html = built.html.read_text(encoding="utf-8")
    assert "missing.json: not found" in html
    assert "no-series.json: cannot read" in html
    assert html.count("not run") >= 5


# ---- scripts/bench-error with a fake caplab ------------------------------------------------------------

FAKE_CAPLAB = """#!{python}
# Fake `caplab run CASE --fidelity F --out DIR --set P=V ... --threads N`: a finished run whose
# drag coefficient is 1.4 + 3 h^2 (h = numerics.grid.fine_spacing); one file per call in $FAKE_CALLS.
import json, os, sys, uuid
sys.path.insert(0, {here!r})
import fakes
args = sys.argv[1:]
assert args[0] == "run", args
case = json.load(open(args[1]))
out = args[args.index("--out") + 1]
for i, a in enumerate(args):
    if a == "--set":
        k, v = args[i + 1].split("=", 1)
        node = case
        keys = k.split(".")
        for part in keys[:-1]:
            node = node.setdefault(part, {{}})
        node[keys[-1]] = json.loads(v)
h = case["numerics"]["grid"]["fine_spacing"]
label = os.path.basename(out.rstrip("/"))
open(os.path.join(os.environ["FAKE_CALLS"], label + "." + uuid.uuid4().hex), "w").close()
if h > 0.09:
    print("error: unstable", file=sys.stderr)
    sys.exit(3)
fakes.make_run_dir(out, case, args[args.index("--fidelity") + 1], "pass")
summary = json.load(open(os.path.join(out, "summary.json")))
summary["metrics"]["drag_coefficient_mean"]["value"] = 1.4 + 3 * h * h
json.dump(summary, open(os.path.join(out, "summary.json"), "w"))
"""


def small_series(tmp_path: Path, h_last: float = 0.025) -> Path:
    case = tmp_path / "cylinder.json"
    fakes.write_json(case, fakes.cylinder_case())

    def pt(label, h, **kw):
        return {"label": label, "set": {"numerics.grid.fine_spacing": h}, **kw}

    series = {"description": "test", "families": [
        {"id": "cyl", "title": "cylinder", "case": str(case),
         "metrics": [{"name": "drag_coefficient_mean", "symbol": "Cd", "references": [
             {"kind": "external", "value": 1.438, "source": "references/cylinder/table_2_1.csv#Present:cd_re100"},
             {"kind": "richardson", "over": "numerics.grid.fine_spacing", "points": ["h20", "h40", "h80"],
              "quick_points": ["q1", "q2"], "order": 2}]}],
         "points": [pt("h20", 0.05), pt("h40", h_last), pt("h80", 0.0125), pt("q1", 0.1, quick=True),
                    pt("q2", 0.05, quick=True), {"label": "standard", "level": "standard", "set": {}}]},
        {"id": "other", "title": "another family", "case": str(case),
         "metrics": [{"name": "drag_coefficient_mean", "references": [
             {"kind": "external", "value": 1.4, "source": "references/cylinder/table_2_1.csv#Present:cd_re100"}]}],
         "points": [pt("x", 0.05)]}]}
    path = tmp_path / "series.json"
    fakes.write_json(path, series)
    return path


@pytest.fixture
def runner(tmp_path):
    caplab = tmp_path / "caplab"
    caplab.write_text(FAKE_CAPLAB.format(python=PYTHON, here=str(HERE)))
    caplab.chmod(0o755)
    calls = tmp_path / "calls"
    calls.mkdir()
    results = tmp_path / "results"

    def run(*extra, series=None):
        cmd = [PYTHON, str(REPO / "scripts" / "bench-error"), "--caplab", str(caplab), "--results", str(results),
               "--series", str(series or small_series(tmp_path)), "--threads", "1", *extra]
        if "--report" in extra:
            cmd.remove("--report")
            cmd += ["--bench-out", str(tmp_path / "page"), "--no-pdf"]
        else:
            cmd.append("--no-report")
        return subprocess.run(cmd, env=dict(os.environ, FAKE_CALLS=str(calls)), capture_output=True, text=True,
                              timeout=120)

    def count(label=None):
        return len([p for p in calls.iterdir() if label is None or p.name.startswith(label + ".")])

    return {"run": run, "count": count, "results": results, "caplab": caplab, "tmp": tmp_path}


def test_runner_runs_then_skips_then_reruns_changed(runner):
    run, count, results = runner["run"], runner["count"], runner["results"]
    first = run("--only", "cyl")
    assert first.returncode == 0, first.stdout + first.stderr
    assert count() == 4 and count("x") == 0          # the full points of family cyl only
    stamp = json.loads((results / "cyl" / "h40.reproduce.json").read_text())
    assert stamp["overrides"] == ["numerics.grid.fine_spacing=0.025"] and stamp["threads"] == 1
    assert "--set" in stamp["command"] and stamp["command"][-2:] == ["--threads", "1"]
    again = run("--only", "cyl")
    assert again.returncode == 0 and count() == 4, again.stdout     # nothing changed: all skipped
    assert again.stdout.count("skipped") == 4
    # one point's overrides change: only that point runs again
    changed = run("--only", "cyl", series=small_series(runner["tmp"], h_last=0.02))
    assert changed.returncode == 0 and count("h40") == 2 and count() == 5, changed.stdout
    # a new binary: every point runs again
    with open(runner["caplab"], "a") as fh:
        fh.write("# rebuilt\n")
    rebuilt = run("--only", "cyl", series=small_series(runner["tmp"], h_last=0.02))
    assert rebuilt.returncode == 0 and count() == 9


def test_runner_quick_failure_and_page(runner):
    run, count = runner["run"], runner["count"]
    proc = run("--quick", "--report")
    assert proc.returncode == 1, proc.stdout + proc.stderr          # q1 at h = 0.1 "diverges"
    assert count("q1") == 1 and count("q2") == 1 and count() == 2
    assert "cyl/q1 (exit 3 (diverged))" in proc.stdout
    html = (runner["tmp"] / "page" / "index.html").read_text(encoding="utf-8")
    assert "Shown here: the <b>quick</b> set" in html
    assert "exit code 3 (diverged)" in html
    assert "1 finished point(s); 2 needed" in html                 # no Richardson value without q1


def test_runner_bad_series_and_family(runner, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"families": [{"id": "x"}]}))
    proc = runner["run"](series=bad)
    assert proc.returncode == 2
    assert f"{bad}: /families/0/title: expected a non-empty string (got null)" in proc.stderr
    proc = runner["run"]("--only", "nope")
    assert proc.returncode != 0 and "--only nope: no such family; the series has cyl, other" in proc.stderr
    assert runner["count"]() == 0


def test_point_started_and_not_finished_says_whether_it_is_running(tmp_path):
    """A point whose stamp has no exit code and whose manifest says "running": running now while a
    caplab holds its directory's lock, killed once nobody does."""
    import fcntl
    import os
    series = bench.load_series(SERIES, REPO)
    fam = series["families"][0]
    point = next(p for p in fam["points"] if not p.get("quick"))
    base = tmp_path / fam["id"]
    run = fakes.make_run_dir(base / point["label"], fakes.cylinder_case(), point["fidelity"], "running")
    fakes.write_json(base / f"{point['label']}.reproduce.json",
                     {"case_id": "ch2/cylinder_re100", "case_file": str(REPO / fam["case"]),
                      "fidelity": point["fidelity"], "overrides": bench.point_overrides(point), "threads": 1})
    fd = os.open(run, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        live = bench.read_point(fam, point, tmp_path)
    finally:
        os.close(fd)
    killed = bench.read_point(fam, point, tmp_path)
    assert live.state == killed.state == "running"
    assert "running now" in live.message and "killed" in killed.message, (live.message, killed.message)
