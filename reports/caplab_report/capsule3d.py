"""Chapter 5 section of the report: 3D capsules in simple shear flow (thesis chapter 5).

A 3D capsule run is a chapter 5 run whose case has ``physics.dimension == 3`` and a body with a
``membrane``. Its series.h5 holds taylor_deformation (D_xz), inclination (rad), length, width,
thickness (semi-axes of the equivalent ellipsoid, in a), volume_change, surface_area_change,
max_area_change and tank_treading_phase against t in L/U = 1/k (L = a, U = k a, so t is k t);
its snapshots.h5 the capsule surface mesh (``/step_*/<body>/points``, ``connectivity`` [M][3],
point fields ``max_principal_stretch`` and ``area_ratio``). Conventions:
references/capsule3d/provenance.json ``conventions``.

What the section shows, kept apart as DESIGN.md section 7 asks:

1. validation (external data): D(kt) of the unbounded NH spheres with the Pozrikidis 1995 and
   Ramanujan & Pozrikidis 1998 (RP98) curves of the same G, theta(kt)/pi, and a table of the steady
   D against the RP98 steady value and the RMS distance to Pozrikidis 1995 (score.json, and
   recomputed here as the scorer does it: over the reference abscissae);
2. verification (analytic limits and convergence): the steady D of the spheres against the
   first-order small-deformation theory D = 25/4 G (NH) and 25/6 G (Skalak, C = 1) (Barthes-Biesel
   1980, in thesis units; references/capsule3d/provenance.json ``analytic``); grid studies (runs
   that differ only in the fine spacing: observed order of the steady D and its Richardson
   extrapolation from three resolutions), domain studies (only the domain differs) and two-block
   runs against their uniform-grid twin (moving.twin_of: steady D difference, cost ratios);
3. conservation and membrane: volume_change, surface_area_change and max_area_change against kt
   for every run, their largest values next to the thesis bounds (claims ch5.volume_change and
   ch5.biconcave.area_change, applied to the runs the claim is about);
4. shape: the cross-section of the last snapshot's capsule mesh with the plane y = y_c through its
   volume centroid (the shear plane x-z; thesis fig. 5.8), and for the oblate spheroids and the
   biconcave discoids D, theta and the semi-axes against kt (thesis figs. 5.15-5.17, 5.19);
5. cost: wall time, MLUPS, and the share of the IB and membrane stages (manifest stage_share).

The thesis statements of chapter 5 (claims.json) are checked by capsule.py, not here. A run that
did not finish is listed, never plotted; a part with no run to show is left out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from . import capsule, figures, moving  # noqa: E402
from .convergence import Order, observed_order  # noqa: E402
from .references import Dataset, ReferenceLibrary  # noqa: E402
from .runs import Run, finite  # noqa: E402

CHAPTER = "ch5"
BENCHMARK = "capsule3d"
STEADY_FILE = "steady_values.csv"
CLAIMS_FILE = "claims.json"
#: Reference curves D(kt) per G: file name pattern, legend text, line style (dashed: references).
CURVES = (("pozrikidis1995_G{G}.csv", "Pozrikidis 1995", "--"),
          ("ramanujan1998_G{G}.csv", "Ramanujan & Pozrikidis 1998", "-."))
#: First-order small-deformation theory, steady D_xz = slope * G in thesis units (Barthes-Biesel
#: 1980: D = 5/4 (2 + nu_s)/(1 + nu_s) eps, nu_s = 1/2; eps = 3 G for NH, 2 G for Skalak C = 1).
SMALL_DEFORMATION = {"neo_hookean": 25.0 / 4.0, "skalak": 25.0 / 6.0}
SMALL_DEFORMATION_ENTRY = {"neo_hookean": "small_deformation_nh", "skalak": "small_deformation_sk"}
SMALL_G = 0.05  #: the steady D of runs up to this G are tabled against the theory (validity: G -> 0)
#: Bounds of the thesis (claims.json): (claim id, summary metric, series column).
BOUNDS = (("ch5.volume_change", "volume_change_max", "volume_change"),
          ("ch5.biconcave.area_change", "surface_area_change_max", "surface_area_change"))
CONSERVED = (("volume_change", "V/V₀ − 1 [%]"), ("surface_area_change", "A/A₀ − 1 [%]"),
             ("max_area_change", "max over triangles |Aₑ/Aₑ₀ − 1| [%]"))
#: provenance.json "discrepancies" shown beside the part they bear on.
DISCREPANCIES = {"validation": ("membrane_law_of_the_bem_references",),
                 "verification": ("small_deformation_order",)}
LAW_LABELS = {"neo_hookean": "NH", "skalak": "SK", "zero_thickness": "ZT"}
SHAPE_LABELS = {"sphere": "sphere", "oblate_spheroid": "oblate spheroid", "biconcave_discoid": "biconcave discoid"}
FIDELITY_WIDTH = {"quick": 1.0, "standard": 1.6, "thesis": 2.2}
MAX_SECTION_PANELS = 16


# ---- what a 3D capsule run is ----------------------------------------------------------------------

def is_capsule3d(run: Run) -> bool:
    return run.dimension == 3 and capsule.capsule_body(run) is not None


def params(run: Run) -> dict:
    """The run's capsule and set-up: capsule.parameters plus law, C, the oblate aspect ratio, walls,
    domain, refinement, membrane subdivisions and the equivalent radius a (half the diameter)."""
    body = capsule.capsule_body(run) or {}
    shape = body.get("shape") if isinstance(body.get("shape"), dict) else {}
    membrane = body.get("membrane") if isinstance(body.get("membrane"), dict) else {}
    domain = run.physics.get("domain") if isinstance(run.physics.get("domain"), dict) else {}
    boundaries = domain.get("boundaries") if isinstance(domain.get("boundaries"), list) else []
    size = domain.get("size") if isinstance(domain.get("size"), list) else []
    p = capsule.parameters(run)
    p.update(law=membrane.get("law"), area_dilation=membrane.get("area_dilation"),
             aspect_ratio=shape.get("aspect_ratio") if finite(shape.get("aspect_ratio")) else None,
             walls="wall" in boundaries, domain=tuple(size), refinement=moving.refinement(run),
             spacing=run.fine_spacing, subdivisions=membrane.get("subdivisions"),
             radius=shape["diameter"] / 2 if finite(shape.get("diameter")) else 1.0)
    return p


def physics_key(p: dict) -> tuple:
    return tuple(p.get(k) for k in ("shape", "aspect_ratio", "law", "area_dilation", "capillary", "reynolds", "walls"))


def run_label(run: Run, p: dict | None = None) -> str:
    p = params(run) if p is None else p
    shape = SHAPE_LABELS.get(p["shape"], p["shape"] or "?")
    if p["shape"] == "oblate_spheroid" and finite(p.get("aspect_ratio")):
        shape += f" {p['aspect_ratio']:.3g}:1"
    g = f"G = {p['capillary']:g}" if finite(p.get("capillary")) else "G = ?"
    re = f", Re = {p['reynolds']:g}" if finite(p.get("reynolds")) and p.get("walls") else ""
    return f"{LAW_LABELS.get(p['law'], p['law'] or '?')} {shape}, {g}{re} ({run.fidelity})"


def steady_d(run: Run):
    return run.metric("taylor_deformation_mean")


def fidelity_text(runs: list[Run]) -> str:
    fids = sorted({r.fidelity for r in runs})
    return "fidelity " + ", ".join(fids) if fids else "no run"


# ---- geometry of the surface mesh --------------------------------------------------------------------

def volume_centroid(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Centroid of the volume enclosed by a closed triangulated surface: the sum over the tetrahedra
    from the mean node to each triangle (a consistent orientation, outward or inward, cancels); the
    mean node where the surface encloses no volume."""
    points = np.asarray(points, dtype=float)
    origin = points.mean(axis=0)
    a, b, c = (points[triangles[:, i]] - origin for i in range(3))
    v = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    total = v.sum()
    if not np.isfinite(total) or abs(total) < 1e-300:
        return origin
    return origin + (v[:, None] * (a + b + c)).sum(axis=0) / (4.0 * total)


def plane_section(points: np.ndarray, triangles: np.ndarray, level: float, axis: int = 1) -> np.ndarray:
    """Segments [K][2][3] where the plane ``points[:, axis] == level`` cuts the triangles. A node on
    the plane (to round-off) counts as above it, so that every cut triangle has exactly two cut
    edges, an edge lying in the plane is drawn once (by the triangle below it) and the segments
    join end to end."""
    points = np.asarray(points, dtype=float)
    triangles = np.asarray(triangles, dtype=int).reshape(-1, 3)
    if points.size == 0 or triangles.size == 0:
        return np.zeros((0, 2, 3))
    d = points[:, axis] - level
    d[np.abs(d) <= 1e-12 * float(np.ptp(points, axis=0).max())] = 0.0
    above = d >= 0.0
    sides = above[triangles]
    n_above = sides.sum(axis=1)
    tri = triangles[(n_above == 1) | (n_above == 2)]
    if tri.size == 0:
        return np.zeros((0, 2, 3))
    a = tri
    b = np.roll(tri, -1, axis=1)  # edges (0, 1), (1, 2), (2, 0)
    cut = above[a] != above[b]
    da, db = d[a], d[b]
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(cut, da / (da - db), 0.0)
    crossing = points[a] + w[..., None] * (points[b] - points[a])  # [K][3 edges][3]
    first_two = np.argsort(~cut, axis=1, kind="stable")[:, :2]
    segments = np.take_along_axis(crossing, first_two[..., None], axis=1)
    # a triangle below the plane touching it at one node only gives a point: no segment
    return segments[np.any(segments[:, 0] != segments[:, 1], axis=1)]


@dataclass
class Snapshot:
    time: float
    points: np.ndarray
    triangles: np.ndarray
    fields: dict = field(default_factory=dict)  #: point fields (max_principal_stretch, area_ratio)


def last_surface(run: Run, name: str | None = None) -> tuple[Snapshot | None, str]:
    """(the capsule mesh at the last snapshot time, problem) from snapshots.h5: the triangle mesh
    named after the capsule body (any triangle mesh when ``name`` is None) with its point fields."""
    path = run.snapshots_path
    if path is None:
        return None, ""
    meshes, problem = figures.read_meshes(path)
    meshes = [m for m in meshes if m.connectivity.ndim == 2 and m.connectivity.shape[1] == 3
              and m.points.ndim == 2 and m.points.shape[1] == 3 and (name is None or m.name == name)]
    if not meshes:
        return None, problem or "snapshots.h5 holds no triangulated capsule mesh"
    last = max(meshes, key=lambda m: (np.nan_to_num(m.time, nan=-np.inf)))
    snap = Snapshot(last.time, last.points, last.connectivity)
    try:
        import h5py
        with h5py.File(path, "r") as f:
            for step_name in f:
                step = f[step_name]
                if not hasattr(step, "keys") or last.name not in step:
                    continue
                t = np.asarray(step.attrs.get("time", [np.nan]), dtype=float).ravel()
                if t.size and (t[0] == last.time or (np.isnan(t[0]) and np.isnan(last.time))):
                    group = step[last.name]
                    for key in group:
                        ds = group[key]
                        if key not in ("points", "connectivity") and getattr(ds, "shape", None) == (last.points.shape[0],):
                            snap.fields[key] = np.asarray(ds[()], dtype=float)
                    break
    except Exception as err:  # h5py raises many types for a damaged file
        return snap, f"point fields unreadable: {err}"
    return snap, ""


# ---- convergence ---------------------------------------------------------------------------------------



# ---- figures ---------------------------------------------------------------------------------------------

@dataclass
class Figure:
    src: str
    caption: str


def _colours(keys) -> dict:
    keys = sorted(set(keys), key=lambda k: (k is None, k))
    cmap = plt.get_cmap("viridis" if len(keys) <= 6 else "turbo")
    return {k: cmap(0.08 + 0.84 * i / max(1, len(keys) - 1)) for i, k in enumerate(keys)}


def _thin(t: np.ndarray, y: np.ndarray):
    step = max(1, t.size // figures.MAX_POINTS)
    return t[::step], y[::step]


def _finish(fig, axes, title: str) -> str:
    axes = np.ravel(axes)
    for ax in axes:
        ax.grid(True, lw=0.3, alpha=0.6)
    fig.suptitle(title, fontsize=9)
    if len(axes) > 1:  # one axes needs no layout: the PNG is cropped to what is drawn (figures.png_data_uri)
        fig.tight_layout()
    return figures.png_data_uri(fig)


def _legend_outside(ax, n: int) -> None:
    ax.legend(fontsize=6.5 if n > 8 else 7.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), framealpha=0.85,
              ncol=1 if n <= 18 else 2)


def _against_time(ax, ylabel: str) -> None:
    """Axis labels of a history against k t, and the legend beside it."""
    ax.set_xlabel("k t")
    ax.set_ylabel(ylabel)
    _legend_outside(ax, len(ax.get_lines()))


# ---- 1. validation ---------------------------------------------------------------------------------------

@dataclass
class ValidationRow:
    run: Run
    capillary: float
    steady: float | None
    rp98: float | None
    rp98_spread: float | None
    rms_scored: float | None = None
    rms_tolerance: float | None = None
    rms_verdict: str = ""
    rms_recomputed: float | None = None
    rms_points: int = 0

    @property
    def error(self) -> float | None:
        return (self.steady - self.rp98) / self.rp98 if finite(self.steady) and finite(self.rp98) and self.rp98 else None


@dataclass
class Validation:
    rows: list[ValidationRow] = field(default_factory=list)
    deformation: Figure | None = None
    inclination: Figure | None = None
    notes: list[str] = field(default_factory=list)
    datasets: list[Dataset] = field(default_factory=list)


def _steady_row(refs: ReferenceLibrary, key: str) -> tuple[float | None, float | None]:
    ds = refs.get(BENCHMARK, STEADY_FILE)
    if ds is None:
        return None, None

    def number(column):
        try:
            v = float(ds.cell(key, column) or "")
        except ValueError:
            return None
        return v if math.isfinite(v) else None

    return number("D"), number("uncertainty")


def reference_curves(refs: ReferenceLibrary, g: float) -> list[tuple[str, str, Dataset, np.ndarray, np.ndarray]]:
    """(label, line style, dataset, t, D) of every reference D(kt) of capillary ``g`` present."""
    out = []
    for pattern, label, style in CURVES:
        ds = refs.get(BENCHMARK, pattern.format(G=f"{g:g}"))
        if ds is None or "t" not in ds.columns or "D" not in ds.columns:
            continue
        t, d = np.asarray(ds.column_values("t")), np.asarray(ds.column_values("D"))
        ok = np.isfinite(t) & np.isfinite(d)
        if ok.sum() >= 2:
            out.append((label, style, ds, t[ok], d[ok]))
    return out


def _validation_refs(run: Run) -> int:
    """How many acceptance entries of the run name an external capsule3d dataset."""
    return sum(1 for a in run.case.get("acceptance", []) if isinstance(a, dict)
               and str(a.get("reference", "")).startswith(f"references/{BENCHMARK}/")
               and a.get("comparison") in ("time_series", "relative"))


def sweep_runs(runs: list[Run], law: str, cache: dict) -> list[Run]:
    """The unbounded spheres of one law, one run per (G, fidelity): the one scored against the most
    reference data (the base case, not a member of the studies), then a two-block one."""
    chosen: dict[tuple, tuple] = {}  # (G, fidelity) -> (rank, run)
    for run in runs:
        p = params(run)
        if p["shape"] != "sphere" or p["law"] != law or p["walls"] or not finite(p["capillary"]):
            continue
        if "taylor_deformation" not in moving.series(run, cache):
            continue
        key = (p["capillary"], run.fidelity)
        rank = (-_validation_refs(run), p["refinement"] != "two_level", len(run.case_id), run.case_id)
        if key not in chosen or rank < chosen[key][0]:
            chosen[key] = (rank, run)
    return [r for _, r in sorted(chosen.values(), key=lambda x: (params(x[1])["capillary"], x[1].fidelity))]


def validation(runs: list[Run], refs: ReferenceLibrary, cache: dict) -> Validation:
    out = Validation()
    nh = sweep_runs(runs, "neo_hookean", cache)
    if not nh:
        return out
    colours = _colours(params(r)["capillary"] for r in nh)
    used: dict[str, Dataset] = {}
    fig, ax = plt.subplots(figsize=(9.6, 4.4))
    fig_t, ax_t = plt.subplots(figsize=(9.6, 3.8))
    drawn_refs = set()
    for run in nh:
        g = params(run)["capillary"]
        data = moving.series(run, cache)
        t, d = data["t"], data["taylor_deformation"]
        width = FIDELITY_WIDTH.get(run.fidelity, 1.2)
        ax.plot(*_thin(t, d), color=colours[g], lw=width, label=f"caplab G = {g:g} ({run.fidelity})")
        if "inclination" in data:
            ax_t.plot(*_thin(t, data["inclination"] / math.pi), color=colours[g], lw=width,
                      label=f"caplab G = {g:g} ({run.fidelity})")
        curves = reference_curves(refs, g)
        for label, style, ds, tr, dr in curves:
            used[ds.rel] = ds
            if (label, g) not in drawn_refs:
                ax.plot(tr, dr, style, color=colours[g], lw=1.0, label=f"{label}, G = {g:g}")
                drawn_refs.add((label, g))
        if not curves:
            out.notes.append(f"G = {g:g}: no reference curve D(kt) in references/{BENCHMARK}/: drawn without one")
        rp98, spread = _steady_row(refs, f"ramanujan1998_G{g:g}")
        row = ValidationRow(run, g, steady_d(run), rp98, spread)
        p95_file = CURVES[0][0].format(G=f"{g:g}")
        for e in run.entries:
            if e.get("comparison") == "time_series" and f"/{p95_file}#" in str(e.get("reference", "")):
                row.rms_scored = float(e["error"]) if finite(e.get("error")) else None
                row.rms_tolerance = float(e["tolerance"]) if finite(e.get("tolerance")) else None
                row.rms_verdict = str(e.get("verdict") or "")
        p95 = next((c for c in curves if c[2].filename == p95_file), None)
        if p95 is not None:
            rec = moving.rms_on_reference(t, d, p95[3], p95[4], None)
            if rec:
                row.rms_recomputed, row.rms_points = rec
        else:
            out.notes.append(f"G = {g:g}: references/{BENCHMARK}/{p95_file} not found: the RMS to Pozrikidis 1995 "
                             "is not recomputed" + (" (score.json's is shown)" if row.rms_scored is not None else ""))
        if row.rms_scored is not None and row.rms_recomputed is not None and not math.isclose(
                row.rms_scored, row.rms_recomputed, rel_tol=1e-6, abs_tol=1e-9):
            out.notes.append(f"{run.case_id} ({run.fidelity}): score.json has the RMS {row.rms_scored:.6g} to "
                             f"Pozrikidis 1995, the report recomputes {row.rms_recomputed:.6g}")
        out.rows.append(row)
    if refs.get(BENCHMARK, STEADY_FILE) is not None:
        used[f"references/{BENCHMARK}/{STEADY_FILE}"] = refs.get(BENCHMARK, STEADY_FILE)
    out.datasets = list(used.values())
    fids = fidelity_text(nh)
    _against_time(ax, "D_xz [-]")
    out.deformation = Figure(_finish(fig, ax, "validation: NH spheres in unbounded shear, D_xz(kt)"),
                             f"Validation (external data). Taylor deformation D_xz = (L − B)/(L + B) in the shear plane "
                             f"x–z (dimensionless) against k t of every unbounded neo-Hookean sphere run ({fids}; line "
                             "width grows with the fidelity), one colour per G. Dashed: Pozrikidis 1995, dash-dotted: "
                             "Ramanujan & Pozrikidis 1998, both boundary-element results (Stokes flow) at Ca = G, "
                             "digitized by a third party (±0.005 in D; references/capsule3d, provenance below).")
    if not ax_t.get_lines():
        plt.close(fig_t)
        return out
    ax_t.axhline(0.25, color="k", ls=":", lw=1.0, label="small-deformation limit θ → π/4 (verification)")
    _against_time(ax_t, "inclination θ/π [-]")
    out.inclination = Figure(_finish(fig_t, ax_t, "NH spheres in unbounded shear, inclination θ(kt)/π"),
                             f"Inclination θ of the long axis L of the equivalent ellipsoid from +x toward +z, divided by "
                             f"π, against k t ({fids}). No external data: the inclinations of Pozrikidis 1995 and "
                             "Ramanujan & Pozrikidis 1998 were not digitized (provenance.json not_available); the dotted "
                             "line is the analytic small-deformation limit π/4 (verification, valid as G → 0).")
    return out


# ---- 2. verification ---------------------------------------------------------------------------------------

@dataclass
class TheoryRow:
    run: Run
    law: str
    capillary: float
    steady: float | None
    theory: float
    inclination: float | None

    @property
    def deviation(self) -> float | None:
        return (self.steady - self.theory) / self.theory if finite(self.steady) else None


@dataclass
class Study:
    """Runs of one capsule that differ only in the grid (what = "grid") or only in the domain."""

    what: str
    title: str
    runs: list[Run]                 #: coarsest grid (or smallest domain) first
    rows: list[dict] = field(default_factory=list)
    order: Order | None = None
    order_note: str = ""
    figure: Figure | None = None


@dataclass
class TwinRow:
    run: Run
    twin: Run
    steady: float | None
    steady_twin: float | None
    cost: moving.Cost
    fine_fraction: float | None
    rms: float | None

    @property
    def difference(self) -> float | None:
        return ((self.steady - self.steady_twin) / self.steady_twin
                if finite(self.steady) and finite(self.steady_twin) and self.steady_twin else None)


@dataclass
class Verification:
    theory: list[TheoryRow] = field(default_factory=list)
    theory_figure: Figure | None = None
    analytic: list[dict] = field(default_factory=list)   #: provenance "analytic" entries used
    studies: list[Study] = field(default_factory=list)
    twins: list[TwinRow] = field(default_factory=list)


def _skalak_c1(p: dict) -> bool:
    return p["law"] != "skalak" or (finite(p.get("area_dilation")) and math.isclose(p["area_dilation"], 1.0))


def small_deformation(runs: list[Run], refs: ReferenceLibrary, cache: dict, out: Verification) -> list[Dataset]:
    spheres = {law: [r for r in sweep_runs(runs, law, cache) if _skalak_c1(params(r))] for law in SMALL_DEFORMATION}
    if not any(spheres.values()):
        return []
    prov = refs.benchmarks.get(BENCHMARK, {}).get("analytic") or {}
    fig, ax = plt.subplots(figsize=(7.4, 4.2))
    markers = {"neo_hookean": "o", "skalak": "s"}
    colours = {"neo_hookean": "#1f4e79", "skalak": "#b03a2e"}
    g_max = max(params(r)["capillary"] for rs in spheres.values() for r in rs)
    gg = np.linspace(0.0, max(0.2, g_max), 50)
    for law, members in spheres.items():
        if not members:
            continue
        slope = SMALL_DEFORMATION[law]
        entry = prov.get(SMALL_DEFORMATION_ENTRY[law])
        if isinstance(entry, dict):
            out.analytic.append(dict(entry, law=law))
        ax.plot(gg, slope * gg, "--", color=colours[law], lw=1.0,
                label=f"first-order theory D = {'25/4' if law == 'neo_hookean' else '25/6'} G ({LAW_LABELS[law]})")
        for fid in sorted({r.fidelity for r in members}):
            pts = [(params(r)["capillary"], steady_d(r)) for r in members if r.fidelity == fid and steady_d(r) is not None]
            if pts:
                ax.plot(*zip(*pts), markers[law], color=colours[law], ms=6 if fid == "quick" else 8,
                        mfc="none" if fid == "quick" else colours[law], label=f"caplab {LAW_LABELS[law]} ({fid})")
        for r in members:
            p = params(r)
            if p["capillary"] <= SMALL_G + 1e-12:
                out.theory.append(TheoryRow(r, law, p["capillary"], steady_d(r), slope * p["capillary"],
                                            r.metric("inclination_mean")))
    ds = refs.get(BENCHMARK, STEADY_FILE)
    used = []
    if ds is not None:
        pts = []
        for row in ds.rows:
            if row and row[0].startswith("ramanujan1998_"):
                try:
                    pts.append((float(ds.cell(row[0], "G")), float(ds.cell(row[0], "D"))))
                except (TypeError, ValueError):
                    continue
        if pts:
            ax.plot(*zip(*pts), "D", color="#444", ms=6, mfc="none",
                    label="Ramanujan & Pozrikidis 1998, steady (validation)")
            used.append(ds)
    ax.set_xlabel("G = μka/E")
    ax.set_ylabel("steady D_xz [-]")
    ax.set_xlim(0, gg[-1] * 1.03)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=7, loc="upper left")
    all_runs = [r for rs in spheres.values() for r in rs]
    out.theory_figure = Figure(
        _finish(fig, ax, "verification: steady D_xz of the spheres against small-deformation theory"),
        "Verification (analytic limit). Steady Taylor deformation D_xz (summary taylor_deformation_mean, the time "
        f"average over k t ≥ outputs.average_from; dimensionless) against G of the unbounded spheres ({fidelity_text(all_runs)}; "
        "open markers: quick). Dashed lines: first-order small-deformation theory of Barthès-Biesel 1980 in thesis "
        "units, D = 25/4 G (NH, E = 3G_s) and 25/6 G (Skalak C = 1, E = 2G_s), valid as G → 0 only (the thesis: "
        "no longer good at G = 0.05). Open diamonds: steady values of Ramanujan & Pozrikidis 1998 "
        "(references/capsule3d/steady_values.csv, mean of the digitized curve; external data).")
    return used


def _same_but(a: dict, b: dict, keys: tuple) -> bool:
    return all(a.get(k) == b.get(k) for k in ("physics", "domain", "spacing", "refinement", "fidelity", "window")
               if k not in keys)


def _config(run: Run) -> dict:
    """What must agree between two members of a study but the varied parameter; the averaging window
    (outputs.average_from, numerics.end_time) too, as steady means over different windows differ by more
    than a grid step's change (ch5 G = 0.2 at standard: 0.3 % between [4, 8] and [5, 10] of one run)."""
    p = params(run)
    spacing = round(p["spacing"], 9) if finite(p.get("spacing")) else None
    outputs, numerics = run.case.get("outputs") or {}, run.case.get("numerics") or {}
    return {"physics": physics_key(p), "domain": p["domain"], "spacing": spacing, "refinement": p["refinement"],
            "fidelity": run.fidelity, "window": (outputs.get("average_from"), numerics.get("end_time"))}


def _spacing_text(h) -> str:
    if not finite(h):
        return "–"
    n = 1.0 / h
    return f"a/{n:.0f}" if abs(n - round(n)) < 1e-6 else f"{h:.4g} a"


def studies(runs: list[Run], cache: dict, twin_rows: list | None = None) -> list[Study]:
    """The grid and domain studies among ``runs``; a grid study's figure also draws the uniform-grid
    twin of a member (``twin_rows``), as thesis fig. 5.5(b)."""
    ok = [r for r in runs if "taylor_deformation" in moving.series(r, cache) and r.fine_spacing is not None]
    configs = {id(r): _config(r) for r in ok}
    out = []
    for what, varies in (("grid", ("spacing",)), ("domain", ("domain",))):
        groups: list[list[Run]] = []
        for run in ok:
            for group in groups:
                if _same_but(configs[id(group[0])], configs[id(run)], varies):
                    group.append(run)
                    break
            else:
                groups.append([run])
        for members in groups:
            if len({configs[id(r)][varies[0]] for r in members}) < 2:
                continue
            if what == "grid":
                members.sort(key=lambda r: -r.fine_spacing)
            else:
                members.sort(key=lambda r: params(r)["domain"])
            twin = next((t.twin for t in twin_rows or [] if t.run in members), None) if what == "grid" else None
            out.append(_study(what, members, cache, twin))
    return out


def _study(what: str, members: list[Run], cache: dict, twin: Run | None = None) -> Study:
    ref = members[-1]
    study = Study(what, run_label(ref), members)
    ref_d = moving.series(ref, cache)
    for run in members:
        q = params(run)
        d = steady_d(run)
        data = moving.series(run, cache)
        diff = None
        if run is not ref:
            diff = moving.relative_rms(data["t"], data["taylor_deformation"], ref_d["t"], ref_d["taylor_deformation"], 0.0)
        triangles = 8 * 4 ** int(q["subdivisions"]) if isinstance(q.get("subdivisions"), int) else None
        study.rows.append({"run": run, "spacing": _spacing_text(q["spacing"]),
                           "per_diameter": f"{2 * q['radius'] / q['spacing']:.0f}" if finite(q.get("spacing")) else "–",
                           "triangles": triangles, "domain": " × ".join(f"{x:g}" for x in q["domain"]),
                           "steady": d, "rms": diff.rms if diff else None})
    if what == "grid":
        pts = [(r.fine_spacing, steady_d(r)) for r in members if steady_d(r) is not None]
        if len(pts) >= 3:
            pts = sorted(pts)[:3]  # the three finest
            study.order = observed_order(*zip(*pts))
            if study.order is None:
                study.order_note = ("no observed order: the steady D does not converge monotonically over the three "
                                    "finest grids (or the order is outside 0.05–20)")
        else:
            study.order_note = f"observed order needs three resolutions; {len(pts)} finished"
        if study.order is not None:
            for row in study.rows:
                if finite(row["steady"]):
                    row["to_extrapolated"] = (row["steady"] - study.order.extrapolated) / study.order.extrapolated
    study.figure = _study_figure(study, cache, twin)
    return study


def _study_figure(study: Study, cache: dict, twin: Run | None = None) -> Figure | None:
    fig, ax = plt.subplots(figsize=(8.4, 3.6))
    colours = _colours(range(len(study.runs)))
    for i, run in enumerate(study.runs):
        data = moving.series(run, cache)
        q = params(run)
        tag = (f"Δx_f = {_spacing_text(q['spacing'])}" if study.what == "grid"
               else "domain " + " × ".join(f"{x:g}" for x in q["domain"]) + " a")
        ax.plot(*_thin(data["t"], data["taylor_deformation"]), color=colours[i], lw=1.2,
                label=f"{tag} ({run.case_id})")
    twin_data = moving.series(twin, cache) if twin is not None else {}
    if "taylor_deformation" in twin_data:
        ax.plot(*_thin(twin_data["t"], twin_data["taylor_deformation"]), color="k", ls=":", lw=1.4,
                label=f"uniform grid Δx = {_spacing_text(twin.fine_spacing)} ({twin.case_id})")
    _against_time(ax, "D_xz [-]")
    kind = "grid convergence (thesis fig. 5.5b)" if study.what == "grid" else "domain size (thesis fig. 5.5a)"
    return Figure(_finish(fig, ax, f"verification, {kind}: {study.title}"),
                  f"Verification (self-convergence, caplab against caplab; no external data). D_xz (dimensionless) "
                  f"against k t of the runs of {study.title} that differ only in the "
                  f"{'fine grid spacing (and membrane resolution)' if study.what == 'grid' else 'domain size (in a)'}, "
                  f"{fidelity_text(study.runs)}"
                  + (f"; black dotted: the uniform-grid twin {twin.case_id} (the thesis's original IB-LBM)."
                     if "taylor_deformation" in twin_data else "."))


def twins(runs: list[Run], all_runs: list[Run], cache: dict) -> list[TwinRow]:
    out = []
    for run in runs:
        twin = moving.twin_of(run, all_runs)
        if twin is None or twin.status != "ok":
            continue
        a, b = moving.series(run, cache), moving.series(twin, cache)
        rms = None
        if "taylor_deformation" in a and "taylor_deformation" in b:
            diff = moving.relative_rms(a["t"], a["taylor_deformation"], b["t"], b["taylor_deformation"], 0.0)
            rms = diff.rms if diff else None
        out.append(TwinRow(run, twin, steady_d(run), steady_d(twin), moving.cost(run, twin),
                           moving.fine_fraction(run.case), rms))
    return out


# ---- 3. conservation and membrane ------------------------------------------------------------------------

@dataclass
class BoundCheck:
    claim: dict
    metric: str
    column: str

    @property
    def upper(self) -> float | None:
        return float(self.claim["upper"]) if finite(self.claim.get("upper")) else None

    def applies(self, run: Run) -> bool:
        p = params(run)
        law = (self.claim.get("parameters") or {}).get("law")
        return not capsule.claim_matches(self.claim, p) and (law is None or law == p["law"])


@dataclass
class Conservation:
    rows: list[dict] = field(default_factory=list)
    bounds: list[BoundCheck] = field(default_factory=list)
    figure: Figure | None = None


def _largest(run: Run, metric: str, column: str, cache: dict):
    v = run.metric(metric)
    if v is not None:
        return abs(v), "summary.json"
    y = moving.series(run, cache).get(column)
    if y is not None and np.isfinite(y).any():
        return float(np.nanmax(np.abs(y))), "series.h5"
    return None, ""


def conservation(runs: list[Run], refs: ReferenceLibrary, cache: dict, surfaces: dict) -> Conservation:
    out = Conservation()
    ds = refs.get(BENCHMARK, CLAIMS_FILE)
    for cid, metric, column in BOUNDS:
        claim = ds.claims.get(cid) if ds is not None else None
        if isinstance(claim, dict):
            out.bounds.append(BoundCheck(claim, metric, column))
    shown = [r for r in runs if any(c in moving.series(r, cache) for c, _ in CONSERVED)]
    for run in shown:
        row = {"run": run, "label": run_label(run), "values": [], "stretch": None, "area_ratio": None}
        for metric, column in (("volume_change_max", "volume_change"), ("surface_area_change_max", "surface_area_change"),
                               ("max_area_change_max", "max_area_change")):
            value, source = _largest(run, metric, column, cache)
            bound = next((b for b in out.bounds if b.metric == metric and b.applies(run)), None)
            ok = None if bound is None or bound.upper is None or value is None else value <= bound.upper
            row["values"].append({"value": value, "source": source, "bound": bound, "ok": ok})
        snap = surfaces.get(id(run))
        if snap is not None:
            if "max_principal_stretch" in snap.fields:
                row["stretch"] = float(np.nanmax(snap.fields["max_principal_stretch"]))
            if "area_ratio" in snap.fields:
                row["area_ratio"] = (float(np.nanmin(snap.fields["area_ratio"])), float(np.nanmax(snap.fields["area_ratio"])))
            row["snapshot_time"] = snap.time
        out.rows.append(row)
    if shown:
        out.figure = _conservation_figure(shown, cache, out.bounds)
    return out


def _conservation_figure(shown: list[Run], cache: dict, bounds: list[BoundCheck]) -> Figure:
    fig, axes = plt.subplots(len(CONSERVED), 1, figsize=(9.8, 2.5 * len(CONSERVED) + 0.8), sharex=True)
    colours = _colours(range(len(shown)))
    styles = ("-", "--", "-.", ":")
    for i, run in enumerate(shown):
        data = moving.series(run, cache)
        for ax, (column, _) in zip(axes, CONSERVED):
            if column in data:
                ax.plot(*_thin(data["t"], 100 * data[column]), color=colours[i], ls=styles[i % 4], lw=1.0,
                        label=run_label(run) if ax is axes[0] else None)
    drawn = [b for b in bounds if b.upper is not None and any(b.applies(r) for r in shown)]
    for ax, (column, ylabel) in zip(axes, CONSERVED):
        for b in drawn:
            if b.column == column:
                for sign in (1, -1):
                    ax.axhline(sign * 100 * b.upper, color="#d62728", lw=0.9, ls=(0, (6, 3)),
                               label=f"thesis bound ±{100 * b.upper:g} % ({b.claim['id']})" if sign > 0 else None)
        ax.set_ylabel(ylabel, fontsize=8)
        if ax.get_legend_handles_labels()[0]:
            _legend_outside(ax, len(shown))
    axes[-1].set_xlabel("k t")
    applies = "; ".join(f"{b.claim['id']}: ±{100 * b.upper:g} % on {b.metric.replace('_max', '')}, for "
                        f"{b.claim.get('applies_to', 'the runs it is about')}" for b in drawn)
    return Figure(_finish(fig, axes, "conservation: enclosed volume and membrane area"),
                  f"Enclosed volume V/V₀ − 1, membrane area A/A₀ − 1 and the largest local area change over the "
                  f"triangles max|Aₑ/Aₑ₀ − 1|, in %, against k t, of every chapter 5 run ({fidelity_text(shown)}). "
                  "No reference curve (the exact values are 0); "
                  + (f"red dashed: the thesis bounds ({applies}), stated at thesis resolution — quick runs leak more."
                     if applies else "no thesis bound applies to these runs (claims.json)."))


# ---- 4. shape ----------------------------------------------------------------------------------------------

@dataclass
class Section:
    run: Run
    time: float
    centroid: np.ndarray
    segments: np.ndarray   #: [K][2][3]

    @property
    def extent(self) -> tuple[float, float]:
        """Largest and smallest distance of the cut from the centroid, in the plane."""
        r = np.hypot(self.segments[..., 0] - self.centroid[0], self.segments[..., 2] - self.centroid[2])
        return float(r.max()), float(r.min())


def cross_section(snap: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """(volume centroid, segments) of the cut y = y_centroid of one capsule mesh."""
    c = volume_centroid(snap.points, snap.triangles)
    return c, plane_section(snap.points, snap.triangles, float(c[1]), axis=1)


def _sections_figure(sections: list[Section]) -> Figure:
    shown = sections[:MAX_SECTION_PANELS]
    cols = min(4, len(shown))
    rows = math.ceil(len(shown) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(2.6 * cols + 0.4, 2.55 * rows + 0.5), squeeze=False)
    lim = max(1.05 * max(s.extent[0] for s in shown), 1.1)
    for ax in axes.ravel():
        ax.set_visible(False)
    for ax, s in zip(axes.ravel(), shown):
        ax.set_visible(True)
        p = params(s.run)
        seg = s.segments[..., [0, 2]] - s.centroid[[0, 2]]
        phi = np.linspace(0, 2 * math.pi, 200)
        ax.plot(p["radius"] * np.cos(phi), p["radius"] * np.sin(phi), color="#999", lw=0.7, ls=":")
        ax.add_collection(LineCollection(seg, colors="#1f4e79", linewidths=1.4))
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=6)
        ax.set_xlabel("x − x_c [a]", fontsize=6.5)
        ax.set_ylabel("z − z_c [a]", fontsize=6.5)
        ax.set_title(f"{run_label(s.run, p)}\nk t = {s.time:.3g}", fontsize=6.5)
        ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle("cross-sections y = y_c of the last snapshot's capsule mesh (shear plane x–z)", fontsize=8.5)
    fig.tight_layout()
    note = f" (the first {len(shown)} of {len(sections)})" if len(sections) > len(shown) else ""
    return Figure(figures.png_data_uri(fig),
                  f"Cross-section of the capsule surface mesh of the last snapshot in snapshots.h5 with the plane "
                  f"y = y_c through the volume centroid, i.e. the shear plane x–z (compare thesis figs. 5.8, 5.14, "
                  f"5.18), in units of a about the centroid, per run{note} ({fidelity_text([s.run for s in shown])}); k t of the "
                  "snapshot in each title. Dotted grey: the circle of radius a (the equivalent radius; the rest "
                  "shape of the spheres). No reference curve: the thesis figures are not available as data.")


@dataclass
class Histories:
    title: str
    runs: list[Run]
    figure: Figure | None = None


def _histories(title: str, members: list[Run], cache: dict, figs: str) -> Histories:
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 3.7))
    colours = _colours(range(len(members)))
    for i, run in enumerate(members):
        data = moving.series(run, cache)
        t = data["t"]
        tag = f"G = {params(run)['capillary']:g} ({run.fidelity})"
        if "taylor_deformation" in data:
            axes[0].plot(*_thin(t, data["taylor_deformation"]), color=colours[i], lw=1.1, label=tag)
        if "inclination" in data:
            axes[1].plot(*_thin(t, data["inclination"] / math.pi), color=colours[i], lw=1.1, label=tag)
        for name, style in (("length", "-"), ("width", "--"), ("thickness", ":")):
            if name in data:
                axes[2].plot(*_thin(t, data[name]), color=colours[i], ls=style, lw=1.1, label=f"{name}, {tag}")
    for ax, ylabel in zip(axes, ("D_xz [-]", "inclination θ/π [-]", "semi-axes L, W, B [a]")):
        ax.set_xlabel("k t")
        ax.set_ylabel(ylabel)
    axes[0].legend(fontsize=7)
    axes[2].legend(fontsize=6, ncol=1 if len(members) < 3 else 2)
    return Histories(title, members, Figure(
        _finish(fig, axes, f"{title}: D_xz, θ/π and the semi-axes against k t"),
        f"{title} ({fidelity_text(members)}): Taylor deformation D_xz (dimensionless), inclination θ/π of the long "
        "axis from +x toward +z, and the semi-axes of the equivalent ellipsoid in a — L the longer and B the shorter "
        "one in the shear plane (series length, thickness), W along the vorticity axis y (series width) — against "
        f"k t (compare thesis {figs}). No reference curve: caplab has no external data for these shapes "
        "(provenance.json note); they are judged on the thesis statements above."))


#: The thesis figures of chapter 5 that show the histories of each rest shape (shape_histories).
CH5_HISTORY_FIGURES = {"oblate_spheroid": "figs. 5.15 (10:9) and 5.16 (2:1)",
                       "biconcave_discoid": "figs. 5.17 (θ) and 5.19 (length and width)"}


def group_title(shape: str, ratio, law: str) -> str:
    """"ZT oblate spheroids, axis ratio 1.5:1", "SK biconcave discoids", "NH spheres"."""
    if shape == "oblate_spheroid":
        return f"{LAW_LABELS.get(law, law)} oblate spheroids" + (f", axis ratio {ratio:.3g}:1" if finite(ratio) else "")
    return f"{LAW_LABELS.get(law, law)} {SHAPE_LABELS.get(shape, shape or '?')}s"


def shape_histories(runs: list[Run], cache: dict, figures_of=None) -> list[Histories]:
    """D, θ/π and the semi-axes against k t, one figure per rest shape, axis ratio and law.
    ``figures_of(shape, ratio, law)`` names the thesis figures to compare with, or None to leave
    the group out (default: chapter 5's oblate spheroids and biconcave discoids)."""
    figures_of = figures_of or (lambda shape, ratio, law: CH5_HISTORY_FIGURES.get(shape))
    groups: dict[tuple, list[Run]] = {}
    for run in runs:
        p = params(run)
        if figures_of(p["shape"], p.get("aspect_ratio"), p["law"]) and moving.series(run, cache):
            groups.setdefault((p["shape"], p.get("aspect_ratio"), p["law"]), []).append(run)
    out = []
    for (shape, ratio, law), members in sorted(groups.items(), key=lambda kv: str(kv[0])):
        members.sort(key=lambda r: (params(r)["capillary"] or 0, r.fidelity))
        out.append(_histories(group_title(shape, ratio, law), members, cache, figures_of(shape, ratio, law)))
    return out


# ---- 5. cost -------------------------------------------------------------------------------------------------

def cost_rows(runs: list[Run]) -> list[dict]:
    rows = []
    for run in runs:
        share = run.stage_share
        lattice = run.manifest.get("lattice") if isinstance(run.manifest.get("lattice"), dict) else {}
        coupled = [share[k] for k in ("ib", "membrane") if k in share]
        rows.append({"run": run, "label": run_label(run), "wall": run.perf("wall_time_s"), "mlups": run.perf("mlups"),
                     "steps": run.perf("steps"), "threads": run.manifest.get("threads") or run.environment.get("threads"),
                     "node_updates": lattice.get("node_updates"), "share": share,
                     "ib_membrane": sum(coupled) if coupled else None})
    return rows


# ---- the section -----------------------------------------------------------------------------------------------

@dataclass
class Capsules3D:
    runs: list[Run] = field(default_factory=list)          #: every 3D capsule run of the chapter with output
    not_shown: list[Run] = field(default_factory=list)     #: runs that did not finish (listed, not plotted)
    validation: Validation = field(default_factory=Validation)
    verification: Verification = field(default_factory=Verification)
    conservation: Conservation = field(default_factory=Conservation)
    sections: Figure | None = None
    section_rows: list[dict] = field(default_factory=list)
    histories: list[Histories] = field(default_factory=list)
    cost: list[dict] = field(default_factory=list)
    provenance: list[Dataset] = field(default_factory=list)  #: the reference datasets of the section
    discrepancies: dict = field(default_factory=dict)        #: part -> [(key, entry)] of provenance.json
    conventions: dict = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)

    @property
    def present(self) -> bool:
        return bool(self.runs or self.not_shown)

    @property
    def datasets(self) -> list[Dataset]:
        return self.provenance

    @property
    def reference_data(self) -> list[Dataset]:
        """The datasets of the section other than the thesis statements (claims.json)."""
        return [ds for ds in self.provenance if ds.filename != CLAIMS_FILE]


def discrepancy_notes(provenance: dict, parts: dict) -> dict:
    """part -> [(key, entry)] of the provenance.json ``discrepancies`` that ``parts`` names per part."""
    notes = provenance.get("discrepancies") if isinstance(provenance.get("discrepancies"), dict) else {}
    return {part: [(k, notes[k]) for k in keys if isinstance(notes.get(k), dict)] for part, keys in parts.items()}


def _guarded(section: Capsules3D, what: str, fn, default=None):
    try:
        return fn()
    except Exception as err:  # a broken file must not stop the report
        section.problems.append(f"3D capsules: {what} failed: {err}")
        return default


def build(runs: list[Run], refs: ReferenceLibrary, chapter: str) -> Capsules3D:
    section = Capsules3D()
    if chapter != CHAPTER:
        return section
    mine = [r for r in runs if is_capsule3d(r) and r.status != "missing"]
    cache: dict = {}
    section.runs = [r for r in mine if r.status == "ok" and moving.series(r, cache)]
    section.not_shown = [r for r in mine if r not in section.runs]
    if not section.present:
        return section
    prov = refs.benchmarks.get(BENCHMARK, {})
    section.conventions = prov.get("conventions") if isinstance(prov.get("conventions"), dict) else {}
    section.discrepancies = discrepancy_notes(prov, DISCREPANCIES)
    if not prov:
        section.problems.append(f"3D capsules: references/{BENCHMARK}/provenance.json not found: no reference data shown")
    ok = section.runs

    section.validation = _guarded(section, "validation", lambda: validation(ok, refs, cache), Validation())
    used = {ds.rel: ds for ds in section.validation.datasets}
    ver = section.verification
    for ds in _guarded(section, "small-deformation comparison", lambda: small_deformation(ok, refs, cache, ver), []):
        used[ds.rel] = ds
    ver.twins = _guarded(section, "uniform-grid twins", lambda: twins(ok, runs, cache), [])
    ver.studies = _guarded(section, "grid and domain studies", lambda: studies(ok, cache, ver.twins), [])

    surfaces: dict[int, Snapshot] = {}
    sections: list[Section] = []
    for run in ok:
        body = capsule.capsule_body(run) or {}
        snap, problem = last_surface(run, body.get("name"))
        if problem:
            section.problems.append(f"3D capsules: {run.case_id} ({run.fidelity}): {problem}")
        if snap is None:
            continue
        surfaces[id(run)] = snap
        centroid, segments = _guarded(section, f"cross-section of {run.case_id}", lambda: cross_section(snap), (None, None))
        if segments is not None and len(segments):
            s = Section(run, snap.time, centroid, segments)
            sections.append(s)
            longest, shortest = s.extent
            section.section_rows.append({"run": run, "label": run_label(run), "time": snap.time, "segments": len(segments),
                                         "longest": longest, "shortest": shortest})
    if sections:
        section.sections = _guarded(section, "cross-section figure", lambda: _sections_figure(sections))
    section.conservation = _guarded(section, "conservation", lambda: conservation(ok, refs, cache, surfaces),
                                    Conservation())
    for b in section.conservation.bounds:
        ds = refs.get(BENCHMARK, CLAIMS_FILE)
        if ds is not None:
            used[ds.rel] = ds
    section.histories = _guarded(section, "shape histories", lambda: shape_histories(ok, cache), [])
    section.cost = cost_rows(ok)
    section.provenance = sorted(used.values(), key=lambda d: d.rel)
    return section
