"""Tests of the chapter 5 section of the report (reports/caplab_report/capsule3d.py) on a real quick
run of ch5/sphere_nh_G0.05 (tests/python/capsule3d_runs/, see its README) and on runs derived from it
here (grid study, uniform twin, domain study, oblate and biconcave capsules, a diverged run); run with
`/usr/bin/python3 -m pytest -q tests/python/test_capsule3d_report.py`."""

from __future__ import annotations

import html as htmllib
import json
import math
import re
import shutil
import sys
from pathlib import Path

import h5py
import matplotlib.pyplot as plt
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "reports"))

import fakes  # noqa: E402
from caplab_report import capsule3d  # noqa: E402
from caplab_report.build import build_report, environment  # noqa: E402
from caplab_report.references import ReferenceLibrary  # noqa: E402
from caplab_report.runs import Run, discover, load_run  # noqa: E402
from pages import assert_self_contained, parse, summary, write_case  # noqa: E402

FIXTURE = HERE / "capsule3d_runs" / "quick" / "ch5__sphere_nh_G0.05"
REFERENCES = REPO / "references"
GRID = {"ch5/sphere_nh_G0.2_grid20": 0.2, "ch5/sphere_nh_G0.2": 1 / 6, "ch5/sphere_nh_G0.2_grid32": 0.125}
STEADY = lambda h: 0.47 + 0.9 * h * h  # noqa: E731  the synthetic steady D of the grid study: order 2


def text(html: str) -> str:
    """What a reader sees: tags removed, entities decoded, spaces collapsed."""
    return " ".join(htmllib.unescape(re.sub(r"<[^>]+>", " ", html)).split())


# ---- runs derived from the real one ---------------------------------------------------------------------

def derive(results: Path, case_id: str, edit=None, steady=None, status="ok", snapshots=True, cost=1.0) -> Path:
    """A copy of the fixture run as case ``case_id``: ``edit(case)`` changes the case; ``steady`` sets
    the steady D (summary and series scaled to it); ``cost`` scales wall time and node updates."""
    d = results / "quick" / case_id.replace("/", "__")
    shutil.copytree(FIXTURE, d)
    case = json.loads((d / "case.json").read_text())
    case["id"] = case_id
    if edit:
        edit(case)
    fakes.write_json(d / "case.json", case)
    manifest = json.loads((d / "manifest.json").read_text())
    manifest.update(case_id=case_id, status=status, wall_time_s=manifest["wall_time_s"] * cost)
    manifest["lattice"]["node_updates"] *= cost
    fakes.write_json(d / "manifest.json", manifest)
    score = json.loads((d / "score.json").read_text())
    score["performance"]["wall_time_s"] = manifest["wall_time_s"]
    fakes.write_json(d / "score.json", score)
    if steady is not None:
        s = json.loads((d / "summary.json").read_text())
        old = s["metrics"]["taylor_deformation_mean"]["value"]
        s["metrics"]["taylor_deformation_mean"]["value"] = steady
        fakes.write_json(d / "summary.json", s)
        with h5py.File(d / "series.h5", "r+") as f:
            f["taylor_deformation"][...] = f["taylor_deformation"][()] * (steady / old)
    if not snapshots:
        (d / "snapshots.h5").unlink()
    return d


def study_member(spacing=None, domain=None, uniform=False):
    def edit(case):
        case["physics"]["bodies"][0]["membrane"]["capillary"] = 0.2
        case["acceptance"] = [a for a in case["acceptance"] if a["metric"] == "mode"]
        if spacing is not None:
            case["numerics"]["grid"]["fine_spacing"] = spacing
        if domain is not None:
            case["physics"]["domain"]["size"] = [domain] * 3
            case["physics"]["bodies"][0]["shape"]["center"] = [domain / 2] * 3
        if uniform:
            case["numerics"]["grid"] = {"refinement": "uniform", "fine_spacing": case["numerics"]["grid"]["fine_spacing"]}
    return edit


def oblate(case):
    case["physics"]["bodies"][0]["shape"].update(type="oblate_spheroid", aspect_ratio=10 / 9)
    case["physics"]["bodies"][0]["membrane"].update(law="zero_thickness", capillary=0.1)
    case["acceptance"] = []


def biconcave(case):
    case["physics"]["bodies"][0]["shape"] = {"type": "biconcave_discoid", "center": [5, 5, 5], "diameter": 2}
    case["physics"]["bodies"][0]["membrane"] = {"law": "skalak", "area_dilation": 200, "capillary": 0.6,
                                                "subdivisions": 4}
    case["physics"]["reynolds"] = 0.25
    case["acceptance"] = []


def skalak(case):
    case["physics"]["bodies"][0]["membrane"].update(law="skalak", area_dilation=1, capillary=0.0125)
    case["acceptance"] = []


def render(section) -> str:
    """The section as the chapter page shows it: its macro, in the report's jinja environment."""
    template = environment().from_string('{% import "capsule3d.html.j2" as c3 %}{{ c3.capsule3d_section(c) }}')
    return template.render(c=section)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The section built from the real run and the runs derived from it (only two with snapshots, to
    keep the test fast), and its HTML."""
    results = tmp_path_factory.mktemp("capsule3d_runs")
    derive(results, "ch5/sphere_nh_G0.05")
    base = json.loads((FIXTURE / "case.json").read_text())["acceptance"]
    derive(results, "ch5/sphere_nh_G0.2", edit=lambda c: (study_member()(c), c.update(acceptance=base)),
           steady=STEADY(GRID["ch5/sphere_nh_G0.2"]), snapshots=False)
    for cid, h in GRID.items():
        if cid != "ch5/sphere_nh_G0.2":
            derive(results, cid, edit=study_member(spacing=h), steady=STEADY(h), snapshots=False)
    derive(results, "ch5/sphere_nh_G0.2_uniform", edit=study_member(uniform=True), steady=STEADY(1 / 6) * 1.01,
           cost=3.0, snapshots=False)
    derive(results, "ch5/sphere_nh_G0.2_domain12", edit=study_member(domain=12), steady=STEADY(1 / 6) * 0.995,
           snapshots=False)
    # Averaged over another window: not a member of the domain study.
    derive(results, "ch5/sphere_nh_G0.2_domain8",
           edit=lambda c: (study_member(domain=8)(c), c["outputs"].update(average_from=c["outputs"]["average_from"] + 1)),
           steady=STEADY(1 / 6) * 1.02, snapshots=False)
    derive(results, "ch5/oblate_zt_10to9_G0.1", edit=oblate, snapshots=False)
    derive(results, "ch5/biconcave_sk_G0.6", edit=biconcave)
    derive(results, "ch5/sphere_sk_G0.0125", edit=skalak, steady=0.0512, snapshots=False)
    derive(results, "ch5/sphere_sk_G0.2", edit=skalak, status="diverged")
    runs = discover(results)
    never_run = Run(case_id="ch5/sphere_nh_G0.1", fidelity="quick", case=json.loads((FIXTURE / "case.json").read_text()))
    section = capsule3d.build(runs + [never_run], ReferenceLibrary(REFERENCES), "ch5")
    html = render(section)
    return {"section": section, "html": html, "text": text(html)}


# ---- the section -------------------------------------------------------------------------------------------

def test_section_builds(built):
    page, html = built["text"], built["html"]
    assert not built["section"].problems, built["section"].problems
    for heading in ("Validation (external data): neo-Hookean spheres against Pozrikidis 1995",
                    "Verification (analytic limits and convergence)", "Conservation and membrane", "Shape", "Cost"):
        assert heading in page, heading
    assert html.index("capsules3d-validation") < html.index("capsules3d-verification")
    # D(kt), θ(kt), theory, grid, domain, conservation, cross-sections, shape histories (oblate, biconcave)
    assert len(re.findall(r"<img ", html)) == 9
    captions = re.findall(r"<figcaption>(.*?)</figcaption>", html, re.S)
    assert len(captions) == 9 and all("fidelity quick" in c for c in captions), captions
    assert "Pozrikidis 1995" in captions[0] and "Ramanujan &amp; Pozrikidis 1998" in captions[0]
    assert all("reference" in c.lower() or "external data" in c for c in captions), captions
    assert "ch5/sphere_nh_G0.1" not in page  # never run: absent from the section
    assert re.search(r"Not plotted .*ch5/sphere_sk_G0\.2 \(quick\) DIVERGED", page)
    assert page.count("ch5/sphere_sk_G0.2 (quick)") == 1  # and nowhere else


def test_report_page_shows_the_section(tmp_path):
    """The hook in build.py and chapter.html.j2, on a cheap run (no series, snapshots or score: no
    figure to draw): the section is on the chapter 5 page; a catalogue case without a run is missing."""
    results, catalogue = tmp_path / "results", tmp_path / "catalogue"
    d = derive(results, "ch5/sphere_nh_G0.05")
    for name in ("series.h5", "snapshots.h5", "score.json"):
        (d / name).unlink()
    write_case(catalogue, json.loads((d / "case.json").read_text()))
    never_run = json.loads((FIXTURE / "case.json").read_text())
    never_run["id"] = "ch5/sphere_nh_G0.1"
    write_case(catalogue, never_run)
    result = build_report(results, tmp_path / "out", REFERENCES, catalogue, chapters=["5"], pdf=False)
    page = tmp_path / "out" / "chapter5" / "index.html"
    html = page.read_text(encoding="utf-8")
    assert '<a href="#capsules3d">3D capsules</a>' in html and 'id="capsules3d"' in html
    assert "Not plotted (the run did not finish or left no series)" in text(html)
    assert summary(parse(page))["ch5/sphere_nh_G0.1"]["verdict"] == "MISSING"
    assert not [p for p in result.problems if "3D capsules" in p], result.problems
    assert_self_contained(tmp_path / "out")


def test_validation_table_shows_the_rp98_error(built):
    row = re.search(r"0\.05 ch5/sphere_nh_G0\.05 \(quick\) (.*?) \(81 points\)", built["text"])
    assert row, built["text"][:3000]
    cells = row.group(1)
    summary_d = json.loads((FIXTURE / "summary.json").read_text())["metrics"]["taylor_deformation_mean"]["value"]
    error = 100 * (summary_d - 0.26209) / 0.26209
    assert f"{summary_d:.4g} 0.2621 ± 0.0026 {error:+.1f} %" in cells  # +11.4 %
    scored = json.loads((FIXTURE / "score.json").read_text())["accuracy"]["entries"]
    rms = next(e["error"] for e in scored if e["comparison"] == "time_series")
    assert f"{rms:.3g} 0.04 PASS {rms:.3g}" in cells  # score.json and the recomputation agree
    (v,) = [r for r in built["section"].validation.rows if r.capillary == 0.05]
    assert v.error == pytest.approx((summary_d - 0.26209) / 0.26209) and v.rms_recomputed == pytest.approx(rms, rel=1e-9)
    # G = 0.2: the base case of the studies, against RP98 (no Pozrikidis score: its acceptance names G = 0.05)
    (g2,) = [r for r in built["section"].validation.rows if r.capillary == 0.2]
    assert g2.run.case_id == "ch5/sphere_nh_G0.2" and g2.rp98 == pytest.approx(0.501086) and g2.rms_scored is None
    # the provenance of every reference of the section
    for name in ("pozrikidis1995_G0.05.csv", "ramanujan1998_G0.05.csv", "pozrikidis1995_G0.2.csv",
                 "ramanujan1998_G0.2.csv", "steady_values.csv"):
        assert name in built["text"], name
    assert "WebPlotDigitizer" in built["text"] and "+-0.005 in D" in built["text"]
    assert "discrepancies.membrane_law_of_the_bem_references" in built["text"]


def test_verification_parts(built):
    page = built["text"]
    assert "p = 2 ; Richardson-extrapolated steady D xz = 0.47" in page
    (grid,) = [s for s in built["section"].verification.studies if s.what == "grid"]
    assert [r.case_id for r in grid.runs] == ["ch5/sphere_nh_G0.2_grid20", "ch5/sphere_nh_G0.2", "ch5/sphere_nh_G0.2_grid32"]
    assert grid.order.order == pytest.approx(2.0, rel=1e-6) and grid.order.extrapolated == pytest.approx(0.47, abs=1e-9)
    (domain,) = [s for s in built["section"].verification.studies if s.what == "domain"]
    assert [r.case_id for r in domain.runs] == ["ch5/sphere_nh_G0.2", "ch5/sphere_nh_G0.2_domain12"]
    (twin,) = built["section"].verification.twins
    assert twin.twin.case_id == "ch5/sphere_nh_G0.2_uniform"
    assert twin.difference == pytest.approx(1 / 1.01 - 1) and twin.fine_fraction == pytest.approx(0.064)
    assert twin.cost.wall_ratio == pytest.approx(3.0) and twin.cost.node_ratio == pytest.approx(3.0)
    assert re.search(r"ch5/sphere_nh_G0\.2 \(quick\) ch5/sphere_nh_G0\.2_uniform \(quick\) 0\.495 0\.5 -0\.99 % "
                     r"[0-9.]+ 6\.4 % 3 3", page)
    # small-deformation theory: the Skalak sphere at G = 0.0125 against 25/6 G
    assert re.search(r"skalak 0\.0125 ch5/sphere_sk_G0\.0125 \(quick\) 0\.0512 0\.05208 -1\.7 %", page)


def test_conservation_bounds_apply_to_the_runs_the_claim_is_about(built):
    rows = {r["run"].case_id: r for r in built["section"].conservation.rows}
    volume, area, local = rows["ch5/sphere_nh_G0.05"]["values"]
    assert volume["bound"].claim["id"] == "ch5.volume_change" and volume["ok"] is False  # quick leaks > 0.2 %
    assert area["bound"] is None and local["bound"] is None  # the 1 % area bound is for the discoids only
    volume, area, _ = rows["ch5/biconcave_sk_G0.6"]["values"]
    assert area["bound"].claim["id"] == "ch5.biconcave.area_change" and area["ok"] is False
    assert "5.495 % bound 1 % ( ch5.biconcave.area_change ) ✗" in built["text"]
    assert rows["ch5/sphere_nh_G0.05"]["stretch"] == pytest.approx(1.32, abs=0.01)


def test_a_run_inside_the_bound_passes(tmp_path, monkeypatch):
    monkeypatch.setattr(capsule3d.figures, "png_data_uri", no_png)
    d = tmp_path / "run"
    shutil.copytree(FIXTURE, d)
    s = json.loads((d / "summary.json").read_text())
    s["metrics"]["volume_change_max"]["value"] = 0.0015
    fakes.write_json(d / "summary.json", s)
    run = load_run(d, "ch5/sphere_nh_G0.05", "quick")
    (row,) = capsule3d.conservation([run], ReferenceLibrary(REFERENCES), {}, {}).rows
    assert row["values"][0]["value"] == 0.0015 and row["values"][0]["ok"] is True


def test_cross_sections_only_for_runs_with_snapshots(built):
    rows = {r["run"].case_id: r for r in built["section"].section_rows}
    assert set(rows) == {"ch5/sphere_nh_G0.05", "ch5/biconcave_sk_G0.6"}  # the others have no snapshots.h5
    assert rows["ch5/sphere_nh_G0.05"]["time"] == pytest.approx(10.0, abs=0.01)
    assert re.search(r"ch5/sphere_nh_G0\.05 \(quick\) 10 \d+ 1\.28\d* / 0\.69\d* ", built["text"])


def no_png(fig) -> str:
    plt.close(fig)
    return "data:image/png;base64,"


# ---- capsule3d.py on its own -----------------------------------------------------------------------------

def octahedron_sphere(subdivisions: int, radius: float, centre) -> tuple[np.ndarray, np.ndarray]:
    """An octahedron subdivided 4^n per face and projected onto the sphere (thesis 5.1.2)."""
    points = [np.array(p, float) for p in ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))]
    faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    for _ in range(subdivisions):
        mid, new = {}, []

        def middle(i, j):
            key = (min(i, j), max(i, j))
            if key not in mid:
                points.append((points[i] + points[j]) / 2)
                mid[key] = len(points) - 1
            return mid[key]
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        faces = new
    p = np.array(points)
    p = radius * p / np.linalg.norm(p, axis=1)[:, None] + np.asarray(centre, float)
    return p, np.array(faces)


@pytest.mark.parametrize("offset", [0.0, 0.3, -0.55])
def test_cross_section_of_a_sphere_is_a_circle_of_the_right_radius(offset):
    radius, centre = 1.3, np.array([5.0, 4.0, 6.0])
    points, triangles = octahedron_sphere(4, radius, centre)
    assert len(points) == 1026 and len(triangles) == 2048
    c = capsule3d.volume_centroid(points, triangles)
    assert np.allclose(c, centre, atol=1e-12)
    segments = capsule3d.plane_section(points, triangles, c[1] + offset * radius)
    ends = segments.reshape(-1, 3)
    assert np.allclose(ends[:, 1], c[1] + offset * radius, atol=1e-12)  # in the plane
    r = np.hypot(ends[:, 0] - centre[0], ends[:, 2] - centre[2])
    expected = radius * math.sqrt(1 - offset ** 2)
    assert r.max() <= expected * (1 + 1e-9) and r.min() >= expected * (1 - 0.005), (r.min(), r.max(), expected)
    # a closed curve: every end meets the end of exactly one other segment, and it goes all round
    dist = np.linalg.norm(ends[:, None, :] - ends[None, :, :], axis=2)
    own = np.arange(len(ends)) ^ 1  # the other end of the same segment
    dist[np.arange(len(ends)), np.arange(len(ends))] = np.inf
    dist[np.arange(len(ends)), own] = np.inf
    assert np.all((dist < 1e-9).sum(axis=1) == 1)
    angles = np.sort(np.arctan2(ends[:, 2] - centre[2], ends[:, 0] - centre[0]))
    assert np.diff(np.concatenate([angles, angles[:1] + 2 * math.pi])).max() < 0.25
    # a plane that misses the sphere cuts nothing
    assert capsule3d.plane_section(points, triangles, centre[1] + 1.01 * radius).shape == (0, 2, 3)


def test_cross_section_of_the_real_run_matches_its_ellipsoid():
    run = load_run(FIXTURE, "ch5/sphere_nh_G0.05", "quick")
    snap, problem = capsule3d.last_surface(run, "capsule")
    assert not problem and snap.time == pytest.approx(10.0, abs=0.01)
    assert {"max_principal_stretch", "area_ratio"} <= set(snap.fields)
    centroid, segments = capsule3d.cross_section(snap)
    s = capsule3d.Section(run, snap.time, centroid, segments)
    longest, shortest = s.extent
    assert longest == pytest.approx(run.metric("length_final"), rel=0.03)
    assert shortest == pytest.approx(run.metric("thickness_final"), rel=0.03)


@pytest.mark.parametrize("p, f0, c", [(2.0, 0.47, 0.9), (1.0, 0.3, -0.2), (1.37, 0.501, 0.05)])
def test_observed_order_from_three_steady_values(p, f0, c):
    h = [1 / 10, 1 / 12, 1 / 16]  # the thesis's 2a = 20, 24, 32 spacings: ratios 1.2 and 1.33
    order = capsule3d.observed_order(h, [f0 + c * x ** p for x in h])
    assert order.order == pytest.approx(p, rel=1e-7) and order.extrapolated == pytest.approx(f0, abs=1e-9)
    assert capsule3d.observed_order(h[::-1], [f0 + c * x ** p for x in h[::-1]]).order == pytest.approx(p, rel=1e-7)


def test_observed_order_must_be_able_to_fail():
    h = [0.1, 1 / 12, 1 / 16]
    assert capsule3d.observed_order(h, [0.50, 0.49, 0.51]) is None  # oscillating: no order
    assert capsule3d.observed_order(h, [0.50, 0.50, 0.50]) is None  # stalled
    assert capsule3d.observed_order(h[:2], [0.50, 0.49]) is None    # two grids
    assert capsule3d.observed_order([0.1, 0.1, 0.05], [0.5, 0.49, 0.48]) is None


def test_small_deformation_slopes_match_the_reference_rows():
    ds = ReferenceLibrary(REFERENCES).get("capsule3d", "steady_values.csv")
    for row in ds.rows:
        for law, prefix in (("neo_hookean", "small_deformation_nh_"), ("skalak", "small_deformation_sk_")):
            if row[0].startswith(prefix):
                g, d = float(ds.cell(row[0], "G")), float(ds.cell(row[0], "D"))
                assert d == pytest.approx(capsule3d.SMALL_DEFORMATION[law] * g, rel=1e-12), row[0]


def test_missing_reference_file_and_runs_are_handled(tmp_path, monkeypatch):
    monkeypatch.setattr(capsule3d.figures, "png_data_uri", no_png)  # what is drawn is tested above
    refs_dir = tmp_path / "references"
    shutil.copytree(REFERENCES / "capsule3d", refs_dir / "capsule3d")
    (refs_dir / "capsule3d" / "pozrikidis1995_G0.05.csv").unlink()
    (refs_dir / "capsule3d" / "steady_values.csv").unlink()
    run = load_run(FIXTURE, "ch5/sphere_nh_G0.05", "quick")
    section = capsule3d.build([run], ReferenceLibrary(refs_dir), "ch5")
    assert not section.problems, section.problems
    (row,) = section.validation.rows
    assert row.rp98 is None and row.error is None and row.rms_recomputed is None
    assert row.rms_scored == pytest.approx(0.0131263, rel=1e-5)  # still shown from score.json
    assert any("pozrikidis1995_G0.05.csv not found" in n for n in section.validation.notes)
    assert section.validation.deformation is not None  # drawn with the RP98 curve that is left
    assert "pozrikidis1995_G0.05.csv" not in {ds.filename for ds in section.datasets}
    # no references at all: the runs alone, said so
    bare = capsule3d.build([run], ReferenceLibrary(tmp_path / "none"), "ch5")
    assert bare.validation.rows and bare.validation.rows[0].rp98 is None
    assert any("provenance.json not found" in p for p in bare.problems)
    assert bare.conservation.bounds == [] and bare.conservation.rows[0]["values"][0]["ok"] is None
    # a missing run (catalogue only), a run without snapshots, and another chapter
    missing = Run(case_id="ch5/sphere_nh_G0.1", fidelity="quick", case=json.loads((FIXTURE / "case.json").read_text()))
    assert not capsule3d.build([missing], ReferenceLibrary(REFERENCES), "ch5").present
    no_snap = tmp_path / "run"
    shutil.copytree(FIXTURE, no_snap)
    (no_snap / "snapshots.h5").unlink()
    section = capsule3d.build([load_run(no_snap, "ch5/sphere_nh_G0.05", "quick")], ReferenceLibrary(REFERENCES), "ch5")
    assert section.present and section.sections is None and not section.section_rows and not section.problems
    assert not capsule3d.build([run], ReferenceLibrary(REFERENCES), "ch3").present
