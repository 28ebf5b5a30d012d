"""Tests of the capsule part of the report (reports/caplab_report/capsule.py) and of the thesis
statements in references/capsule2d/ (claims.json, provenance.json), on hand-built capsule run
directories (fakes.py); run with `/usr/bin/python3 -m pytest -q tests/python` after `make build`: the
verdicts of the statements are the built caplab's (`caplab claims`), which the report shows."""

from __future__ import annotations

import html as htmllib
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "reports"))

import fakes  # noqa: E402
from caplab_report import capsule  # noqa: E402
from caplab_report import references as refmod  # noqa: E402
from caplab_report.runs import load_run  # noqa: E402
from pages import CHROMIUM, PYTHON, assert_self_contained, chromium, parse, summary, write_case  # noqa: E402

CLAIMS = REPO / "references" / "capsule2d" / "claims.json"
THESIS = HERE.parents[2] / "shared" / "thesis.txt"  # shared/ beside the checkout
MODES = {"steady_tank_treading", "oscillating_tank_treading", "tumbling"}
KINDS = {"mode", "bracket", "trend", "bound", "value"}


def claims() -> dict[str, dict]:
    return {c["id"]: c for c in json.loads(CLAIMS.read_text(encoding="utf-8"))["claims"]}


# ---- fixture: capsule runs of chapters 2, 3 and 4 -----------------------------------------------

# (case, behaviour of the fake run; None: in the catalogue, never run)
def capsule_runs():
    C = fakes.capsule_case
    ell = [
        (C("ch3/ellipse_G0.04_Eb0", bending_ratio=0, claim="ch3.ellipse.G0.04.Eb0",
           reference_mode="steady_tank_treading"), "steady_tank_treading"),
        # the run tank-treads steadily where the thesis states an oscillating inclination: must fail
        (C("ch3/ellipse_G0.04_Eb0.005", bending_ratio=0.005, claim="ch3.ellipse.G0.04.Eb0.005",
           reference_mode="oscillating_tank_treading"), "steady_tank_treading"),
        # reference_mode wider than the claim: passes in score.json, flagged against the claim
        (C("ch3/ellipse_G0.04_Eb0.02", bending_ratio=0.02, claim="ch3.ellipse.G0.04.Eb0.02",
           reference_mode=["oscillating_tank_treading", "steady_tank_treading"]), "oscillating_tank_treading"),
        (C("ch3/ellipse_G0.04_Eb0.04", bending_ratio=0.04, claim="ch3.ellipse.G0.04.Eb0.04",
           reference_mode="oscillating_tank_treading"), None),
        (C("ch3/ellipse_G0.04_Eb0.06", bending_ratio=0.06, claim="ch3.ellipse.G0.04.Eb0.06",
           reference_mode="tumbling"), "tumbling"),
        (C("ch3/ellipse_G0.04_Eb0.4", bending_ratio=0.4, claim="ch3.ellipse.G0.04.Eb0.4",
           reference_mode="tumbling"), "tumbling"),
        # its twin in a larger domain (Jeffery's orbit is scored there): same parameters, told apart by the domain
        (C("ch3/ellipse_G0.04_Eb0.4_domain32", bending_ratio=0.4, domain=32.0, claim="ch3.ellipse.G0.04.Eb0.4",
           reference_mode="tumbling"), "tumbling"),
        (C("ch3/biconcave_G0.025_Eb0.02", shape="biconcave", capillary=0.025, bending_ratio=0.02, reynolds=0.027,
           claim="ch3.biconcave.G0.025.Eb0.02", reference_mode="tumbling"), "tumbling"),
    ]
    ch2 = [(C(f"ch2/capsule_circle_G0.0125_grid{n}", shape="circle", capillary=0.0125, fine_spacing=h),
            "steady_tank_treading") for n, h in ((20, 0.1), (40, 0.05), (60, 1 / 30))]
    ch2.append((C("ch2/capsule_circle_G0.04", shape="circle", capillary=0.04, claim="ch2.circle.mode",
                  reference_mode="steady_tank_treading"), "steady_tank_treading"))
    ch4 = [(C(f"ch4/circle_G0.04_Re{re}", shape="circle", capillary=0.04, reynolds=re, claim="ch4.mode",
              reference_mode="steady_tank_treading"), "steady_tank_treading") for re in (1, 10, 100)]
    # thesis fig. 4.3: the grid refined with the membrane (120 nodes on 2a = 30 spacings), and 240
    # instead of 160 nodes on the same grid
    ch4 += [(C(f"ch4/circle_G0.04_Re100_{tag}", shape="circle", capillary=0.04, reynolds=100, fine_spacing=h,
               nodes=n), "steady_tank_treading") for tag, h, n in (("grid30", 2 / 30, 120), ("nodes240", 0.05, 240))]
    return ell + ch2 + ch4


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("capsule_report")
    results, catalogue, out = root / "results", root / "catalogue", root / "out"
    for case, mode in capsule_runs():
        write_case(catalogue, case)
        if mode is not None:
            fakes.make_capsule_run_dir(results / "quick" / case["id"].replace("/", "__"), case, "quick", mode)
    proc = subprocess.run([PYTHON, str(REPO / "scripts" / "report"), "--results", str(results), "--out", str(out),
                           "--catalogue", str(catalogue), "--references", str(REPO / "references")]
                          + ([] if CHROMIUM else ["--no-pdf"]), capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    html = {ch: (out / f"chapter{ch}" / "index.html").read_text(encoding="utf-8") for ch in (2, 3, 4)}
    return {"root": root, "out": out, "proc": proc, "html": html, "text": {ch: text(h) for ch, h in html.items()}}


def text(html: str, sep: str = "") -> str:
    """What a reader sees: tags removed (replaced by ``sep``), entities decoded, spaces collapsed."""
    return " ".join(htmllib.unescape(re.sub(r"<[^>]+>", sep, html)).split())


def claim_row(html: str, claim_id: str) -> str:
    """The text of the row of ``claim_id`` in the statements table."""
    m = re.search(rf'<tr id="claim-{re.escape(claim_id.replace(".", "-"))}">(.*?)</tr>', html, re.S)
    assert m, f"no row for claim {claim_id}"
    return text(m.group(1), " ")


def scorecard_row(html: str, case_id: str) -> str:
    anchor = "case-" + case_id.replace("/", "__").replace(".", "-") + "-quick"
    section = html[html.index(f'id="{anchor}"'):]
    return text(section[section.index('<table class="scorecard">'):section.index("</table>")], " ")


# ---- the built report -----------------------------------------------------------------------------

def test_pages_and_verdicts(built):
    rows = summary(parse(built["out"] / "chapter3" / "index.html"))
    assert rows["ch3/ellipse_G0.04_Eb0.06"]["verdict"] == "PASS"
    assert rows["ch3/ellipse_G0.04_Eb0.005"]["accuracy"] == "FAIL"
    assert rows["ch3/ellipse_G0.04_Eb0.04"]["verdict"] == "MISSING"
    assert_self_contained(built["out"])
    assert not re.search(r"^report: ch\d: ", built["proc"].stderr, re.M), built["proc"].stderr  # no capsule problems


def test_families_overlay_runs_with_jeffery(built):
    page = built["text"][3]
    assert "elliptical (r = 2) capsules, minimum bending-energy shape: the initial shape" in page
    assert "biconcave (α = 1.39) capsules" in page
    # per family D_xy, inclination and contours; one time-history figure per run with a series; the
    # domain study of the E_b = 0.4 pair
    assert len(parse(built["out"] / "chapter3" / "index.html").imgs) == 2 * 3 + 7 + 1
    assert "Jeffery's orbit of a rigid ellipse with r = 2 from the initial angle(s) 0 rad" in page
    assert "verification, analytic" in page
    # the Jeffery verification table, labelled
    html = built["html"][3]
    section = text(html[html.index('id="capsule-verification"'):html.index('id="cases"')], " ")
    assert "π(1 + r²)/r = 7.8540" in section and "E_b = 0.4" in section
    # runs that differ only in the domain are labelled with it, in the table and the legends
    assert "E_b = 0.4 (domain 16 × 16)" in section and "E_b = 0.4 (domain 32 × 32)" in section
    assert "Domain size" in section


def test_scorecard_mode_rows_are_strings(built):
    html = built["html"][3]
    row = scorecard_row(html, "ch3/ellipse_G0.04_Eb0.005")
    assert "mode steady_tank_treading oscillating_tank_treading" in row  # metric, value, reference
    assert re.search(r"\bmismatch\b", row) and "FAIL" in row and "mode exact" in row and "is not the reference" in row
    row = scorecard_row(html, "ch3/ellipse_G0.04_Eb0.02")
    assert "oscillating_tank_treading or steady_tank_treading" in row
    assert re.search(r"\bmatch\b", row) and "PASS" in row
    assert "is not what the claim states" in row  # the wider reference_mode is flagged against the claim
    assert "thesis 3.2.2, fig. 3.10: “It is seen that without bending stiffness" in row  # the claim quoted


def test_thesis_statements_are_checked_against_the_runs(built):
    html = built["html"][3]
    assert 'id="capsule-validation"' in html and 'id="capsule-verification"' in html
    assert html.index('id="capsule-validation"') < html.index('id="capsule-verification"')
    assert "CONSISTENT" in claim_row(html, "ch3.ellipse.G0.04.Eb0.06")
    assert "When the reduced bending modulus reached 0.06" in claim_row(html, "ch3.ellipse.G0.04.Eb0.06")
    assert "INCONSISTENT" in claim_row(html, "ch3.ellipse.G0.04.Eb0.005")
    assert "NO RUN" in claim_row(html, "ch3.ellipse.G0.04.Eb0.04")  # only a missing run
    bracket = claim_row(html, "ch3.ellipse.G0.04.transition")
    assert "CONSISTENT" in bracket and "below the bracket" in bracket and "above the bracket" in bracket
    assert "CONSISTENT" in claim_row(html, "ch3.area_change")
    assert "derived" in claim_row(html, "ch3.ellipse.G0.125.Eb0.04")
    # every chapter 3 claim has a row
    for cid in claims():
        if cid.startswith("ch3."):
            claim_row(html, cid)
    assert "CONSISTENT" in claim_row(built["html"][4], "ch4.mode")
    assert "CONSISTENT" in claim_row(built["html"][4], "ch4.D_vs_Re")  # D grows with Re in the fakes


def test_not_available_reference_and_self_convergence(built):
    for page in (built["text"][2], built["text"][4]):
        assert "Reference data not available — thesis fig(s). 2.17, 4.4(a), 4.5(a)" in page
        assert "Breyiannis" in page and "grid-converged caplab self-reference" in page
    assert "Reference data not available" not in built["text"][3]
    ch2 = built["html"][2]
    section = ch2[ch2.index('id="capsule-verification"'):ch2.index('id="cases"')]
    assert "Self-convergence" in section and "self-reference" in section
    assert "ch2/capsule_circle_G0.0125_grid60, quick" in section  # the finest grid is the reference
    orders = [float(x) for x in re.findall(r'<td class="num">(\d+\.\d\d)</td></tr>', section)]
    assert orders and all(1.0 < p < 4.0 for p in orders), orders  # fakes: error ~ h^2


def test_a_node_study_is_not_mistaken_for_a_grid_study(built):
    ch4 = built["html"][4]
    section = ch4[ch4.index('id="capsule-verification"'):ch4.index('id="cases"')]
    grid = section[section.index("<b>Self-convergence</b>"):]
    grid = grid[:grid.index("</table>")]
    assert "ch4/circle_G0.04_Re100_grid30" in grid and "ch4/circle_G0.04_Re100_nodes240" not in grid
    assert "(ch4/circle_G0.04_Re100, quick) is the self-reference" in grid  # 160 nodes on 0.05a, the finest
    nodes = section[section.index("<b>Membrane nodes</b>"):]
    nodes = nodes[:nodes.index("</table>")]
    assert "(ch4/circle_G0.04_Re100_nodes240, quick) is the self-reference" in nodes
    assert "ch4/circle_G0.04_Re100</a>" in nodes and "grid30" not in nodes


def test_references_page_lists_claims_and_analytic(built):
    html = (built["out"] / "references.html").read_text(encoding="utf-8")
    assert f'id="{refmod.anchor_for("capsule2d", "claims.json")}"' in html
    for cid in claims():
        assert f"<code>{cid}</code>" in html, cid
    assert "10.1098/rspa.1922.0078" in html and "10.1103/PhysRevE.75.066301" in html
    assert "Not available — thesis fig(s). 2.17" in html


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed")
def test_screenshot_and_pdf(built):
    png = built["root"] / "chapter3.png"
    proc = chromium(f"--screenshot={png}", "--window-size=1280,3000",
                    (built["out"] / "chapter3" / "index.html").as_uri())
    assert png.is_file() and png.stat().st_size > 50_000, proc.stderr
    import matplotlib.image as mpimg
    img = mpimg.imread(png)
    assert img.shape[0] >= 1000 and img[..., :3].std() > 0.05
    pdf = built["out"] / "chapter3" / "index.pdf"
    assert pdf.is_file(), built["proc"].stderr
    text = " ".join(subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True).stdout.split())
    for needle in ("Validation: thesis statements", "Verification: analytic limits", "tumbling", "Jeffery",
                   "INCONSISTENT", "ch3.ellipse.G0.04.Eb0.06"):
        assert needle in text, needle


# ---- capsule.py on its own ----------------------------------------------------------------------

@pytest.mark.parametrize("theta0", [0.0, 0.4, -1.0, math.pi / 2, 2.5])
def test_jeffery_closed_form_matches_integration(theta0):
    r = 2.0
    half = capsule.jeffery_half_period(r)
    assert half == pytest.approx(7.853981633974483, rel=1e-15)
    t = np.linspace(0.0, 2.5 * half, 5001)
    exact = capsule.jeffery_orbit(t, r, theta0)
    assert np.max(np.abs(exact - fakes.jeffery_by_integration(t, r, theta0))) < 1e-8
    assert np.all(np.diff(exact) < 0)  # unwrapped: tumbling decreases without bound
    assert capsule.jeffery_orbit([half], r, theta0)[0] == pytest.approx(theta0 - math.pi, abs=1e-12)
    if theta0 == 0.0:  # thesis eq. 3.11 as printed, with r -> 1/r: the clockwise angle from x
        printed = np.arctan((1 / r) * np.tan(r * t / (1 + r * r)))
        sel = np.abs(np.cos(r * t / (1 + r * r))) > 1e-3
        assert np.max(np.abs(np.tan(-exact[sel]) - np.tan(printed[sel]))) < 1e-6


def _run(tmp_path, name, case, mode, edit=None):
    d = fakes.make_capsule_run_dir(tmp_path / name, case, "quick", mode)
    if edit:
        s = json.loads((d / "summary.json").read_text())
        edit(s["metrics"])
        fakes.write_json(d / "summary.json", s)
    return load_run(d, case["id"], "quick")


def test_claim_checks_must_be_able_to_fail(tmp_path):
    c = claims()
    C = fakes.capsule_case
    tumbling_low = _run(tmp_path, "a", C("ch3/a", bending_ratio=0.02), "tumbling")
    tt_high = _run(tmp_path, "b", C("ch3/b", bending_ratio=0.06), "steady_tank_treading")
    assert capsule.check_claim(c["ch3.ellipse.G0.04.Eb0.02"], [tumbling_low]).verdict == "inconsistent"
    assert capsule.check_claim(c["ch3.ellipse.G0.04.Eb0.06"], [tt_high]).verdict == "inconsistent"
    assert capsule.check_claim(c["ch3.ellipse.G0.04.transition"], [tumbling_low, tt_high]).verdict == "inconsistent"
    assert capsule.check_claim(c["ch3.ellipse.G0.04.Eb0.06"], [tumbling_low]).verdict == "no run"  # E_b differs
    # a trend in the wrong direction: D_xy falling with G at E_b = 0 for the circle
    lo = _run(tmp_path, "c", C("ch2/c", shape="circle", capillary=0.0125), "steady_tank_treading",
              lambda m: m["taylor_deformation_final"].update(value=0.3))
    hi = _run(tmp_path, "d", C("ch2/d", shape="circle", capillary=0.04), "steady_tank_treading",
              lambda m: m["taylor_deformation_final"].update(value=0.1))
    assert capsule.check_claim(c["ch2.circle.D_vs_G"], [lo, hi]).verdict == "inconsistent"
    assert capsule.check_claim(c["ch2.circle.D_vs_G"], [lo]).verdict == "not enough runs"
    # a bound: the enclosed area must not change by 0.1 %
    leaky = _run(tmp_path, "e", C("ch3/e", bending_ratio=0.02), "oscillating_tank_treading",
                 lambda m: m["area_change_max"].update(value=0.004))
    assert capsule.check_claim(c["ch3.area_change"], [leaky]).verdict == "inconsistent"
    # a run whose acceptance names a claim about another case
    named = C("ch3/f", bending_ratio=0.03, claim="ch3.ellipse.G0.04.Eb0.06", reference_mode="tumbling")
    check = capsule.check_claim(c["ch3.ellipse.G0.04.Eb0.06"], [_run(tmp_path, "f", named, "tumbling")])
    assert check.verdict == "inconsistent" and "E_b = 0.03" in check.note
    # and they pass where they should
    good = _run(tmp_path, "g", C("ch3/g", bending_ratio=0.06), "tumbling")
    assert capsule.check_claim(c["ch3.ellipse.G0.04.Eb0.06"], [good]).verdict == "consistent"
    assert capsule.check_claim(c["ch3.ellipse.G0.04.transition"], [good]).verdict == "not enough runs"  # one side
    tt_low = _run(tmp_path, "h", C("ch3/h", bending_ratio=0.02), "oscillating_tank_treading")
    assert capsule.check_claim(c["ch3.ellipse.G0.04.transition"], [tt_low, good]).verdict == "consistent"


def test_acceptance_cross_check_must_be_able_to_fail():
    lib = refmod.ReferenceLibrary(REPO / "references")
    C = fakes.capsule_case
    assert capsule.acceptance_problems(C("ch3/x", bending_ratio=0.06, claim="ch3.ellipse.G0.04.Eb0.06",
                                         reference_mode="tumbling"), lib) == []
    assert capsule.acceptance_problems(C("ch3/x", bending_ratio=0.02, claim="ch3.ellipse.G0.04.Eb0.02",
                                         reference_mode="oscillating_tank_treading"), lib) == []
    wrong_mode = capsule.acceptance_problems(C("ch3/x", bending_ratio=0.06, claim="ch3.ellipse.G0.04.Eb0.06",
                                               reference_mode="steady_tank_treading"), lib)
    assert len(wrong_mode) == 1 and "not what the claim states" in wrong_mode[0]
    wrong_case = capsule.acceptance_problems(C("ch3/x", bending_ratio=0.05, claim="ch3.ellipse.G0.04.Eb0.06",
                                               reference_mode="tumbling"), lib)
    assert len(wrong_case) == 1 and "E_b = 0.05" in wrong_case[0]
    wrong_shape = capsule.acceptance_problems(C("ch3/x", shape="circle", bending_ratio=0.06,
                                                claim="ch3.ellipse.G0.04.Eb0.06", reference_mode="tumbling"), lib)
    assert any("shape" in p for p in wrong_shape)
    missing = capsule.acceptance_problems(C("ch3/x", claim="ch3.no_such_claim", reference_mode="tumbling"), lib)
    assert len(missing) == 1 and "not in claims.json" in missing[0]
    not_a_mode = capsule.acceptance_problems(C("ch3/x", claim="ch3.area_change", reference_mode="tumbling"), lib)
    assert any("bound statement" in p for p in not_a_mode)


def test_catalogue_entries_naming_claims_are_consistent():
    """Every acceptance entry of the catalogue that names a thesis statement is about a case the
    statement is about, with the regime it states (vacuous until capsule cases are added)."""
    lib = refmod.ReferenceLibrary(REPO / "references")
    problems = []
    for path in sorted((REPO / "catalogue").rglob("*.json")):
        if path.name == "schema.json":
            continue
        problems += capsule.acceptance_problems(json.loads(path.read_text(encoding="utf-8")), lib)
    assert not problems, "\n".join(problems)


# ---- references/capsule2d -------------------------------------------------------------------------

def test_claims_are_well_formed():
    doc = json.loads(CLAIMS.read_text(encoding="utf-8"))
    ids = [c["id"] for c in doc["claims"]]
    assert len(ids) == len(set(ids))
    lib = refmod.ReferenceLibrary(REPO / "references")
    assert not lib.problems, lib.problems
    for c in doc["claims"]:
        assert c["kind"] in KINDS, c["id"]
        assert c["id"].split(".")[0] in ("ch2", "ch3", "ch4"), c["id"]
        assert c.get("section") and c.get("sentence"), c["id"]
        assert c.get("basis") in ("stated", "derived"), c["id"]
        if c["basis"] == "derived":
            assert c.get("derivation"), c["id"]
        for key in c.get("parameters", {}):
            assert key in capsule.KEYS, (c["id"], key)
        if c["kind"] == "mode":
            assert refmod.claim_modes(c) and set(refmod.claim_modes(c)) <= MODES, c["id"]
        if c["kind"] == "bracket":
            lo, hi = c["between"]
            assert lo < hi and c["below"] in MODES and c["above"] in MODES, c["id"]
        if c["kind"] == "bound":
            assert c.get("upper") is not None or c.get("lower") is not None or c.get("note"), c["id"]


@pytest.mark.skipif(not THESIS.is_file(), reason="thesis text not beside the checkout")
def test_claim_sentences_are_verbatim():
    text = " ".join(THESIS.read_text(encoding="utf-8").split())
    for cid, c in claims().items():
        assert " ".join(c["sentence"].split()) in text, cid


@pytest.mark.parametrize("cid, mode", [
    ("ch3.ellipse.G0.04.Eb0", "steady_tank_treading"),
    ("ch3.ellipse.G0.04.Eb0.005", "oscillating_tank_treading"),
    ("ch3.ellipse.G0.04.Eb0.02", "oscillating_tank_treading"),
    ("ch3.ellipse.G0.04.Eb0.04", "oscillating_tank_treading"),
    ("ch3.ellipse.G0.04.Eb0.06", "tumbling"),
    ("ch3.ellipse.G0.04.Eb0.4", "tumbling"),
    ("ch3.biconcave.G0.025.Eb0.015", "oscillating_tank_treading"),
    ("ch3.biconcave.G0.025.Eb0.02", "tumbling"),
    ("ch3.biconcave.Eb0.01.G0.04", "oscillating_tank_treading"),
    ("ch3.biconcave.Eb0.01.G0.02", "oscillating_tank_treading"),
    ("ch3.biconcave.Eb0.01.G0.01", "tumbling"),
    ("ch3.biconcave.Eb0.01.G0.001", "tumbling"),
    ("ch3.ellipse.G0.04.Eb0.01", "oscillating_tank_treading"),
    ("ch3.ellipse.G0.001.Eb0.01", "tumbling"),
    ("ch2.circle.mode", "steady_tank_treading"),
    ("ch4.mode", "steady_tank_treading"),
])
def test_thesis_regimes(cid, mode):
    assert refmod.claim_modes(claims()[cid]) == [mode]


def test_quantitative_statements():
    c = claims()
    assert c["ch3.ellipse.G0.04.transition"]["between"] == [0.04, 0.06]
    assert c["ch3.biconcave.G0.025.transition"]["between"] == [0.015, 0.02]
    assert c["ch3.biconcave.Eb0.01.transition"]["between"] == [0.01, 0.02]
    assert c["ch3.area_change"]["upper"] == 0.001 and c["ch3.area_change"]["metric"] == "area_change_max"
    length = c["ch3.biconcave.G0.0025.membrane_length_change"]
    assert length["upper"] == 0.005 and length["metric"] == "length_change_max"  # the membrane, not the enclosed area
    assert c["ch3.circle.tt_frequency"]["limit"] == 1.0
    assert c["ch3.ellipse.G0.04.Eb0.4.jeffery"]["value"] == pytest.approx(math.pi * 5 / 2)
    assert c["ch4.tt_frequency_vs_Re"]["direction"] == "decreasing"
    assert c["ch4.D_vs_Re"]["direction"] == "increasing"
    assert c["ch4.inclination_above_45"]["lower"] == pytest.approx(math.pi / 4)
    assert "overshoot" in c["ch4.overshoot"]["sentence"]
    assert "dampened oscillations" in c["ch4.damped_oscillation"]["sentence"]


def test_provenance_states_sources_and_what_is_missing():
    prov = json.loads((REPO / "references" / "capsule2d" / "provenance.json").read_text(encoding="utf-8"))
    ds = prov["datasets"]["claims.json"]
    assert ds["obtained"].startswith("stated in the thesis text") and ds["kind"] == "statement"
    assert "10.1103/PhysRevE.75.066301" in json.dumps(ds["source"])
    assert "modes: exact" in ds["uncertainty"] and "brackets: as given" in ds["uncertainty"]
    jeffery = prov["analytic"]["jeffery_orbit"]
    assert jeffery["source"]["doi"] == "10.1098/rspa.1922.0078" and jeffery["kind"] == "verification"
    assert "7.85398" in jeffery["half_turn_period"]
    (missing,) = [n for n in prov["not_available"] if "2.17" in n["figures"]]
    assert "Breyiannis" in missing["what"] and "self-reference" in missing["substitute"]
    readme = REPO.parent / "shared" / "refdata" / "README.md"
    if readme.is_file():
        assert "Breyiannis & Pozrikidis 2000" in readme.read_text(encoding="utf-8").split("Not available")[1]
