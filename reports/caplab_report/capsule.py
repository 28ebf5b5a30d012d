"""Capsule extras of a chapter page (thesis section 2.2.4, chapters 3 and 4).

A capsule run is one whose case has a body with a ``membrane`` (catalogue/schema.json), or, for a
run without its case, whose summary.json has ``taylor_deformation_final``. Its series.h5 holds
``taylor_deformation`` (D_xy), ``inclination`` (rad, unwrapped: tumbling decreases it without
bound), ``area_change`` and ``tank_treading_phase``; its summary.json a string metric ``mode``.

What a chapter page gets, kept apart as the thesis statements are apart from the analytic and
convergence checks (DESIGN.md section 7):

- families: the runs of one rest shape and one minimum bending-energy shape overlaid like the
  thesis figures (2.17, 3.3, 3.10, 3.12, 3.17, 3.19, 4.4, 4.5): D_xy(kt), theta/pi(kt) and the
  membrane contours of snapshots.h5; ellipse families carry Jeffery's orbit (verification);
- validation: every thesis statement of the chapter (references/*/claims.json, ids "<chapter>.*")
  with the runs it is about and the verdict of ``caplab claims`` on them (claims.py; the checks
  are the C++ scorer's, solver/score/claims.hpp): a mode, the two sides of a bracket, the
  direction of a trend, a bound. score.json stays the per-run verdict; this check only says
  whether the runs together agree with the statement;
- verification: tumbling periods against Jeffery's half-turn period, and self-convergence (one
  case on several grids, the finest as the self-reference, as thesis figs. 2.18 and 4.3) and
  domain-size series;
- what a thesis figure is compared with that caplab does not have (provenance.json
  ``not_available``), e.g. the boundary-element curves of fig. 2.17.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import figures  # noqa: E402
from . import claims as claims_tool  # noqa: E402
from .references import PARAMETER_SYMBOLS, ReferenceLibrary, claim_summary, parameters_text  # noqa: E402
from .runs import Run, finite  # noqa: E402

SERIES = ("taylor_deformation", "inclination", "area_change", "tank_treading_phase")
TANK_TREADING = ("steady_tank_treading", "oscillating_tank_treading")
#: Capsule parameters in the keys of the claims (references/capsule2d/provenance.json format).
KEYS = ("shape", "aspect_ratio", "alpha", "reference_curvature", "capillary", "bending_ratio", "reynolds", "law")
# Restricted by a claim but never splitting a trend into series (the ch6 biconcave cells take C from G).
MATCH_ONLY_KEYS = ("area_dilation",)
MAX_CONTOUR_PANELS = 16


# ---- what a capsule run is --------------------------------------------------------------------

def capsule_body(run: Run) -> dict | None:
    for body in run.bodies:
        if isinstance(body.get("membrane"), dict):
            return body
    return None


def is_capsule(run: Run) -> bool:
    return capsule_body(run) is not None or run.summary_value("taylor_deformation_final") is not None


def _number(v, default=None):
    return float(v) if finite(v) else default


def parameters(run: Run) -> dict:
    """The run's capsule in the keys of the claims; the case-file defaults where a key is absent."""
    body = capsule_body(run) or {}
    shape = body.get("shape") if isinstance(body.get("shape"), dict) else {}
    membrane = body.get("membrane") if isinstance(body.get("membrane"), dict) else {}
    kind = shape.get("type")
    p = {"shape": kind, "capillary": _number(membrane.get("capillary")),
         "bending_ratio": _number(membrane.get("bending_ratio"), 0.0),
         "reference_curvature": membrane.get("reference_curvature", "initial"),
         "reynolds": run.reynolds, "angle": _number(shape.get("angle"), 0.0),
         "aspect_ratio": (_number(shape.get("aspect_ratio"), 2.0) if kind == "ellipse"
                          else _number(shape.get("aspect_ratio")) if kind == "oblate_spheroid" else None),
         "law": membrane.get("law"), "area_dilation": _number(membrane.get("area_dilation")),
         "alpha": _number(shape.get("alpha"), 1.39) if kind == "biconcave" else None}
    if kind == "circle" and p["reference_curvature"] == "circle":
        p["reference_curvature"] = "initial"  # the same curvature for a circle
    return p


def mode_of(run: Run) -> str | None:
    v = run.summary_value("mode")
    return v if isinstance(v, str) and v else None


# ---- Jeffery's orbit (references/capsule2d/provenance.json analytic.jeffery_orbit) -----------

def jeffery_half_period(r: float) -> float:
    """Time k t of a half-turn of a rigid ellipse of aspect ratio r: pi (1 + r^2)/r."""
    return math.pi * (1.0 + r * r) / r


def jeffery_orbit(t, r: float, theta0: float = 0.0) -> np.ndarray:
    """Inclination (rad, unwrapped, counter-clockwise from +x) of a rigid ellipse of aspect ratio
    ``r`` in u = (k y, 0) at times k t, from ``theta0``: tan(theta) = -tan(phi)/r with
    phi = r k t/(1 + r^2) + phi0 (thesis eq. 3.11 in caplab's convention)."""
    t = np.asarray(t, dtype=float)

    def g(phi):  # the continuous branch of atan(tan(phi)/r), increasing by pi per half-turn of phi
        return phi + np.arctan((1.0 - r) * np.sin(2 * phi) / ((r + 1.0) + (r - 1.0) * np.cos(2 * phi)))

    reduced = math.remainder(theta0, math.pi)  # the same orientation, in [-pi/2, pi/2]
    if abs(abs(reduced) - math.pi / 2) < 1e-12:
        phi0 = -math.pi / 2  # major axis across the flow: g(phi0) = -pi/2
    else:
        phi0 = math.atan(-r * math.tan(reduced))  # g(phi0) = -reduced
    return theta0 - (g(r * t / (1.0 + r * r) + phi0) - g(phi0))


# ---- matching runs to claims ------------------------------------------------------------------

def _matches(value, wanted) -> bool:
    if wanted is None:
        return True
    if isinstance(wanted, list):
        return any(_matches(value, w) for w in wanted)
    if isinstance(wanted, dict):
        lo, hi = wanted.get("from"), wanted.get("to")
        return finite(value) and finite(lo) and finite(hi) and lo - 1e-12 <= value <= hi + 1e-12
    if isinstance(wanted, str):
        return value == wanted
    if finite(wanted):
        return finite(value) and math.isclose(value, wanted, rel_tol=1e-6, abs_tol=1e-12)
    return False


def claim_matches(claim: dict, params: dict) -> list[str]:
    """The parameters of ``claim`` that ``params`` does not satisfy ([] when it is about the run).
    A key the claim does not give is not restricted (e.g. the parameter a trend varies)."""
    wrong = []
    for key, wanted in (claim.get("parameters") or {}).items():
        if key not in KEYS and key not in MATCH_ONLY_KEYS:
            continue
        if key == "reference_curvature" and params.get("bending_ratio") == 0:
            continue  # no bending stiffness: the minimum bending-energy shape plays no role
        if not _matches(params.get(key), wanted):
            wrong.append(f"{PARAMETER_SYMBOLS.get(key) or key} = {params.get(key)} (claim: {wanted})")
    return wrong


def references_claim(run: Run, claim_id: str) -> dict | None:
    """The acceptance entry of ``run`` that names ``claim_id`` (…claims.json#<id>), if any."""
    for a in run.case.get("acceptance", []):
        ref = a.get("reference") if isinstance(a, dict) else None
        if isinstance(ref, str) and ".json#" in ref and ref.rsplit("#", 1)[1] == claim_id:
            return a
    return None


def acceptance_problems(case: dict, refs: ReferenceLibrary) -> list[str]:
    """What is wrong with the acceptance entries of ``case`` that name a thesis statement
    (``…/claims.json#<id>``) or an analytic result (``…/provenance.json#<entry>``): a claim or entry
    that does not exist, a mode entry naming a claim that states no mode, a reference_mode other
    than the claim's, a case the claim is not about, or a reference_value other than the analytic one."""
    run = Run(case_id=str(case.get("id", "?")), fidelity="", case=case)
    params = parameters(run)
    problems = []
    for i, a in enumerate(case.get("acceptance", [])):
        ref = a.get("reference") if isinstance(a, dict) else None
        if not isinstance(ref, str) or ".json#" not in ref:
            continue
        where = f"{run.case_id}: acceptance/{i} ({ref})"
        res = refs.resolve(ref, a.get("reference_mode", a.get("reference_value")))
        if res.analytic is not None:  # references/<b>/provenance.json#<analytic entry>
            if res.mismatch:
                problems.append(f"{where}: {res.note.rsplit(' — ', 1)[-1]}")
            continue
        if res.claim is None:
            problems.append(f"{where}: {res.note}")
            continue
        if a.get("comparison") == "mode" and res.claim.get("kind") != "mode":
            problems.append(f"{where}: a mode comparison, but the claim is a {res.claim.get('kind')} statement")
        if res.mismatch:
            problems.append(f"{where}: {res.note.rsplit(' — ', 1)[-1]}")
        wrong = claim_matches(res.claim, params)
        if wrong:
            problems.append(f"{where}: the claim is not about this case: " + "; ".join(wrong))
    return problems


@dataclass
class ClaimRun:
    label: str
    anchor: str
    value: str
    ok: bool | None = None  #: None: shown, not judged
    scored: str = ""        #: the score.json verdict when the run's acceptance names the claim
    parameters: str = ""


@dataclass
class ClaimCheck:
    claim: dict
    summary: str
    parameters: str
    runs: list[ClaimRun] = field(default_factory=list)
    verdict: str = "no run"  #: consistent | inconsistent | no run | not enough runs | not checked
    note: str = ""

    @property
    def kind(self) -> str:
        return self.claim.get("kind", "")

    @property
    def group(self) -> str:
        return {"mode": "regimes", "bracket": "regimes", "trend": "trends", "bound": "trends"}.get(self.kind, "values")


def _parameters_text(params: dict) -> str:
    parts = [f"G = {params['capillary']:g}" if finite(params.get("capillary")) else "G = ?",
             f"E_b = {params.get('bending_ratio') or 0:g}"]
    if finite(params.get("reynolds")):
        parts.append(f"Re = {params['reynolds']:g}")
    return ", ".join(parts)


def _value_text(claim: dict, row: dict) -> str:
    """What a run shows for a claim, from a row of the ``caplab claims`` result."""
    if row.get("status") != "ok":
        return str(row.get("note") or f"run {row.get('status')}")
    value, note = row.get("value"), str(row.get("note") or "")
    if isinstance(value, str):
        shown = value
    elif finite(value):
        statistic = f" {claim['statistic']}" if claim.get("statistic") else ""
        shown = f"{claim.get('metric')}{statistic} = {value:.4g}"
    else:
        shown = ""
    varying = claim.get("varying")
    if isinstance(varying, str) and finite(row.get("parameter")):
        shown += f" at {PARAMETER_SYMBOLS.get(varying) or varying} = {row['parameter']:g}"
    if note:
        shown = f"{shown} ({note})" if shown else note
    return shown or "–"


def check_claims(claims: list[dict], runs: list[Run], claims_file: Path | None = None,
                 only: str | None = None) -> list[ClaimCheck]:
    """The verdict of each claim of ``claims`` on ``runs``, by ``caplab claims`` (solver/score/claims.hpp)
    on ``claims_file`` (``--only``: ``only``), or on a document of ``claims`` when no file is given.
    Runs without a directory (in the catalogue, never run) are not about any claim."""
    checks = {c.get("id"): ClaimCheck(c, claim_summary(c), parameters_text(c.get("parameters"))) for c in claims}
    by_dir = {str(r.directory.resolve()): r for r in runs if r.directory is not None}
    if not by_dir:
        return list(checks.values())
    result = claims_tool.evaluate(claims_file or {"claims": claims}, [Path(d) for d in by_dir], only)
    params = {str(Path(r["directory"]).resolve()): r.get("parameters") or {} for r in result.get("runs", [])}
    for out in result.get("claims", []):
        check = checks.get(out.get("id"))
        if check is None:
            continue
        check.verdict = out.get("verdict") or "not checked"
        if check.verdict in ("inconsistent", "not enough runs") or out.get("problems"):
            check.note = str(out.get("message") or "")
        for row in out.get("runs", []):
            directory = str(Path(row["directory"]).resolve())
            run = by_dir.get(directory)
            ok = {"pass": True, "fail": False}.get(row.get("verdict"))
            check.runs.append(ClaimRun(f"{row.get('run')} ({row.get('fidelity')})", run.anchor if run else "",
                                       _value_text(check.claim, row), ok, str(row.get("scored") or ""),
                                       _parameters_text(params.get(directory, {}))))
    return list(checks.values())


def check_claim(claim: dict, runs: list[Run]) -> ClaimCheck:
    """``check_claims`` for one claim."""
    return check_claims([claim], runs)[0]


# ---- series and figures -----------------------------------------------------------------------

def capsule_series(run: Run, cache: dict) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """{column: (t, values)} of the capsule columns of series.h5 (read once per run)."""
    key = id(run)
    if key not in cache:
        out = {}
        path = run.series_path
        if path is not None:
            t, cols, _ = figures.read_series(path)
            if t is not None:
                for c in cols:
                    for name in SERIES:
                        if c.name == name or c.name.endswith("." + name):
                            out.setdefault(name, (t.values, c.values))
        cache[key] = out
    return cache[key]


@dataclass
class Family:
    key: tuple
    title: str
    runs: list[Run]
    labels: dict[int, str] = field(default_factory=dict)
    deformation: str | None = None
    inclination: str | None = None
    contours: str | None = None
    jeffery: dict | None = None   #: {"r", "half_period", "rows": [...]} for ellipse families
    problems: list[str] = field(default_factory=list)


CURVATURE_TEXT = {"initial": "the initial shape", "circle": "a circle", "flat": "flat"}


def family_key(params: dict) -> tuple:
    return (params["shape"], params.get("aspect_ratio"), params.get("alpha"), params["reference_curvature"])


def family_title(key: tuple) -> str:
    shape, r, alpha, curvature = key
    what = {"ellipse": f"elliptical (r = {r:g})" if finite(r) else "elliptical",
            "biconcave": f"biconcave (α = {alpha:g})" if finite(alpha) else "biconcave"}.get(shape, shape or "?")
    return f"{what} capsules, minimum bending-energy shape: {CURVATURE_TEXT.get(curvature, curvature)}"


def _run_labels(runs: list[Run]) -> dict[int, str]:
    """Legend text per run: the parameters that vary within the family, then fidelity and grid."""
    params = [parameters(r) for r in runs]
    varying = [k for k in ("capillary", "bending_ratio", "reynolds")
               if len({p.get(k) for p in params}) > 1] or ["capillary", "bending_ratio"]
    several_fidelities = len({r.fidelity for r in runs}) > 1
    several_grids = len({r.fine_spacing for r in runs}) > 1
    several_domains = len({_domain(r) for r in runs}) > 1
    labels = {}
    for run, p in zip(runs, params):
        text = ", ".join(f"{PARAMETER_SYMBOLS[k]} = {p[k]:g}" for k in varying if finite(p.get(k)))
        extra = [run.fidelity] if several_fidelities else []
        if several_grids and run.fine_spacing:
            extra.append(f"Δx_f = {run.fine_spacing:g}")
        if several_domains and _domain(run):
            extra.append("domain " + _domain_text(run))
        labels[id(run)] = text + (f" ({', '.join(extra)})" if extra else "")
    return labels


def _overlay(family: Family, name: str, ylabel: str, scale: float, cache: dict, jeffery=None) -> str | None:
    curves = [(run, capsule_series(run, cache).get(name)) for run in family.runs]
    curves = [(run, c) for run, c in curves if c is not None]
    if not curves:
        return None
    fig, ax = plt.subplots(figsize=(8.6, 3.9))
    cmap = plt.get_cmap("viridis")
    for i, (run, (t, y)) in enumerate(curves):
        step = max(1, t.size // figures.MAX_POINTS)
        ax.plot(t[::step], y[::step] / scale, lw=1.1, color=cmap(i / max(1, len(curves) - 1) * 0.9),
                label=family.labels.get(id(run), run.case_id))
    if jeffery is not None:
        t_end = max(float(c[0][-1]) for _, c in curves)
        tj = np.linspace(0.0, t_end, 2000)
        for theta0 in jeffery["angles"]:
            ax.plot(tj, jeffery_orbit(tj, jeffery["r"], theta0) / scale, "k--", lw=1.0,
                    label=f"verification: Jeffery's orbit, rigid ellipse r = {jeffery['r']:g} (eq. 3.11, analytic)")
    ax.set_xlabel("k t")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(fontsize=7, loc="best", framealpha=0.85)
    ax.set_title(family.title, fontsize=9)
    fig.tight_layout()
    return figures.png_data_uri(fig)


def _ring(points: np.ndarray, connectivity: np.ndarray) -> np.ndarray:
    """The nodes of a closed ring in the order of its segments (node 0 first), closed."""
    if connectivity.ndim != 2 or connectivity.shape[1] != 2 or connectivity.shape[0] != points.shape[0]:
        order = list(range(points.shape[0]))
    else:
        nxt = {int(a): int(b) for a, b in connectivity}
        order, node = [], 0
        while node not in order and node in nxt:
            order.append(node)
            node = nxt[node]
        if len(order) != points.shape[0]:
            order = list(range(points.shape[0]))
    ring = points[order, :2]
    return np.vstack([ring, ring[:1]])


def _contours(family: Family) -> str | None:
    panels = []
    for run in family.runs:
        path = run.snapshots_path
        if path is None:
            continue
        meshes, problem = figures.read_meshes(path)
        if problem:
            family.problems.append(f"{run.case_id}: {problem}")
        meshes = [m for m in meshes if m.points.ndim == 2 and m.points.shape[0] >= 3]
        if meshes:
            panels.append((run, meshes))
    if not panels:
        return None
    shown = panels[:MAX_CONTOUR_PANELS]
    if len(panels) > len(shown):
        family.problems.append(f"contours of {len(panels) - len(shown)} more run(s) not drawn")
    cols = min(4, len(shown))
    rows = math.ceil(len(shown) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols + 0.4, 2.5 * rows + 0.5), squeeze=False)
    for ax in axes.ravel():
        ax.set_visible(False)
    for ax, (run, meshes) in zip(axes.ravel(), shown):
        ax.set_visible(True)
        first = meshes[0].points[:, :2]
        centre = first.mean(axis=0)
        for i, m in enumerate(meshes):
            final = i == len(meshes) - 1
            ring = _ring(m.points, m.connectivity) - centre
            ax.plot(ring[:, 0], ring[:, 1], lw=1.4 if final else 0.8, color="#1f4e79" if final else "#9db3cc",
                    label=f"kt = {m.time:g}" if final or i == 0 else None)
            ax.plot(ring[0, 0], ring[0, 1], "o", ms=3.5 if final else 2.5, color="#d62728")  # node 0
        ax.set_aspect("equal")
        ax.set_title(family.labels.get(id(run), run.case_id), fontsize=7)
        ax.tick_params(labelsize=6)
        ax.legend(fontsize=6, loc="upper right", framealpha=0.8)
    fig.suptitle(f"{family.title}: membrane contours from snapshots.h5 (final bold; red: node 0)", fontsize=8)
    fig.tight_layout()
    return figures.png_data_uri(fig)


def _jeffery_rows(family: Family, r: float) -> list[dict]:
    half = jeffery_half_period(r)
    rows = []
    for run in family.runs:
        period = run.summary_value("tumbling_period")
        if run.status == "ok" and mode_of(run) == "tumbling" and finite(period):
            rows.append({"run": family.labels.get(id(run), run.case_id), "anchor": run.anchor,
                         "period": f"{period:.4g}", "deviation": f"{100 * (period - half) / half:+.1f} %"})
    return rows


# ---- self-convergence and domain series (verification) ----------------------------------------

@dataclass
class Series:
    """Runs of one capsule case that differ only in the grid, the domain or the membrane nodes."""

    what: str              #: "grid" | "domain" | "nodes"
    title: str
    runs: list[Run]        #: coarsest (smallest, fewest nodes) first; the last is the self-reference
    rows: list[dict] = field(default_factory=list)
    figure: str | None = None


def _domain(run: Run) -> tuple:
    size = (run.physics.get("domain") or {}).get("size")
    return tuple(size) if isinstance(size, list) else ()


def _domain_text(run: Run) -> str:
    return " × ".join(f"{x:g}" for x in _domain(run))


def _nodes(run: Run) -> int | None:
    n = ((capsule_body(run) or {}).get("membrane") or {}).get("nodes")
    return int(n) if finite(n) else None


def _grid_per_marker(run: Run) -> float:
    """Nodes times fine spacing: within one capsule shape, proportional to the grid spacing over
    the marker spacing (0 when unknown)."""
    n, h = _nodes(run), run.fine_spacing
    return n * h if n and h else 0.0


def _rms_to_reference(run: Run, ref: Run, name: str, cache: dict):
    a, b = capsule_series(run, cache).get(name), capsule_series(ref, cache).get(name)
    if a is None or b is None:
        return None
    t0, t1 = max(a[0][0], b[0][0]), min(a[0][-1], b[0][-1])
    sel = (a[0] >= t0) & (a[0] <= t1)
    if not sel.any():
        return None
    diff = a[1][sel] - np.interp(a[0][sel], b[0], b[1])
    return float(np.sqrt(np.nanmean(diff ** 2))), float(np.nanmax(np.abs(diff)))


def _one_per_spacing(members: list[Run]) -> list[Run]:
    """A grid study refines the grid (and the membrane with it, thesis fig. 4.3, or not, fig.
    2.18); a run that differs from another at its spacing only in the node count belongs to a
    node study: keep, per spacing, the run whose marker-to-grid ratio is nearest the study's median."""
    ratios = sorted(_grid_per_marker(r) for r in members)
    median = ratios[len(ratios) // 2]
    best: dict[float, Run] = {}
    for run in members:
        other = best.get(run.fine_spacing)
        if other is None or abs(_grid_per_marker(run) - median) < abs(_grid_per_marker(other) - median):
            best[run.fine_spacing] = run
    return [r for r in members if best.get(r.fine_spacing) is r]


_STUDY = {  # what: (key fixed beyond the capsule's parameters, the measure that varies)
    "grid": (lambda r: _domain(r), lambda r: -r.fine_spacing),
    "domain": (lambda r: (r.fine_spacing, _nodes(r)), lambda r: _domain(r)[0] if _domain(r) else 0),
    "nodes": (lambda r: (r.fine_spacing,) + _domain(r), lambda r: _nodes(r) or 0),
}


def series_groups(runs: list[Run], cache: dict) -> list[Series]:
    out = []
    for what, (fixed_of, measure) in _STUDY.items():
        groups: dict[tuple, list[Run]] = {}
        for run in runs:
            if run.status != "ok" or run.fine_spacing is None:
                continue
            p = parameters(run)
            groups.setdefault(tuple(p.get(k) for k in KEYS) + tuple(fixed_of(run)), []).append(run)
        for members in groups.values():
            if what == "grid":
                members = _one_per_spacing(members)
            if len({measure(r) for r in members}) < 2:
                continue
            members = sorted(members, key=lambda r: (measure(r), r.fidelity))
            ref = members[-1]
            p = parameters(ref)
            title = (f"{family_title(family_key(p))}, G = {p['capillary']:g}, E_b = {p['bending_ratio']:g}"
                     + (f", Re = {p['reynolds']:g}" if finite(p.get("reynolds")) else ""))
            group = Series(what, title, members)
            errors = []
            for run in members[:-1]:
                d = _rms_to_reference(run, ref, "taylor_deformation", cache)
                th = _rms_to_reference(run, ref, "inclination", cache)
                errors.append((run.fine_spacing, d[0] if d else None))
                group.rows.append({"run": run.case_id, "fidelity": run.fidelity, "anchor": run.anchor,
                                   "spacing": f"{run.fine_spacing:g}", "domain": _domain_text(run),
                                   "nodes": _nodes(run) or "–",
                                   "d_rms": f"{d[0]:.3g}" if d else "–", "d_max": f"{d[1]:.3g}" if d else "–",
                                   "theta_rms": f"{th[0]:.3g}" if th else "–", "order": ""})
            if what == "grid":
                for i in range(1, len(errors)):
                    (h1, e1), (h2, e2) = errors[i - 1], errors[i]
                    if e1 and e2 and e1 > 0 and e2 > 0 and h1 != h2:
                        group.rows[i]["order"] = f"{math.log(e1 / e2) / math.log(h1 / h2):.2f}"
            group.figure = _series_figure(group, cache)
            out.append(group)
    return out


def _series_figure(group: Series, cache: dict) -> str | None:
    fig, axes = plt.subplots(1, 2, figsize=(9.4, 3.4))
    drawn = False
    for i, run in enumerate(group.runs):
        data = capsule_series(run, cache)
        last = i == len(group.runs) - 1
        tag = (f"Δx_f = {run.fine_spacing:g}, {_nodes(run)} nodes" if group.what == "grid"
               else f"{_nodes(run)} nodes" if group.what == "nodes"
               else "domain " + _domain_text(run))
        tag += " (self-reference)" if last else ""
        for ax, name, scale in ((axes[0], "taylor_deformation", 1.0), (axes[1], "inclination", math.pi)):
            if name in data:
                t, y = data[name]
                ax.plot(t, y / scale, lw=1.4 if last else 1.0, ls="-" if last else "--", label=tag)
                drawn = True
    if not drawn:
        plt.close(fig)
        return None
    axes[0].set_ylabel("D_xy")
    axes[1].set_ylabel("inclination θ/π")
    for ax in axes:
        ax.set_xlabel("k t")
        ax.grid(True, lw=0.3, alpha=0.6)
        ax.legend(fontsize=7)
    study = {"grid": "self-convergence", "domain": "domain size", "nodes": "membrane nodes"}[group.what]
    fig.suptitle(f"verification ({study}): {group.title}",
                 fontsize=8)
    fig.tight_layout()
    return figures.png_data_uri(fig)


# ---- the chapter's capsule section --------------------------------------------------------------

@dataclass
class Capsules:
    runs: list[Run] = field(default_factory=list)
    families: list[Family] = field(default_factory=list)
    claims: list[ClaimCheck] = field(default_factory=list)
    series: list[Series] = field(default_factory=list)
    not_available: list[dict] = field(default_factory=list)
    analytic: dict = field(default_factory=dict)   #: provenance "analytic" entries used (jeffery_orbit, ...)
    datasets: list = field(default_factory=list)   #: claims datasets used on the page
    problems: list[str] = field(default_factory=list)

    @property
    def present(self) -> bool:
        return bool(self.runs)

    def claims_in(self, group: str) -> list[ClaimCheck]:
        return [c for c in self.claims if c.group == group]

    @property
    def tally(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for c in self.claims:
            out[c.verdict] = out.get(c.verdict, 0) + 1
        return out


def build(runs: list[Run], refs: ReferenceLibrary, chapter: str) -> Capsules:
    section = Capsules(runs=[r for r in runs if is_capsule(r)])
    if not section.present:
        return section
    cache: dict = {}
    by_family: dict[tuple, list[Run]] = {}
    # Families, contours and convergence series are the 2D rings'; 3D capsules have their own
    # section (capsule3d.py). The thesis statements below are checked for both.
    rings = [r for r in section.runs if r.dimension != 3]
    for run in rings:
        if capsule_body(run) is None:
            section.problems.append(f"{run.case_id}: no capsule body in case.json; not placed in a family")
            continue
        by_family.setdefault(family_key(parameters(run)), []).append(run)
    for key, members in sorted(by_family.items(), key=lambda kv: json.dumps(kv[0], default=str)):
        members.sort(key=lambda r: tuple(parameters(r).get(k) or 0 for k in ("capillary", "bending_ratio", "reynolds"))
                     + (r.fidelity, -(r.fine_spacing or 0)))
        family = Family(key, family_title(key), members, _run_labels(members))
        try:
            family.deformation = _overlay(family, "taylor_deformation", "D_xy", 1.0, cache)
            jeffery = None
            if key[0] == "ellipse" and finite(key[1]):
                angles = sorted({parameters(r)["angle"] for r in members})
                jeffery = {"r": key[1], "angles": angles}
                family.jeffery = {"r": key[1], "half_period": f"{jeffery_half_period(key[1]):.4f}",
                                  "angles": ", ".join(f"{a:g}" for a in angles),
                                  "rows": _jeffery_rows(family, key[1])}
            family.inclination = _overlay(family, "inclination", "inclination θ/π", math.pi, cache, jeffery)
            family.contours = _contours(family)
        except Exception as err:  # a broken file must not stop the report
            family.problems.append(f"figure failed: {err}")
        if family.deformation is None and family.inclination is None:
            family.problems.append("no run of this family has a capsule series in series.h5")
        section.families.append(family)
    try:
        section.series = series_groups(rings, cache)
    except Exception as err:
        section.problems.append(f"convergence series failed: {err}")

    by_file: dict[str, tuple] = {}
    for ds, claim in refs.claims(chapter + "."):
        by_file.setdefault(ds.anchor, (ds, []))[1].append(claim)
    for ds, claims in by_file.values():
        try:
            section.claims += check_claims(claims, section.runs, ds.path, chapter + ".")
        except claims_tool.ClaimsUnavailable as err:
            section.problems.append(f"thesis statements of {ds.rel} not checked: {err}")
            section.claims += [ClaimCheck(c, claim_summary(c), parameters_text(c.get("parameters")),
                                          verdict="not checked", note=str(err)) for c in claims]
    section.datasets = [ds for ds, _ in by_file.values()]
    if not section.claims:
        section.problems.append(f"no thesis statements for {chapter} in references/*/claims.json")
    for bench, entries in refs.provenance_entries("not_available"):
        for entry in entries if isinstance(entries, list) else []:
            if isinstance(entry, dict) and chapter in entry.get("chapters", []):
                section.not_available.append(dict(entry, benchmark=bench))
    for bench, analytic in refs.provenance_entries("analytic"):
        if isinstance(analytic, dict) and any(ds.benchmark == bench for ds in section.datasets):
            section.analytic.update({k: dict(v, benchmark=bench) for k, v in analytic.items() if isinstance(v, dict)})
    return section
