"""Tests of the moving-body part of the report (reports/caplab_report/moving.py) and of the thesis
statements in references/moving/ (claims.json, provenance.json); run with
`/usr/bin/python3 -m pytest -q tests/python`.

Two kinds of fixture: moving_runs/ holds five finished quick runs of the catalogue (the two
cylinders, the hovering wing, their uniform-grid twins and the Wang 2004 wing; series.h5 cut down
to the columns the report uses, see moving_runs/README.md), so that the numbers the report
computes are checked on real output; and hand-built runs with made-up series, so that every check
is shown to fail where it must. The statements are checked by the built caplab (`caplab claims`,
solver/score/motion_claims.hpp; reports/caplab_report/claims.py finds it): `make build` first."""

from __future__ import annotations

import copy
import html as htmllib
import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "reports"))

from caplab_report import capsule, moving  # noqa: E402
from caplab_report import references as refmod  # noqa: E402
from caplab_report.runs import Run, discover, load_run  # noqa: E402
from pages import PYTHON, assert_self_contained, parse, summary  # noqa: E402

RUNS = HERE / "moving_runs"
CLAIMS = REPO / "references" / "moving" / "claims.json"
PROVENANCE = REPO / "references" / "moving" / "provenance.json"
THESIS = HERE.parents[2] / "shared" / "thesis.txt"  # shared/ beside the checkout
CASES = ["ch2/two_cylinders_re40", "ch2/two_cylinders_re40_uniform", "ch2/hovering_wing_re157",
         "ch2/hovering_wing_re157_uniform", "extra/hovering_wing_wang2004", "extra/hovering_wing_wang2004_uniform"]
CHECK_TYPES = {"proximity_means", "twin", "refinement", "fine_fraction"}


def claims() -> dict[str, dict]:
    return {c["id"]: c for c in json.loads(CLAIMS.read_text(encoding="utf-8"))["claims"]}


def library() -> refmod.ReferenceLibrary:
    return refmod.ReferenceLibrary(REPO / "references")


SETTINGS = json.loads(PROVENANCE.read_text(encoding="utf-8"))["consistency"]


def judge(claim: dict, runs: list[Run]) -> moving.StatementCheck:
    return moving.check_statement(claim, runs, {}, SETTINGS)


def text(html: str, sep: str = " ") -> str:
    return " ".join(htmllib.unescape(re.sub(r"<[^>]+>", sep, html)).split())


def claim_row(html: str, claim_id: str) -> str:
    rows = re.findall(rf'<tr id="claim-{re.escape(claim_id.replace(".", "-"))}">(.*?)</tr>', html, re.S)
    assert len(rows) == 1, f"{len(rows)} rows for claim {claim_id}"
    return text(rows[0])


def fixture_runs() -> dict[str, Run]:
    return {r.case_id: r for r in discover(RUNS)}


# ---- the report built from the five quick runs --------------------------------------------------------

@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("moving_report")
    catalogue, out = root / "catalogue", root / "out"
    for case_id in CASES:  # the real case files; the Wang twin has no run: it must show as missing
        target = catalogue / (case_id + ".json")
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(REPO / "catalogue" / (case_id + ".json"), target)
    proc = subprocess.run([PYTHON, str(REPO / "scripts" / "report"), "--results", str(RUNS), "--out", str(out),
                           "--catalogue", str(catalogue), "--references", str(REPO / "references"), "--no-pdf"],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    html = {ch: (out / ch / "index.html").read_text(encoding="utf-8") for ch in ("chapter2", "extra")}
    return {"out": out, "proc": proc, "html": html}


def section(html: str, start: str, end: str = 'id="cases"') -> str:
    return html[html.index(f'id="{start}"'):html.index(end)]


def test_pages_hold_the_section_apart_from_the_capsules(built):
    ch2, extra = built["html"]["chapter2"], built["html"]["extra"]
    for anchor in ("moving", "moving-statements", "moving-verification"):
        assert f'id="{anchor}"' in ch2, anchor
    assert 'id="moving-validation"' in extra and 'id="moving-statements"' not in extra  # no thesis statement there
    assert 'id="capsules"' not in ch2  # the capsule section did not take the moving statements as its own
    assert_self_contained(built["out"])
    assert not re.search(r"^report: (ch2|extra): ", built["proc"].stderr, re.M), built["proc"].stderr
    rows = summary(parse(built["out"] / "extra" / "index.html"))
    assert rows["extra/hovering_wing_wang2004_uniform"]["verdict"] == "MISSING"
    # figures: two families on ch2 (cylinders, wing); the validation figure on extra
    assert len(re.findall(r"<img ", section(ch2, "moving"))) == 2
    assert len(re.findall(r"<img ", section(extra, "moving"))) == 1
    # validation and consistency are named as such
    page = text(section(ch2, "moving"))
    assert "caplab against caplab" in page and "not external data" in page
    assert "Validation of moving bodies against external data (the Wang 2004 wing" in page
    assert "Reference data not available" in page and "Xu & Wang 2006 figure 2.12" in page


def test_drag_trend_as_defined_fails_on_the_quick_runs(built):
    row = claim_row(built["html"]["chapter2"], "ch2.two_cylinders.drag_trend")
    assert "INCONSISTENT" in row
    assert "From the results it is seen that the drag force increases" in row
    assert "The windows are caplab's choice" in row  # how the windows were chosen, said on the page
    assert "baseline: 1.86, approaching in close proximity: 1.585, moving away in close proximity: 1.558" in row
    assert "uniform (quick) : baseline: 1.856, approaching in close proximity: 1.588" in row
    # the drag does rise before the cylinders pass abreast: the extremes are shown
    assert "max 2.287 at dx = 1.8" in row and "min 0.8544 at dx = 0.202" in row


def test_method_statements_on_the_quick_runs(built):
    html = built["html"]["chapter2"]
    twin = claim_row(html, "ch2.two_cylinders.uniform_twin")
    assert "INCONSISTENT" in twin and "upper C_d 1.78 %; upper C_l 3.50 % (at most 2.00 %)" in twin
    wing = claim_row(html, "ch2.hovering_wing.twin")
    assert "CONSISTENT" in wing and "C_d 0.44 %; C_l 0.36 %" in wing and "derived" in wing
    fraction = claim_row(html, "ch2.two_cylinders.fine_fraction")
    assert "CONSISTENT" in fraction and "24.06 % as set, 23.79 % as built (thesis 24.1 %" in fraction
    assert "node updates twin/two-block 2.75 (saving 63.60 %)" in fraction and "not judged: noisy" in fraction
    assert "no finished pair ch2/cylinder_re100 + uniform twin at fidelity quick" in fraction
    refinement = claim_row(html, "ch2.hovering_wing.refinement")
    assert "NOT ENOUGH RUNS" in refinement and "no finer grid at fidelity quick" in refinement


def test_verification_tables_on_the_quick_runs(built):
    page = text(section(built["html"]["chapter2"], "moving-verification"))
    for expected in ("upper.lift_coefficient 0.0565 1.614 3.50 %", "lower.drag_coefficient 0.0891 4.532 1.97 %",
                     "24.06 % / 23.79 %", "7.652e+09 / 2.102e+10 2.75", "4.4 min / 11.7 min 2.67", "29.2 / 30",
                     "C_d 2.43 % PASS -0.3847 2–4", "C_l 1.40 % PASS 0.6176 2–4", "C_l 1.45 % PASS 0.6172 2–4"):
        assert expected in page, expected
    assert "caplab's choice, not a thesis number" in page


def test_validation_recomputes_the_scorer_and_the_yardstick(built):
    page = text(section(built["html"]["extra"], "moving-validation"))
    for expected in ("Robotic-wing experiment, drag", "Viscous vortex particle simulation, lift",
                     "0.6577 0.6577 140 0.688 PASS", "0.07819 0.07819 165 0.288 PASS",
                     "0.506 / 0.548 0.548", "0.226 / 0.21 0.226", "validation (external data)"):
        assert expected in page, expected
    assert "extra/hovering_wing_wang2004_uniform (quick) MISSING No finished run" in page


# ---- the numbers, computed by the module from the quick runs -------------------------------------------

def test_numbers_of_the_quick_runs():
    runs = list(fixture_runs().values())
    c = claims()
    trend = judge(c["ch2.two_cylinders.drag_trend"], runs)
    assert trend.verdict == "inconsistent" and len(trend.parts) == 2 and trend.parts[0].ok is False
    r = {run.case_id: run for run in runs}
    d = moving.series(r["ch2/two_cylinders_re40"], {})
    prox = moving.proximity_means(d["t"], d["upper.x"], d["lower.x"], d["upper.drag_coefficient"],
                                  c["ch2.two_cylinders.drag_trend"]["check"])
    assert prox.encounter == pytest.approx(24.0, abs=0.01) and prox.sign == 1.0
    assert prox.baseline.mean == pytest.approx(1.8605, abs=1e-4) and prox.baseline.samples == 40
    approaching, separating = prox.windows  # the means of the figure are the ones caplab judged
    assert approaching.mean == pytest.approx(1.5851, abs=1e-4) and separating.mean == pytest.approx(1.5582, abs=1e-4)
    assert "mean 1.585 over 30 samples" in trend.parts[0].details[1] and "✗" in trend.parts[0].details[1]
    assert "mean 1.558 over 30 samples" in trend.parts[0].details[2] and "✓" in trend.parts[0].details[2]
    tw = moving.twin_of(r["ch2/two_cylinders_re40"], runs)
    assert tw is r["ch2/two_cylinders_re40_uniform"]
    e = moving.series(tw, {})
    lift = moving.relative_rms(d["t"], d["upper.lift_coefficient"], e["t"], e["upper.lift_coefficient"], 0.5)
    assert lift.relative == pytest.approx(0.0350, abs=2e-4)
    assert moving.fine_fraction(r["ch2/two_cylinders_re40"].case) == pytest.approx(22 * 5.6 / 512, rel=1e-12)
    cost = moving.cost(r["ch2/two_cylinders_re40"], tw)
    assert cost.node_ratio == pytest.approx(21020697600 / 7651776000, rel=1e-12)
    wing = moving.series(r["ch2/hovering_wing_re157"], {})
    period = moving.period_of(r["ch2/hovering_wing_re157"])
    assert period == pytest.approx(math.pi * 2.5, rel=1e-12)
    p, n = moving.periodicity(wing["t"], wing["lift_coefficient"], period)
    assert n == 4 and p == pytest.approx(0.0140, abs=2e-4)
    mean, n = moving.period_mean(wing["t"], wing["lift_coefficient"], period, 2)
    assert mean == pytest.approx(0.6176, abs=1e-4) and mean > 0  # upward, as the case's orientation expects


# ---- hand-built runs: every check must be able to fail ------------------------------------------------

def fixture_case(case_id: str) -> dict:
    return json.loads((RUNS / "quick" / case_id.replace("/", "__") / "case.json").read_text(encoding="utf-8"))


def write_run(path: Path, case: dict, columns: dict[str, np.ndarray], node_updates: float = 1e9,
              wall: float = 100.0, status: str = "ok", fidelity: str = "quick") -> Run:
    path.mkdir(parents=True, exist_ok=True)
    (path / "case.json").write_text(json.dumps(case), encoding="utf-8")
    manifest = {"status": status, "case_id": case["id"], "fidelity": fidelity, "wall_time_s": wall, "mlups": 10.0,
                "threads": 2, "lattice": {"node_updates": node_updates}}
    (path / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    (path / "score.json").write_text(json.dumps({"verdict": "pass", "sanity": {"verdict": "pass"},
                                                 "accuracy": {"verdict": "none", "entries": []}}), encoding="utf-8")
    with h5py.File(path / "series.h5", "w") as h5:
        for name, values in columns.items():
            h5.create_dataset(name, data=np.asarray(values, dtype=float))
    return load_run(path, case["id"], fidelity)


def cylinders(t: np.ndarray, drag: np.ndarray, lift_offset: float = 0.0) -> dict[str, np.ndarray]:
    """Columns of the two-cylinder case: the prescribed positions of the catalogue (x0 = 8) and a drag."""
    x_upper = np.where(t < 16, 8 + 16 - 4 / np.pi * np.sin(np.pi * t / 4), 8 + 32 - t)
    x_lower = np.where(t < 16, 8 + 4 / np.pi * np.sin(np.pi * t / 4), 8 + t - 16)
    lift = 0.5 * np.sin(t) + lift_offset
    return {"t": t, "upper.x": x_upper, "lower.x": x_lower, "upper.drag_coefficient": drag,
            "upper.lift_coefficient": lift, "lower.drag_coefficient": -drag, "lower.lift_coefficient": -lift}


T = np.arange(0.05, 32.0 + 1e-9, 0.05)
DX = 48 - 2 * T  # after t = 16


def bump_drag(approach: float, separation: float) -> np.ndarray:
    drag = np.full_like(T, 1.8)
    drag[(T >= 22.5) & (T < 24)] = approach    # 0 < dx <= 3
    drag[(T > 24) & (T <= 25.5)] = separation  # -3 <= dx < 0
    return drag


def test_proximity_check_passes_and_fails(tmp_path):
    claim = claims()["ch2.two_cylinders.drag_trend"]
    case = fixture_case("ch2/two_cylinders_re40")
    good = write_run(tmp_path / "good", case, cylinders(T, bump_drag(2.2, 1.2)))
    result = judge(claim, [good])
    assert result.verdict == "consistent", result.parts
    for approach, separation in ((1.5, 1.2), (2.2, 2.0), (1.8, 1.2)):  # no rise; no fall; equal is not above
        bad = write_run(tmp_path / f"bad{approach}{separation}", case, cylinders(T, bump_drag(approach, separation)))
        assert judge(claim, [bad]).verdict == "inconsistent", (approach, separation)
    # the bodies never pass each other: nothing to judge
    columns = cylinders(T, bump_drag(2.2, 1.2))
    columns["lower.x"] = columns["lower.x"] - 40
    stuck = write_run(tmp_path / "stuck", case, columns)
    result = judge(claim, [stuck])
    assert result.verdict == "not checked" and "never changes sign" in result.parts[0].text
    # a missing run (no directory) is about nothing
    missing = Run(case_id=case["id"], fidelity="quick", case=case, status="missing")
    assert judge(claim, [missing]).verdict == "no run"


def test_opposing_drag_follows_the_direction_of_motion():
    """The lower cylinder moves along +x: its C_d is negative where it opposes the motion."""
    columns = cylinders(T, bump_drag(2.2, 1.2))
    spec = {"baseline": {"dx": "[-10, -6]", "phase": "approaching"},
            "windows": [{"name": "a", "dx": "[-3, 0)", "phase": "approaching", "expect": "above"},
                        {"name": "s", "dx": "(0, 3]", "phase": "separating", "expect": "below"}]}
    prox = moving.proximity_means(T, columns["lower.x"], columns["upper.x"], columns["lower.drag_coefficient"], spec)
    assert prox.sign == -1.0 and prox.baseline.mean == pytest.approx(1.8)
    assert [w.mean for w in prox.windows] == [pytest.approx(2.2), pytest.approx(1.2)]
    with pytest.raises(ValueError):
        moving.proximity_means(T, columns["lower.x"], columns["upper.x"], columns["lower.drag_coefficient"],
                               dict(spec, baseline={"dx": "[-10, -6]", "phase": "before"}))


def test_intervals_and_encounter():
    i = moving.parse_interval("(0, 3]")
    assert list(i.contains(np.array([0.0, 1e-9, 3.0, 3.0001]))) == [False, True, True, False]
    assert list(moving.parse_interval("[-3, 0)").contains(np.array([-3.0, 0.0]))) == [True, False]
    for bad in ("0, 3", "(3, 0]", "[a, b]", ""):
        with pytest.raises(ValueError):
            moving.parse_interval(bad)
    assert moving.encounter_time(np.array([0.0, 1.0, 2.0]), np.array([1.0, 0.5, -0.5])) == pytest.approx(1.5)
    assert moving.encounter_time(np.array([0.0, 1.0]), np.array([1.0, 2.0])) is None


def test_relative_rms():
    t = np.linspace(0, 10, 1001)
    ref = np.sin(t)
    d = moving.relative_rms(t, ref + 0.01, t, ref, 0.0)
    assert d.relative == pytest.approx(0.01, rel=1e-3)
    # other sampling: the larger direction is kept, the answer does not depend on who is interpolated
    t2 = np.linspace(0, 10, 377)
    assert moving.relative_rms(t2, np.sin(t2) + 0.01, t, ref, 0.0).relative == pytest.approx(0.01, rel=2e-2)
    # the start is left out of the difference and of the peak
    spiky = ref.copy()
    spiky[t < 0.5] = 50.0
    assert moving.relative_rms(t, spiky, t, ref, 0.5).relative == pytest.approx(0.0, abs=1e-12)
    assert moving.relative_rms(t, spiky, t, ref, 0.0).relative > 1.0
    nan = ref.copy()
    nan[500] = np.nan
    assert math.isnan(moving.relative_rms(t, nan, t, ref, 0.0).relative)


def test_twin_check_and_pairing(tmp_path):
    claim = claims()["ch2.two_cylinders.uniform_twin"]
    two, uni = fixture_case("ch2/two_cylinders_re40"), fixture_case("ch2/two_cylinders_re40_uniform")
    drag = bump_drag(2.2, 1.2)
    a = write_run(tmp_path / "a", two, cylinders(T, drag), node_updates=1e9)
    same = write_run(tmp_path / "b", uni, cylinders(T, drag), node_updates=3e9)
    assert moving.twin_of(a, [a, same]) is same and moving.twin_of(same, [a, same]) is None
    result = judge(claim, [a, same])
    assert result.verdict == "consistent" and "upper C_l 0.00 %" in result.parts[0].text
    off = write_run(tmp_path / "c", uni, cylinders(T, drag, lift_offset=0.05))  # 0.05 over the peak 0.55
    result = judge(claim, [a, off])
    assert result.verdict == "inconsistent" and "upper C_l 9.09 %" in result.parts[0].text
    # not a twin: other physics, other fine spacing, other fidelity
    other = copy.deepcopy(uni)
    other["physics"]["reynolds"] = 41
    coarser = copy.deepcopy(uni)
    coarser["numerics"]["grid"]["fine_spacing"] = 0.05
    runs = [a, write_run(tmp_path / "d", other, cylinders(T, drag)), write_run(tmp_path / "e", coarser, cylinders(T, drag))]
    assert moving.twin_of(a, runs) is None
    assert judge(claim, runs).verdict == "not enough runs"
    standard = load_run(tmp_path / "b", uni["id"], "standard")
    assert moving.twin_of(a, [a, standard]) is None


def test_fine_fraction_and_cost_checks(tmp_path):
    claim = claims()["ch2.two_cylinders.fine_fraction"]
    two, uni = fixture_case("ch2/two_cylinders_re40"), fixture_case("ch2/two_cylinders_re40_uniform")
    cols = cylinders(T, bump_drag(2.2, 1.2))
    a = write_run(tmp_path / "a", two, cols, node_updates=1e9)
    b = write_run(tmp_path / "b", uni, cols, node_updates=3e9)
    result = judge(claim, [a, b])
    assert result.verdict == "consistent" and [p.ok for p in result.parts] == [True, True, None]
    # the uniform grid cheaper than the two-block one: no saving
    cheap = write_run(tmp_path / "c", uni, cols, node_updates=0.5e9)
    assert judge(claim, [a, cheap]).verdict == "inconsistent"
    # a fine block of another size than the thesis's 24.1 %
    bigger = copy.deepcopy(two)
    bigger["numerics"]["grid"]["fine_region"]["max"] = [28, 11.6]
    big = write_run(tmp_path / "d", bigger, cols)
    assert moving.fine_fraction(bigger) == pytest.approx(23 * 5.6 / 512)
    assert judge(claim, [big, b]).parts[0].ok is False
    # the saving must be smaller than that of section 2.2.1 (a fixed-cylinder pair with a larger saving passes)
    cyl = json.loads((REPO / "catalogue" / "ch2" / "cylinder_re100.json").read_text(encoding="utf-8"))
    cyl_uni = json.loads((REPO / "catalogue" / "ch2" / "cylinder_re100_uniform.json").read_text(encoding="utf-8"))
    cyl_uni["numerics"]["grid"]["fine_spacing"] = cyl["numerics"]["grid"]["fine_spacing"]
    cyl_cols = {"t": T, "drag_coefficient": np.ones_like(T), "lift_coefficient": np.zeros_like(T)}
    for ratio, ok in ((10.0, True), (2.0, False)):
        p = write_run(tmp_path / f"cyl{ratio}", cyl, cyl_cols, node_updates=1e9)
        q = write_run(tmp_path / f"cyl{ratio}u", cyl_uni, cyl_cols, node_updates=ratio * 1e9)
        result = judge(claim, [a, b, p, q])
        assert result.parts[-1].ok is ok and result.verdict == ("consistent" if ok else "inconsistent"), result.parts[-1].text


def test_refinement_check(tmp_path):
    """The thesis's grid (1/64) against the finer member of the study at the same fidelity."""
    claim = claims()["ch2.hovering_wing.refinement"]
    quick = fixture_case("ch2/hovering_wing_re157")  # 1/32
    case = copy.deepcopy(quick)
    case["numerics"]["grid"]["fine_spacing"] = 1 / 64
    finer = copy.deepcopy(case)
    finer["id"] = "ch2/hovering_wing_re157_grid128"
    finer["numerics"]["grid"]["fine_spacing"] = 1 / 128
    t = np.arange(0.02, 31.42, 0.02)
    base = {"t": t, "drag_coefficient": np.cos(0.8 * t), "lift_coefficient": 1 + np.sin(0.8 * t)}

    def standard(name, doc, cols):
        return write_run(tmp_path / name, doc, cols, fidelity="standard")

    a = standard("a", case, base)
    assert judge(claim, [a]).verdict == "not enough runs"
    assert judge(claim, [a, standard("b", finer, base)]).verdict == "consistent"
    c = standard("c", finer, dict(base, drag_coefficient=1.2 * np.cos(0.8 * t)))
    assert judge(claim, [a, c]).verdict == "inconsistent"
    # another fidelity is not a partner; a grid coarser than the statement's is not judged
    assert judge(claim, [a, write_run(tmp_path / "d", finer, base)]).verdict == "not enough runs"
    coarse = judge(claim, [write_run(tmp_path / "e", quick, base), write_run(tmp_path / "f", case, base)])
    assert coarse.verdict == "not enough runs"


def test_periodicity_and_period_means():
    period = 2.0
    t = np.arange(0.0, 8.0 + 1e-9, 0.01)
    y = np.sin(2 * np.pi * t / period)
    p, n = moving.periodicity(t, y, period)
    assert n == 4 and p == pytest.approx(0.0, abs=1e-9)
    drifting, _ = moving.periodicity(t, y + 0.2 * t, period)
    assert drifting > 0.05  # fails the 5 % of provenance.json
    assert moving.periodicity(t[t <= 5.0], y[t <= 5.0], period) is None  # two full periods only
    mean, n = moving.period_mean(t, 0.3 + y, period, 2)
    assert mean == pytest.approx(0.3, abs=1e-6) and n == 4


def test_validation_cross_check_must_be_able_to_fail(tmp_path):
    src = RUNS / "quick" / "extra__hovering_wing_wang2004"
    dst = tmp_path / "quick" / src.name
    shutil.copytree(src, dst)
    score = json.loads((dst / "score.json").read_text(encoding="utf-8"))
    score["accuracy"]["entries"][0]["error"] *= 0.5  # a scorer that disagrees with its own definition
    (dst / "score.json").write_text(json.dumps(score), encoding="utf-8")
    run = load_run(dst, "extra/hovering_wing_wang2004", "quick")
    v = moving.validation(run, library(), [run], {}, figure=False)
    assert [r.agrees for r in v.rows] == [False, True, True, True]
    assert len(v.problems) == 1 and "the report recomputes 0.657693" in v.problems[0]
    yard = {y.metric: y.larger for y in v.yardsticks}
    assert yard["drag_coefficient"] == pytest.approx(0.548, abs=1e-3) and yard["lift_coefficient"] == pytest.approx(0.226, abs=1e-3)


def test_capsule_section_does_not_take_the_moving_statements():
    lib = library()
    assert any(ds.benchmark == "moving" for ds, _ in lib.claims("ch2."))
    view = moving.without_statements(lib)
    assert not any(ds.benchmark == "moving" for ds, _ in view.claims("ch2."))
    assert any(ds.benchmark == "capsule2d" for ds, _ in view.claims("ch2."))
    section = capsule.build([], view, "ch2")
    assert not section.present and lib.get("moving", "claims.json") is not None  # the library itself is untouched


# ---- references/moving ----------------------------------------------------------------------------------

def test_claims_are_well_formed():
    doc = json.loads(CLAIMS.read_text(encoding="utf-8"))
    ids = [c["id"] for c in doc["claims"]]
    assert len(ids) == len(set(ids))
    assert {"ch2.two_cylinders.drag_trend", "ch2.two_cylinders.uniform_twin", "ch2.two_cylinders.fine_fraction",
            "ch2.hovering_wing.twin"} <= set(ids)
    lib = library()
    assert not lib.problems, lib.problems
    catalogue = {json.loads(p.read_text(encoding="utf-8")).get("id") for p in (REPO / "catalogue").rglob("*.json")}
    for c in doc["claims"]:
        assert c["id"].startswith("ch2."), c["id"]
        assert c.get("section") in ("2.2.2", "2.2.3") and c.get("sentence"), c["id"]
        assert c.get("basis") in ("stated", "derived") and (c["basis"] == "stated" or c.get("derivation")), c["id"]
        assert c["kind"] in ("trend", "bound", "value") and refmod.claim_summary(c), c["id"]
        assert c["check"]["type"] in CHECK_TYPES and c["check"].get("basis"), c["id"]
        assert set(c["cases"]) <= catalogue, c["id"]
        assert moving.describe(c, 0.5) and "malformed" not in moving.describe(c, 0.5), c["id"]
        if c["check"]["type"] in ("twin", "refinement"):
            assert 0 < c["upper"] < 0.1 and c["check"]["columns"], c["id"]
        if c["check"]["type"] == "proximity_means":
            for w in [c["check"]["baseline"]] + c["check"]["windows"]:
                moving.parse_interval(w["dx"])
    assert claims()["ch2.two_cylinders.fine_fraction"]["value"] == 0.241


@pytest.mark.skipif(not THESIS.is_file(), reason="thesis text not beside the checkout")
def test_claim_sentences_are_verbatim():
    thesis = " ".join(THESIS.read_text(encoding="utf-8").split())
    for cid, c in claims().items():
        assert " ".join(c["sentence"].split()) in thesis, cid


def test_provenance_describes_claims_and_consistency():
    prov = json.loads(PROVENANCE.read_text(encoding="utf-8"))
    ds = prov["datasets"]["claims.json"]
    assert ds["kind"] == "statement" and ds["obtained"].startswith("stated in the thesis text")
    assert "caplab's reading" in ds["obtained"] and "not external data" in ds["note"]
    assert prov["consistency"]["periodicity"]["tolerance"] == 0.05
    assert moving.start_left_out(prov["consistency"]) == 0.5 and moving.start_left_out({}) == 0.0
    assert prov["consistency"]["periodicity"]["kind"] == "verification"
    assert "not_available" not in prov and "analytic" not in prov  # would be taken up by the capsule section
