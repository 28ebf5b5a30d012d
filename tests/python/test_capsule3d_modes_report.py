"""Tests of the chapter 6 section of the report (reports/caplab_report/capsule3d_modes.py): the
transition brackets measured by a sweep (monotonic, without a tumbling run, non-monotonic, with
unfinished runs), the thesis's numbers read from claims.json, the section as rendered, and the
chapter 5 page left as it was. No caplab run: the ch6 runs are made from the real quick chapter 5
run of tests/python/capsule3d_runs (test_capsule3d_report.derive) with the case files of
catalogue/ch6 and synthetic inclination histories; run with
`/usr/bin/python3 -m pytest -q tests/python/test_capsule3d_modes_report.py`."""

from __future__ import annotations

import json
import math
import re
import shutil
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "reports"))

import fakes  # noqa: E402
from caplab_report import capsule3d_modes as modes  # noqa: E402
from caplab_report.build import build_report, environment  # noqa: E402
from caplab_report.references import ReferenceLibrary  # noqa: E402
from caplab_report.runs import Run, discover  # noqa: E402
from pages import assert_self_contained, parse, write_case  # noqa: E402
from test_capsule3d_report import derive, no_png, text  # noqa: E402

CATALOGUE = REPO / "catalogue" / "ch6"
T, S, ST = "tumbling", "oscillating_tank_treading", "steady_tank_treading"

#: The thesis statements the fixtures are checked against (the format of references/capsule3d_modes/
#: claims.json; kept here so that the tests do not move when that file is edited).
CLAIMS = [
    {"id": "ch6.oblate_zt.transition_3to2", "section": "6.2.2", "figure": "6.7", "kind": "bracket", "basis": "stated",
     "sentence": "The mode transition happens between $G = 0.025$ and $G = 0.0125$",
     "parameters": {"shape": "oblate_spheroid", "aspect_ratio": 1.5, "law": "zero_thickness"},
     "varying": "capillary", "between": [0.0125, 0.025], "below": T, "above": S},
    {"id": "ch6.biconcave.transition", "section": "6.3.2", "figure": "6.16", "kind": "bracket", "basis": "derived",
     "sentence": "With further decreasing the shear rate, the cell's motion falls into tumbling region",
     "parameters": {"shape": "biconcave_discoid", "law": "skalak", "reynolds": 0.1},
     "varying": "capillary", "between": [0.0045, 0.045], "below": T, "above": S},
    {"id": "ch6.oblate_zt.tumbling", "section": "6.2.2", "figure": "6.4(c)", "kind": "mode", "basis": "stated",
     "sentence": "the capsule's motion has changed from swinging to tumbling",
     "parameters": {"shape": "oblate_spheroid", "aspect_ratio": 1.5, "law": "zero_thickness", "capillary": 0.0125},
     "metric": "mode", "mode": T},
    {"id": "ch6.biconcave.swinging_amplitude", "section": "6.3.1", "figure": "6.14", "kind": "bound", "basis": "stated",
     "sentence": "the capsule inclination oscillation amplitude is in the range of 2.9 ~ 3.5 degrees",
     "parameters": {"shape": "biconcave_discoid", "law": "skalak", "capillary": {"from": 0.47, "to": 2.8}},
     "metric": "inclination_amplitude", "lower": math.radians(2.9), "upper": math.radians(3.5), "strict": False,
     "quantifier": "every"},
    {"id": "ch6.biconcave.tank_treading_frequency", "section": "6.3.1", "figure": "6.15", "kind": "bound",
     "basis": "stated", "sentence": "ranges from 0.20 to 0.24",
     "parameters": {"shape": "biconcave_discoid", "law": "skalak", "capillary": {"from": 0.47, "to": 2.8}},
     "metric": "tank_treading_frequency_per_k", "lower": 0.2, "upper": 0.24, "strict": False, "quantifier": "every"},
    {"id": "ch6.sphere_zt.area_change", "section": "6.1", "figure": "6.2", "kind": "value", "basis": "stated",
     "sentence": "the maximum membrane area change ranges from 0.4% for $G = 0.0125$ to 23.5% for $G = 0.2$",
     "parameters": {"shape": "sphere", "law": "zero_thickness", "capillary": [0.0125, 0.2]},
     "metric": "surface_area_change_max", "value": {"0.0125": 0.004, "0.2": 0.235}, "unit": "1"},
]
TRAN_SON_TAY = ("table,cells,gamma_dot_per_s,f_rad_per_s,f_sd\n"
                "I,young,20,4.4,0.2\nI,young,100,22.0,1.0\nI,old,20,3.6,0.2\nI,old,100,18.0,1.0\n")


def references(root: Path, claims=CLAIMS, tst: bool = True) -> Path:
    """A references folder with a capsule3d_modes benchmark of ``claims`` (and the Tran-Son-Tay
    file), next to a copy of the real capsule3d one (chapter 5)."""
    shutil.copytree(REPO / "references" / "capsule3d", root / "capsule3d")
    bench = root / "capsule3d_modes"
    bench.mkdir(parents=True)
    datasets = {"claims.json": {"title": "thesis chapter 6 statements", "kind": "statement"}}
    fakes.write_json(bench / "claims.json", {"claims": claims})
    if tst:
        (bench / "tran_son_tay_1984.csv").write_text(TRAN_SON_TAY)
        datasets["tran_son_tay_1984.csv"] = {"title": "Tran-Son-Tay et al. 1984", "kind": "validation"}
    fakes.write_json(bench / "provenance.json", {"datasets": datasets, "discrepancies": {
        "amplitude_convention": {"what": "peak to peak or half of it", "consequence": "open"}}})
    return root


def catalogue_case(name: str) -> dict:
    return json.loads((CATALOGUE / f"{name}.json").read_text())


def ch6_run(results: Path, name: str, mode: str | None, status: str = "ok", fidelity: str = "quick",
            amplitude_deg: float = 3.0, d_amplitude: float = 0.02, frequency: float | None = None,
            area: float | None = None, section_deg: float | None = None) -> Path:
    """A run of catalogue/ch6/<name>.json that behaves as ``mode`` says: summary mode and amplitudes
    (``section_deg``: also the middle cross section's), and an inclination history (swinging about 20
    degrees, tumbling at -0.4 rad per k t)."""
    case = catalogue_case(name)
    d = derive(results, case["id"], edit=lambda c: (c.clear(), c.update(case)), status=status, snapshots=False)
    if fidelity != "quick":
        moved = results / fidelity / d.name
        moved.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(str(d), moved)
        d = moved
    summary = json.loads((d / "summary.json").read_text())
    m = summary["metrics"]
    if mode is None:
        del m["mode"]
    else:
        m["mode"]["value"] = mode
    m["inclination_amplitude"]["value"] = math.radians(amplitude_deg) if mode != T else 4.0
    m["taylor_deformation_amplitude"]["value"] = d_amplitude
    if section_deg is not None:
        m["section_inclination_amplitude"] = {"value": math.radians(section_deg), "unit": "rad", "definition": "(max - min)/2"}
    if frequency is not None:
        m["tank_treading_frequency_per_k"] = {"value": frequency, "unit": "1", "definition": "f/k = 2 pi/(k T)"}
    if area is not None:
        m["surface_area_change_max"]["value"] = area
    fakes.write_json(d / "summary.json", summary)
    with h5py.File(d / "series.h5", "r+") as f:
        t = f["t"][()]
        if mode == T:
            f["inclination"][...] = 0.5 - 0.4 * t
        elif mode == S:
            f["inclination"][...] = math.radians(20) + math.radians(amplitude_deg) * np.sin(0.5 * t)
    return d


#: (catalogue case, mode; None: no mode in summary.json; "diverged": the run diverged)
SWEEP = [("oblate_zt_3to2_G0.0125", T), ("oblate_zt_3to2_G0.025", "diverged"), ("oblate_zt_3to2_G0.05", S),
         ("oblate_zt_3to2_G0.1", S), ("oblate_zt_3to2_G0.2", None),
         ("oblate_zt_10to9_G0.0125", S), ("oblate_zt_10to9_G0.05", S),                 # no tumbling run
         ("oblate_zt_2to1_G0.0125", T), ("oblate_zt_2to1_G0.025", S), ("oblate_zt_2to1_G0.05", T),
         ("oblate_zt_2to1_G0.1", S),                                                    # not monotonic
         ("oblate_nh_3to2_G0.0221", S), ("oblate_nh_3to2_G0.0225", S),
         ("biconcave_sk_walls_G0.0045", T), ("biconcave_sk_walls_G0.045", S), ("biconcave_sk_walls_G1.87", S),
         ("sphere_zt_G0.0125", ST), ("sphere_zt_G0.2", ST), ("sphere_sk_C100_G0.3", ST)]
NEVER_RUN = "oblate_zt_10to9_G0.025"


def make_results(results: Path) -> None:
    for name, mode in SWEEP:
        extra = {}
        if name == "biconcave_sk_walls_G1.87":
            extra = {"amplitude_deg": 3.1, "section_deg": 3.4, "frequency": 0.215}
        if name.startswith("sphere_zt"):
            extra = {"area": 0.004 if "0.0125" in name else 0.21, "amplitude_deg": 0.01}
        if mode == "diverged":
            ch6_run(results, name, S, status="diverged")
        else:
            ch6_run(results, name, mode, **extra)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The section of the fake chapter 6 runs (one catalogue case never run), and its HTML."""
    tmp = tmp_path_factory.mktemp("ch6")
    make_results(tmp / "results")
    runs = discover(tmp / "results")
    never = Run(case_id=f"ch6/{NEVER_RUN}", fidelity="quick", case=catalogue_case(NEVER_RUN))
    refs = ReferenceLibrary(references(tmp / "references"))
    section = modes.build(runs + [never], refs, "ch6")
    template = environment().from_string('{% import "capsule3d_modes.html.j2" as c6 %}{{ c6.modes_section(c) }}')
    html = template.render(c=section)
    return {"section": section, "html": html, "text": text(html),
            "sweeps": {(s.family[1], modes.ratio_text(s.ratio)): s for s in section.sweeps
                       if s.family[0] == "oblate_spheroid"}}


# ---- the bracket of a sweep -----------------------------------------------------------------------------

def test_bracket_of_a_monotonic_sweep():
    b = modes.measured_bracket([(0.05, S), (0.0125, T), (0.025, S), (0.2, S)])
    assert (b.lower, b.upper, b.monotonic, b.closed) == (0.0125, 0.025, True, True)
    assert b.text == "transition between G = 0.0125 (tumbles) and G = 0.025 (tank-treads)"
    assert b.against(0.0125, 0.025) == (True, "agrees with the thesis's 0.0125 < G < 0.025")
    agrees, words = b.against(0.05, 0.1)  # the thesis would have it higher
    assert agrees is False and words.startswith("disagrees")


def test_bracket_without_a_tumbling_run_is_one_sided():
    b = modes.measured_bracket([(0.05, S), (0.0125, S)])
    assert (b.lower, b.upper, b.monotonic) == (None, 0.0125, True)
    assert b.text.startswith("no run tumbles (2 run(s), G = 0.0125 … 0.05, every one tank-treads)")
    assert b.text.endswith("lies below G = 0.0125")
    assert b.against(0.005, 0.02) == (True, "agrees with the thesis's 0.005 < G < 0.02 (one-sided: no run tumbles)")
    assert b.against(0.025, 0.05)[0] is False  # the thesis says G = 0.0125 tumbles
    spheres = modes.measured_bracket([(0.0125, ST), (0.2, ST)])
    assert "every one steady tank-treading" in spheres.text and "counted with swinging" not in spheres.text
    tumbling = modes.measured_bracket([(0.0125, T), (0.025, T)])
    assert (tumbling.lower, tumbling.upper) == (0.025, None) and tumbling.text.endswith("lies above G = 0.025")
    assert tumbling.against(0.0125, 0.025)[0] is False and tumbling.against(0.02, 0.05)[0] is True


def test_bracket_of_a_non_monotonic_sweep():
    b = modes.measured_bracket([(0.0125, T), (0.025, S), (0.05, T), (0.1, S)])
    assert not b.monotonic and b.reversals == [(0.025, 0.05)]
    assert (b.lower, b.upper) == (0.05, 0.1)
    assert b.text.startswith("not monotonic in G: tank-treads at G = 0.025 but tumbles at G = 0.05")
    assert b.against(0.0125, 0.025) == (None, "not comparable: the sweep is not monotonic in G")
    # the same G both ways (two runs) is not monotonic either; the largest tumbling G tank-treads nowhere above
    same = modes.measured_bracket([(0.025, T), (0.025, S)])
    assert not same.monotonic and same.upper is None and same.text.endswith("no G above it tank-treads")


def test_bracket_leaves_out_runs_without_a_mode_and_notes_steady_ones():
    b = modes.measured_bracket([(0.0125, T), (0.025, None), (0.05, ST), (0.1, S)])
    assert (b.lower, b.upper, b.runs) == (0.0125, 0.05, 3)
    assert b.text.endswith("; steady tank-treading (counted with swinging) at G = 0.05")
    empty = modes.measured_bracket([(0.025, None)])
    assert empty.runs == 0 and empty.text == "no finished run with a mode: no bracket"
    assert empty.against(0.01, 0.02) == (None, "no finished run with a mode")


def test_sweeps_keep_unfinished_runs_apart(built):
    s = built["sweeps"][("zero_thickness", "3:2")]
    assert [round(g, 4) for g, _, _ in s.points()] == [0.0125, 0.05, 0.1]   # finished, with a mode
    assert [r.case_id for r in s.unfinished] == ["ch6/oblate_zt_3to2_G0.025"]  # diverged: listed only
    assert [r.case_id for r in s.no_mode] == ["ch6/oblate_zt_3to2_G0.2"]
    # the diverged G = 0.025 is not used: the bracket is as wide as the finished runs make it
    assert (s.bracket.lower, s.bracket.upper) == (0.0125, 0.05)
    (tb,) = s.thesis
    assert tb.claim["id"] == "ch6.oblate_zt.transition_3to2" and tb.agrees is True
    assert not built["sweeps"][("zero_thickness", "10:9")].thesis  # the 3:2 bracket is not about 10:9
    assert built["sweeps"][("zero_thickness", "10:9")].bracket.lower is None
    assert not built["sweeps"][("zero_thickness", "2:1")].bracket.monotonic
    assert not built["sweeps"][("neo_hookean", "3:2")].thesis  # the bracket is the ZT one
    (bic,) = [s for s in built["section"].sweeps if s.family[0] == "biconcave_discoid"]
    assert [t.claim["id"] for t in bic.thesis] == ["ch6.biconcave.transition"]
    assert (bic.bracket.lower, bic.bracket.upper, bic.thesis[0].agrees) == (0.0045, 0.045, True)


def test_ratio_restriction_from_conditions_or_cases(built):
    runs = [r for s in built["section"].sweeps for r in s.runs]
    claim = dict(CLAIMS[0], parameters={"shape": "oblate_spheroid", "law": "zero_thickness"},
                 conditions={"aspect_ratio": 1.111})  # printed as chapter 5's claims do, rounded
    s109, s32 = built["sweeps"][("zero_thickness", "10:9")], built["sweeps"][("zero_thickness", "3:2")]
    assert modes.claim_is_about(claim, s109, runs) and not modes.claim_is_about(claim, s32, runs)
    by_cases = dict(claim, conditions={}, cases=["ch6/oblate_zt_3to2_G0.05"])
    assert modes.claim_is_about(by_cases, s32, runs) and not modes.claim_is_about(by_cases, s109, runs)
    anywhere = dict(claim, conditions={})
    assert modes.claim_is_about(anywhere, s109, runs) and modes.claim_is_about(anywhere, s32, runs)
    assert not modes.claim_is_about(anywhere, built["sweeps"][("neo_hookean", "3:2")], runs)


# ---- the thesis's numbers ---------------------------------------------------------------------------------

def test_bands_from_the_claims_or_the_thesis_text():
    claims = {c["id"]: c for c in CLAIMS}
    amp = modes.band(claims, "amplitude", degrees=True)
    assert (amp.lower, amp.upper) == pytest.approx((2.9, 3.5)) and amp.capillary == (0.47, 2.8)
    assert amp.source == "claims.json#ch6.biconcave.swinging_amplitude"
    freq = modes.band(claims, "frequency")
    assert (freq.lower, freq.upper, freq.source) == (0.2, 0.24, "claims.json#ch6.biconcave.tank_treading_frequency")
    quoted = modes.band({}, "sphere_sk_area")
    assert (quoted.upper, quoted.capillary) == (0.018, (0.3, 0.3)) and "not in claims.json" in quoted.source
    no_range = modes.band({"ch6.biconcave.swinging_amplitude": {"kind": "value", "value": 3.2}}, "amplitude", True)
    assert (no_range.lower, no_range.upper) == (2.9, 3.5) and "gives no range" in no_range.source
    points, source = modes.sphere_area_points(claims)
    assert points == [(0.0125, 0.004), (0.2, 0.235)] and source == "claims.json#ch6.sphere_zt.area_change"
    assert modes.sphere_area_points({})[0] == [(0.0125, 0.004), (0.2, 0.235)]


def test_tran_son_tay_per_group_of_cells(tmp_path):
    values, ds, note = modes.tran_son_tay(ReferenceLibrary(references(tmp_path / "refs")))
    assert ds is not None and not note
    young, old = values
    assert young.label == "young cells" and young.value == pytest.approx(0.22) and young.rows == 2
    assert (old.lower, old.upper) == pytest.approx((0.18, 0.18)) and old.shear_rates == (20.0, 100.0)
    values, ds, note = modes.tran_son_tay(ReferenceLibrary(references(tmp_path / "bare", tst=False)))
    assert values == [] and ds is None and "tran_son_tay_1984.csv is missing" in note


# ---- the section ------------------------------------------------------------------------------------------

def test_section_renders(built):
    section, page, html = built["section"], built["text"], built["html"]
    assert not section.problems, section.problems
    for heading in ("Tank-treading, swinging and tumbling of 3D capsules (thesis chapter 6)",
                    "Mode maps and transition brackets", "Amplitudes and tank-treading frequency against G",
                    "Time histories", "Runs per family", "Thesis statements of chapter 6: verdicts"):
        assert heading in page, heading
    # maps (oblate, biconcave + spheres), amplitudes, f/k, histories (ZT 10:9, 3:2, 2:1, NH 3:2, biconcave,
    # ZT spheres, SK spheres), sphere area change
    assert len(re.findall(r"<img ", html)) == 12
    assert "ZT oblate spheroids 3:2 (quick) 0.0125 → tumbling; 0.05 → swinging; 0.1 → swinging " in page
    assert "transition between G = 0.0125 (tumbles) and G = 0.05 (tank-treads)" in page
    assert "agrees with the thesis's 0.0125 < G < 0.025" in page
    assert "no run tumbles (2 run(s), G = 0.0125 … 0.05, every one tank-treads)" in page
    assert "not monotonic in G: tank-treads at G = 0.025 but tumbles at G = 0.05" in page
    assert "not comparable" not in page  # no thesis bracket is about the 2:1 sweep
    assert re.search(r"Not plotted \(the run did not finish\): ch6/oblate_zt_3to2_G0\.025 \(quick\) DIVERGED", page)
    assert "ch6/oblate_zt_3to2_G0.2 (quick) (no mode in summary.json)" in page
    assert f"Catalogue cases of this family without a run: ch6/{NEVER_RUN} (quick)" in page
    # Tran-Son-Tay and the thesis's bands
    assert "young cells: f/k = 0.220 (0.220–0.220, 2 rows over γ̇ = 20–100 1/s)" in page
    assert ("biconcave inclination amplitude 2.9–3.5 at G = 0.47–2.8 ( claims.json#ch6.biconcave.swinging_amplitude"
            in page)
    assert "discrepancies.amplitude_convention" in page
    # the claims verdicts, linked to their rows in the capsule section
    assert {c.check.claim["id"] for c in section.claims} == {c["id"] for c in CLAIMS}
    assert 'href="#claim-ch6-oblate_zt-transition_3to2"' in html


def test_family_tables(built):
    tables = {t.title: t for t in built["section"].tables}
    assert list(tables) == ["ZT spheres", "SK spheres, C = 100", "ZT oblate spheroids", "NH oblate spheroids",
                            "SK biconcave discoids between walls (C from G)"]  # the order of thesis 6.1-6.3
    zt = tables["ZT oblate spheroids"]
    assert [r["ratio"] for r in zt.rows] == ["10:9"] * 2 + ["3:2"] * 5 + ["2:1"] * 4  # by axis ratio, then G
    diverged = next(r for r in zt.rows if r["run"].case_id == "ch6/oblate_zt_3to2_G0.025")
    assert not diverged["done"] and diverged["status"] == "DIVERGED" and diverged["theta_amp"] is None
    bic = next(r for r in tables["SK biconcave discoids between walls (C from G)"].rows if r["capillary"] == 1.87)
    # The middle cross section's amplitude where the run has it (thesis fig. 6.14), marked so.
    assert bic["mode_text"] == "swinging" and bic["theta_amp"] == pytest.approx(3.4) and bic["theta_section"]
    assert bic["frequency"] == 0.215
    membrane = catalogue_case("biconcave_sk_walls_G1.87")["physics"]["bodies"][0]["membrane"]
    assert bic["area_dilation"] == membrane["area_dilation"]
    assert re.search(r"ch6/biconcave_sk_walls_G1\.87 \(quick\) quick 1\.87 \d+ swinging 3\.4 s ", built["text"])
    assert not next(r for r in zt.rows if r["done"])["theta_section"]


def test_a_broken_run_does_not_stop_the_section(tmp_path, monkeypatch):
    monkeypatch.setattr(modes.capsule3d.figures, "png_data_uri", no_png)
    d = ch6_run(tmp_path / "results", "oblate_zt_3to2_G0.05", S)
    (d / "series.h5").write_bytes(b"not hdf5")
    refs = ReferenceLibrary(references(tmp_path / "refs"))
    section = modes.build(discover(tmp_path / "results"), refs, "ch6")
    assert section.present and section.oblate_map is not None and section.amplitudes is not None
    assert section.histories == [] and not section.problems
    # other chapters, and a chapter 6 with nothing finished or run
    assert not modes.build(discover(tmp_path / "results"), refs, "ch5").present
    never = Run(case_id="ch6/oblate_zt_3to2_G0.1", fidelity="quick", case=catalogue_case("oblate_zt_3to2_G0.1"))
    assert not modes.build([never], refs, "ch6").present


# ---- the pages ----------------------------------------------------------------------------------------------

def structure(page: Path) -> list[str]:
    """The headings and section ids of a page, in order, with the case ids left out."""
    html = page.read_text(encoding="utf-8")
    return [m.group(0) for m in re.finditer(r'<h[123][^>]*>.*?</h[123]>|id="(capsule|modes)[^"]*"', html)
            if 'id="case-' not in m.group(0)]


def test_chapter_pages(tmp_path):
    """The chapter 5 page is the same in structure with or without chapter 6 runs beside it; the
    chapter 6 page has the section, and not chapter 5's."""
    cheap = tmp_path / "cheap"
    d = derive(cheap, "ch5/sphere_nh_G0.05")
    for name in ("snapshots.h5", "score.json"):
        (d / name).unlink()
    refs = references(tmp_path / "references")
    catalogue = tmp_path / "catalogue"
    write_case(catalogue, json.loads((d / "case.json").read_text()))
    alone = build_report(cheap, tmp_path / "alone", refs, catalogue, chapters=["5"], pdf=False)
    assert not alone.problems, alone.problems
    ch6_run(cheap, "oblate_zt_3to2_G0.0125", T)
    ch6_run(cheap, "oblate_zt_3to2_G0.05", S, fidelity="standard")
    write_case(catalogue, catalogue_case("oblate_zt_3to2_G0.05"))
    both = build_report(cheap, tmp_path / "both", refs, catalogue, chapters=["5", "6"], pdf=False)
    assert not [p for p in both.problems if "capsule" in p.lower()], both.problems
    ch5_alone, ch5_both = tmp_path / "alone" / "chapter5" / "index.html", tmp_path / "both" / "chapter5" / "index.html"
    assert structure(ch5_alone) == structure(ch5_both)
    assert 'id="capsules3d"' in ch5_both.read_text() and "modes3d" not in ch5_both.read_text()
    assert "ch6/" not in text(ch5_both.read_text())
    ch6 = tmp_path / "both" / "chapter6" / "index.html"
    html = ch6.read_text(encoding="utf-8")
    assert '<a href="#modes3d">3D capsule modes</a>' in html and 'id="modes3d"' in html
    assert 'id="capsules3d"' not in html
    assert "transition between G = 0.0125" not in text(html)  # quick and standard are two sweeps
    assert "every run tumbles (1 run(s), G = 0.0125 … 0.0125)" in text(html)
    assert "ch6/oblate_zt_3to2_G0.05 (quick)" in text(html)  # the catalogue case not run at quick
    assert {'claim-ch6-oblate_zt-transition_3to2', 'modes3d-maps'} <= parse(ch6).ids
    assert_self_contained(tmp_path / "both")
