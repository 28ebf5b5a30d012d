"""Chapter 6 section of the report: tank-treading, swinging and tumbling of 3D capsules in simple
shear flow (thesis chapter 6; Sui et al. 2008, Phys. Rev. E 77, 016310).

A chapter 6 run is a 3D capsule run (capsule3d.is_capsule3d) of a case "ch6/...": spheres (ZT, and
SK with C = 100), oblate spheroids (shape.aspect_ratio 10/9, 1.5, 2; ZT, NH, SK) swept over
G = membrane.capillary, and biconcave discoids between walls (SK, C from G). Its summary.json gives
the regime ``mode`` (steady_tank_treading | oscillating_tank_treading, the thesis's "swinging" |
tumbling), ``inclination_amplitude`` (rad), ``taylor_deformation_amplitude`` and ``_mean``,
``tank_treading_frequency_per_k`` (when whole membrane revolutions happened) and the largest volume
and area changes; its series.h5 the chapter 5 columns (capsule3d.py) against k t.

What the section shows (the numbers the thesis states are read from
references/capsule3d_modes/claims.json where it has them, else quoted from the thesis text, and
said so):

1. mode maps: one marker per finished run, shaped and coloured by its mode, against G (log) and the
   axis ratio for the oblate spheroids (one panel per membrane law), against G alone for the
   biconcave discoids and the spheres; the thesis's transition brackets (bracket claims) drawn;
   the sweep's own bracket (between the largest G that tumbles and the smallest G above it that
   tank-treads, per law, axis ratio and fidelity) stated in words, with non-monotonic sweeps and
   sweeps without a tumbling (or a tank-treading) run said to be so;
2. amplitudes against G (thesis fig. 6.7): inclination amplitude in degrees and D amplitude, per
   sweep; the biconcave amplitude against the thesis's 2.9-3.5 degree band; f/k against G with the
   thesis's 0.20-0.24 band and Tran-Son-Tay et al. 1984's value (references/capsule3d_modes/
   tran_son_tay_1984.csv, or a note that it is missing);
3. time histories (capsule3d.shape_histories): D, θ/π and the semi-axes of the oblate groups
   (figs. 6.6, 6.8-6.10), the biconcave discoids (figs. 6.13, 6.16) and the spheres (figs. 6.2,
   6.3), and the spheres' largest area change against G (the thesis's 0.4 % to 23.5 %, ≤ 1.8 %);
4. one table per family (case, fidelity, mode, amplitudes, f/k, area and volume change, wall time),
   unfinished runs listed (never plotted), catalogue cases without a run named; and the verdicts of
   the chapter's thesis statements, checked by capsule.py (caplab claims) as for every
   chapter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import capsule, capsule3d, moving  # noqa: E402
from .capsule3d import LAW_LABELS, Figure, fidelity_text, params  # noqa: E402
from .references import Dataset, ReferenceLibrary  # noqa: E402
from .runs import Run, finite  # noqa: E402

CHAPTER = "ch6"
BENCHMARK = "capsule3d_modes"
CLAIMS_FILE = "claims.json"
TRAN_SON_TAY_FILE = "tran_son_tay_1984.csv"
TUMBLING = "tumbling"
#: Marker, colour and legend text per mode (caplab's names; "swinging" is the thesis's word).
MODE_STYLE = {"steady_tank_treading": ("o", "#2ca02c", "steady tank-treading"),
              "oscillating_tank_treading": ("^", "#1f77b4", "swinging (oscillating tank-treading)"),
              TUMBLING: ("X", "#d62728", "tumbling")}
MODE_WORDS = {"steady_tank_treading": "steady tank-treading", "oscillating_tank_treading": "swinging",
              TUMBLING: "tumbling"}
FIDELITY_OFFSET = {"quick": -1.0, "standard": 0.0, "thesis": 1.0}
LAW_ORDER = ("zero_thickness", "neo_hookean", "skalak")
SHAPE_ORDER = ("sphere", "oblate_spheroid", "biconcave_discoid")  # the order of thesis 6.1-6.3
#: provenance.json "discrepancies" shown beside the part they bear on.
DISCREPANCIES = {"maps": ("mode_after_initial_stage", "fig6_10_law"), "amplitudes": ("amplitude_convention",)}


@dataclass(frozen=True)
class Quoted:
    """A number (or range) the thesis states, with where it comes from when claims.json lacks it."""

    claim_id: str
    lower: float
    upper: float
    capillary: tuple[float, float] | None
    sentence: str


#: The thesis's numbers used by the figures, as printed (thesis 6.1 and 6.3.1); the claims of the
#: same id in references/capsule3d_modes/claims.json take precedence when they give the numbers.
QUOTED = {
    "amplitude": Quoted("ch6.biconcave.swinging_amplitude", 2.9, 3.5, (0.47, 2.8),
                        "With the shear rate ranges from 0.47 to 2.8, the capsule inclination oscillation amplitude "
                        "is in the range of 2.9 ~ 3.5 degrees."),
    "frequency": Quoted("ch6.biconcave.tank_treading_frequency", 0.20, 0.24, (0.47, 2.8),
                        "the normalized tank treading frequency is higher at lower dimensionless shear rate, and "
                        "ranges from 0.20 to 0.24 with the dimensionless shear rate ranging from 0.47 to 2.8."),
    "sphere_sk_area": Quoted("ch6.sphere_sk.area_change", 0.0, 0.018, (0.3, 0.3),
                             "At $G = 0.3$, the membrane area change is within 1.8%."),
}
#: Thesis 6.1: "the maximum membrane area change ranges from 0.4% for G = 0.0125 to 23.5% for G = 0.2".
SPHERE_ZT_AREA_CLAIM = "ch6.sphere_zt.area_change"
SPHERE_ZT_AREA_QUOTED = ((0.0125, 0.004), (0.2, 0.235))


# ---- families and sweeps ----------------------------------------------------------------------------

def is_mode_run(run: Run) -> bool:
    return run.chapter == CHAPTER and capsule3d.is_capsule3d(run)


def family_key(p: dict) -> tuple:
    """(shape, law, walls, C): the biconcave cells take C from G, so C does not split their family."""
    c = p.get("area_dilation") if p["shape"] != "biconcave_discoid" and finite(p.get("area_dilation")) else None
    return (p["shape"], p["law"], bool(p.get("walls")), c)


def family_sort(key: tuple):
    shape, law, walls, c = key
    return (SHAPE_ORDER.index(shape) if shape in SHAPE_ORDER else 9, LAW_ORDER.index(law) if law in LAW_ORDER else 9,
            walls, c or 0)


def family_title(key: tuple) -> str:
    shape, law, walls, c = key
    text = capsule3d.group_title(shape, None, law) + (" between walls" if walls else "")
    if c is not None:
        text += f", C = {c:g}"
    return text + (" (C from G)" if shape == "biconcave_discoid" and law == "skalak" else "")


def same_ratio(a, b) -> bool:
    """Axis ratios as a claim may print them (10/9 as 1.111) against the case's."""
    return finite(a) and finite(b) and abs(a - b) < 1e-3


def ratio_text(r) -> str:
    """10/9 -> "10:9", 1.5 -> "3:2", 2 -> "2:1"; otherwise "1.23:1"."""
    if not finite(r):
        return ""
    f = Fraction(r).limit_denominator(12)
    return f"{f.numerator}:{f.denominator}" if abs(float(f) - r) < 1e-6 else f"{r:.3g}:1"


@dataclass
class Bracket:
    """Where one sweep changes from tumbling (small G) to tank-treading (large G)."""

    lower: float | None = None      #: the largest G that tumbles
    upper: float | None = None      #: the smallest G above ``lower`` that tank-treads (steady or swinging)
    monotonic: bool = True          #: False when some G tank-treads below a G that tumbles
    reversals: list[tuple[float, float]] = field(default_factory=list)  #: (tank-treading G, tumbling G above it)
    steady: list[float] = field(default_factory=list)   #: G of steady tank-treading runs (counted with swinging)
    runs: int = 0                   #: finished runs with a mode
    text: str = ""

    @property
    def closed(self) -> bool:
        return self.lower is not None and self.upper is not None

    def against(self, lo: float, hi: float) -> tuple[bool | None, str]:
        """(agrees, words) for the thesis's bracket lo < G < hi: the region the sweep leaves for the
        transition, (lower, upper), must meet (lo, hi). None when the sweep cannot say."""
        if not self.runs:
            return None, "no finished run with a mode"
        if not self.monotonic:
            return None, "not comparable: the sweep is not monotonic in G"
        below = self.lower if self.lower is not None else 0.0
        above = self.upper if self.upper is not None else math.inf
        agrees = below < hi and above > lo
        side = ("" if self.closed else " (one-sided: no run tumbles)" if self.lower is None
                else " (one-sided: no run tank-treads)")
        return agrees, (f"{'agrees with' if agrees else 'disagrees with'} the thesis's {lo:g} < G < {hi:g}" + side)


def _gs(values) -> str:
    return ", ".join(f"{g:g}" for g in sorted(set(values)))


def measured_bracket(points: list[tuple[float, str | None]]) -> Bracket:
    """The bracket of a sweep from its (G, mode) pairs (finished runs only; a None mode is left
    out): between the largest G that tumbles and the smallest G above it that tank-treads."""
    pts = [(g, m) for g, m in points if finite(g) and m in MODE_STYLE]
    b = Bracket(runs=len(pts), steady=sorted({g for g, m in pts if m == "steady_tank_treading"}))
    tumbling = sorted(g for g, m in pts if m == TUMBLING)
    treading = sorted(g for g, m in pts if m in capsule.TANK_TREADING)
    if not pts:
        b.text = "no finished run with a mode: no bracket"
        return b
    span = f"G = {min(g for g, _ in pts):g} … {max(g for g, _ in pts):g}"
    all_steady = bool(treading) and len(b.steady) == len(set(treading))
    if not tumbling:
        b.upper = treading[0]
        b.text = (f"no run tumbles ({len(pts)} run(s), {span}, every one "
                  f"{'steady tank-treading' if all_steady else 'tank-treads'}): the transition, if any, lies below "
                  f"G = {b.upper:g}")
    elif not treading:
        b.lower = tumbling[-1]
        b.text = f"every run tumbles ({len(pts)} run(s), {span}): the transition lies above G = {b.lower:g}"
    else:
        b.lower = tumbling[-1]
        above = [g for g in treading if g > b.lower]
        b.upper = above[0] if above else None
        b.reversals = [(s, t) for s in treading for t in tumbling if t >= s]
        b.monotonic = not b.reversals
        if b.monotonic:
            b.text = f"transition between G = {b.lower:g} (tumbles) and G = {b.upper:g} (tank-treads)"
        else:
            b.text = (f"not monotonic in G: tank-treads at G = {_gs(s for s, _ in b.reversals)} but tumbles at "
                      f"G = {_gs(t for _, t in b.reversals)} (at or above it); the largest G that tumbles is "
                      f"{b.lower:g}" + (f", the smallest tank-treading G above it {b.upper:g}" if b.upper is not None
                                        else ", and no G above it tank-treads"))
    if b.steady and not all_steady:
        b.text += f"; steady tank-treading (counted with swinging) at G = {_gs(b.steady)}"
    return b


@dataclass
class ThesisBracket:
    claim: dict
    lower: float
    upper: float
    agrees: bool | None = None
    words: str = ""


@dataclass
class Sweep:
    """The runs of one family, axis ratio and fidelity, ordered by G."""

    family: tuple
    ratio: float | None
    fidelity: str
    runs: list[Run] = field(default_factory=list)        #: finished (status ok)
    unfinished: list[Run] = field(default_factory=list)  #: diverged, failed, incomplete: listed, not plotted
    no_mode: list[Run] = field(default_factory=list)     #: finished, but summary.json has no mode
    bracket: Bracket = field(default_factory=Bracket)
    thesis: list[ThesisBracket] = field(default_factory=list)

    @property
    def title(self) -> str:
        shape = self.family[0]
        base = family_title(self.family)
        if shape == "oblate_spheroid" and finite(self.ratio):
            base = base.replace("oblate spheroids", f"oblate spheroids {ratio_text(self.ratio)}", 1)
        return f"{base} ({self.fidelity})"

    def points(self) -> list[tuple[float, str | None, Run]]:
        return [(params(r)["capillary"], capsule.mode_of(r), r) for r in self.runs]

    @property
    def listing(self) -> list[tuple[float, str, Run]]:
        """(G, the mode in the thesis's words, run) of the finished runs."""
        return [(g, MODE_WORDS[m], r) for g, m, r in self.points()]


def _g(run: Run) -> float:
    g = params(run)["capillary"]
    return g if finite(g) else math.nan


def sweeps_of(runs: list[Run]) -> list[Sweep]:
    """Every (family, axis ratio, fidelity) of ``runs`` (missing runs left out), with its bracket."""
    groups: dict[tuple, Sweep] = {}
    for run in runs:
        if run.status == "missing":
            continue
        p = params(run)
        ratio = p.get("aspect_ratio") if p["shape"] == "oblate_spheroid" else None
        key = (family_key(p), ratio, run.fidelity)
        sweep = groups.setdefault(key, Sweep(key[0], ratio, run.fidelity))
        if run.status != "ok":
            sweep.unfinished.append(run)
        elif capsule.mode_of(run) not in MODE_STYLE:
            sweep.no_mode.append(run)
        else:
            sweep.runs.append(run)
    out = sorted(groups.values(), key=lambda s: (family_sort(s.family), s.ratio or 0, s.fidelity))
    for s in out:
        for members in (s.runs, s.unfinished, s.no_mode):
            members.sort(key=_g)
        s.bracket = measured_bracket([(g, m) for g, m, _ in s.points()])
    return out


def _ratio_restriction(claim: dict, runs: list[Run]) -> set | None:
    """The axis ratios a claim is about when its parameters do not say: its ``conditions`` or the
    cases it lists (chapter 5's claims put the oblate ratio there)."""
    cond = claim.get("conditions") if isinstance(claim.get("conditions"), dict) else {}
    wanted = cond.get("aspect_ratio")
    if finite(wanted):
        return {float(wanted)}
    if isinstance(wanted, list) and all(finite(w) for w in wanted):
        return {float(w) for w in wanted}
    cases = claim.get("cases")
    if isinstance(cases, list) and cases:
        ratios = {params(r)["aspect_ratio"] for r in runs
                  if r.case_id in cases and finite(params(r).get("aspect_ratio"))}
        return ratios or None
    return None


def claim_is_about(claim: dict, sweep: Sweep, all_runs: list[Run]) -> bool:
    """Whether a bracket claim (varying G) is about the sweep: its parameters other than G and the
    match-only ones hold for the sweep's runs, and the axis ratio (parameters, conditions or cases)."""
    members = sweep.runs + sweep.no_mode + sweep.unfinished
    if not members:
        return False
    fixed = {k: v for k, v in (claim.get("parameters") or {}).items()
             if k not in (claim.get("varying"), "aspect_ratio") and k not in capsule.MATCH_ONLY_KEYS}
    if capsule.claim_matches(dict(claim, parameters=fixed), params(members[0])):
        return False
    wanted = (claim.get("parameters") or {}).get("aspect_ratio")
    if wanted is not None:
        ratios = set(wanted) if isinstance(wanted, list) else {wanted}
    else:
        ratios = _ratio_restriction(claim, all_runs)
    return ratios is None or any(same_ratio(sweep.ratio, r) for r in ratios)


def attach_thesis_brackets(sweeps: list[Sweep], claims: list[dict], all_runs: list[Run]) -> None:
    for claim in claims:
        lo_hi = claim.get("between") or []
        if claim.get("kind") != "bracket" or claim.get("varying") != "capillary" or len(lo_hi) < 2 \
                or not all(finite(x) for x in lo_hi[:2]):
            continue
        lo, hi = sorted(float(x) for x in lo_hi[:2])
        for s in sweeps:
            if claim_is_about(claim, s, all_runs):
                agrees, words = s.bracket.against(lo, hi)
                s.thesis.append(ThesisBracket(claim, lo, hi, agrees, words))


# ---- the thesis's numbers ----------------------------------------------------------------------------

@dataclass
class Band:
    lower: float
    upper: float
    capillary: tuple[float, float] | None
    source: str          #: "claims.json#<id>" or "thesis text (not in claims.json)"
    sentence: str


def _range_of(claim: dict) -> tuple[float, float] | None:
    """(lower, upper) of a bound claim, or of a value claim whose value is a pair or a range."""
    lo, hi = claim.get("lower"), claim.get("upper")
    if claim.get("kind") == "bound" and (finite(lo) or finite(hi)):
        return (float(lo) if finite(lo) else 0.0, float(hi) if finite(hi) else math.inf)
    v = claim.get("value")
    if isinstance(v, dict):
        v = [v.get("from", v.get("lower")), v.get("to", v.get("upper"))]
    if isinstance(v, list) and len(v) == 2 and all(finite(x) for x in v):
        return tuple(sorted(float(x) for x in v))
    return None


def _g_range(claim: dict, default):
    g = (claim.get("parameters") or {}).get("capillary")
    if isinstance(g, dict) and finite(g.get("from")) and finite(g.get("to")):
        return (float(g["from"]), float(g["to"]))
    if isinstance(g, list) and g and all(finite(x) for x in g):
        return (float(min(g)), float(max(g)))
    if finite(g):
        return (float(g), float(g))
    return default


def band(claims: dict[str, dict], what: str, degrees: bool = False) -> Band:
    """The thesis's range ``what`` (QUOTED): from claims.json when its claim gives numbers (a unit of
    rad converted to degrees where ``degrees``), else as quoted from the thesis text."""
    q = QUOTED[what]
    claim = claims.get(q.claim_id)
    rng = _range_of(claim) if isinstance(claim, dict) else None
    if rng is not None:
        unit = str(claim.get("unit") or "rad").lower()
        if degrees and unit not in ("deg", "degree", "degrees", "°"):  # caplab's angles are in rad
            rng = (math.degrees(rng[0]), math.degrees(rng[1]))
        return Band(rng[0], rng[1], _g_range(claim, q.capillary), f"claims.json#{q.claim_id}",
                    str(claim.get("sentence") or q.sentence))
    why = "not in claims.json" if claim is None else "claims.json gives no range"
    return Band(q.lower, q.upper, q.capillary, f"thesis text ({q.claim_id} {why})", q.sentence)


def sphere_area_points(claims: dict[str, dict]) -> tuple[list[tuple[float, float]], str]:
    """The thesis's largest ZT sphere area changes per G: the claim's {G: value} (or value list
    against its G list), else as quoted from the thesis text."""
    claim = claims.get(SPHERE_ZT_AREA_CLAIM)
    value = claim.get("value") if isinstance(claim, dict) else None
    pts = []
    if isinstance(value, dict):
        for g, v in value.items():
            try:
                pts.append((float(g), float(v)))
            except (TypeError, ValueError):
                continue
    elif isinstance(value, list):
        gs = (claim.get("parameters") or {}).get("capillary")
        if isinstance(gs, list) and len(gs) == len(value) and all(finite(x) for x in gs + value):
            pts = list(zip(map(float, gs), map(float, value)))
    if pts:
        return sorted(pts), f"claims.json#{SPHERE_ZT_AREA_CLAIM}"
    why = "not in claims.json" if claim is None else "claims.json gives no values per G"
    return list(SPHERE_ZT_AREA_QUOTED), f"thesis text 6.1 ({SPHERE_ZT_AREA_CLAIM} {why})"


@dataclass
class ExternalValue:
    """f/k of one group of cells of Tran-Son-Tay et al. 1984: the mean over its rows (shear rates)
    and the range of the rows."""

    label: str
    value: float
    lower: float
    upper: float
    rows: int
    shear_rates: tuple[float, float] | None = None

    @property
    def text(self) -> str:
        rates = (f" over γ̇ = {self.shear_rates[0]:g}–{self.shear_rates[1]:g} 1/s" if self.shear_rates else "")
        return f"{self.label}: f/k = {self.value:.3f} ({self.lower:.3f}–{self.upper:.3f}, {self.rows} rows{rates})"


#: Columns that hold f/k directly, when the file does not give f and the shear rate.
FREQUENCY_COLUMNS = ("f_over_k", "f/k", "frequency_per_k", "tank_treading_frequency_per_k")


def _cell(cells: dict, column: str | None):
    try:
        v = float(cells.get(column, "")) if column else math.nan
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def tran_son_tay(refs: ReferenceLibrary) -> tuple[list[ExternalValue], Dataset | None, str]:
    """Tran-Son-Tay et al. 1984's f/k per group of cells (references/capsule3d_modes/
    tran_son_tay_1984.csv: f_rad_per_s / gamma_dot_per_s per row, or a column of f/k), or a note."""
    ds = refs.get(BENCHMARK, TRAN_SON_TAY_FILE)
    where = f"references/{BENCHMARK}/{TRAN_SON_TAY_FILE}"
    if ds is None:
        return [], None, (f"{where} is missing: Tran-Son-Tay et al. 1984's f/k (the thesis quotes 0.22 for young red "
                          "cells) is not drawn")
    direct = next((c for c in FREQUENCY_COLUMNS if c in ds.columns), None)
    if not direct and not {"f_rad_per_s", "gamma_dot_per_s"} <= set(ds.columns):
        return [], ds, (f"{where} has neither f_rad_per_s and gamma_dot_per_s nor a column of f/k "
                        f"({', '.join(FREQUENCY_COLUMNS)}): nothing drawn")
    groups: dict[str, list[tuple[float, float | None]]] = {}
    for row in ds.rows:
        cells = dict(zip(ds.columns, row))
        rate = _cell(cells, "gamma_dot_per_s")
        fk = _cell(cells, direct) if direct else (
            _cell(cells, "f_rad_per_s") / rate if rate and _cell(cells, "f_rad_per_s") is not None else None)
        if fk is not None:
            groups.setdefault(str(cells.get("cells") or "all cells"), []).append((fk, rate))
    out = []
    for name, pts in groups.items():
        values = [v for v, _ in pts]
        rates = [r for _, r in pts if r]
        out.append(ExternalValue(f"{name} cells" if name != "all cells" else name, float(np.mean(values)),
                                 min(values), max(values), len(values), (min(rates), max(rates)) if rates else None))
    return out, ds, "" if out else f"{where} has no row with a number for f/k: nothing drawn"


# ---- figures ---------------------------------------------------------------------------------------------

def _offset(fidelity: str) -> float:
    return FIDELITY_OFFSET.get(fidelity, 0.5)


def _legend_modes(ax, extra: list | None = None) -> None:
    handles = [plt.Line2D([], [], ls="", marker=m, color=c, ms=8, label=text) for m, c, text in MODE_STYLE.values()]
    ax.legend(handles=handles + (extra or []), fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0),
              framealpha=0.85)


def _mode_markers(ax, sweep: Sweep, y: float) -> None:
    for g, mode, _ in sweep.points():
        marker, colour, _ = MODE_STYLE[mode]
        ax.plot(g, y, marker, color=colour, ms=9 if sweep.fidelity != "quick" else 7,
                mfc=colour if sweep.fidelity != "quick" else "white", mew=1.6, zorder=3)


def _bracket_bars(ax, sweep: Sweep, y: float, half: float) -> None:
    for tb in sweep.thesis:
        ax.fill_between([tb.lower, tb.upper], y - half, y + half, color="#f0a030", alpha=0.35, lw=0, zorder=1)
    b = sweep.bracket
    if b.closed and b.monotonic:
        ax.plot([b.lower, b.upper], [y, y], color="k", lw=1.0, ls=(0, (4, 2)), zorder=2)


def _log_g_axis(ax, gs) -> None:
    gs = [g for g in gs if finite(g) and g > 0]
    if gs:
        ax.set_xlim(min(gs) / 1.8, max(gs) * 1.8)
    ax.set_xscale("log")
    ax.set_xlabel("G = μka/E (log)")


def _map_gs(sweeps: list[Sweep]) -> list[float]:
    """The G a map must show: its runs' and the ends of the thesis brackets drawn."""
    return [g for s in sweeps for g, _, _ in s.points()] + [x for s in sweeps for tb in s.thesis
                                                          for x in (tb.lower, tb.upper)]


def _bracket_legend() -> list:
    return [plt.Rectangle((0, 0), 1, 1, color="#f0a030", alpha=0.35, label="thesis's transition bracket (claims.json)"),
            plt.Line2D([], [], color="k", lw=1.0, ls=(0, (4, 2)), label="this sweep's bracket")]


def oblate_map(sweeps: list[Sweep]) -> Figure | None:
    oblate = [s for s in sweeps if s.family[0] == "oblate_spheroid" and s.runs and finite(s.ratio)]
    if not oblate:
        return None
    laws = sorted({s.family for s in oblate}, key=family_sort)
    fig, axes = plt.subplots(1, len(laws), figsize=(4.0 * len(laws) + 2.2, 3.6), squeeze=False, sharey=True)
    ratios = sorted({s.ratio for s in oblate})
    gs = _map_gs(oblate)
    for ax, fam in zip(axes[0], laws):
        for s in (s for s in oblate if s.family == fam):
            y = s.ratio + 0.04 * _offset(s.fidelity)
            _bracket_bars(ax, s, y, 0.035)
            _mode_markers(ax, s, y)
        _log_g_axis(ax, gs)
        ax.set_title(family_title(fam), fontsize=8.5)
        ax.grid(True, lw=0.3, alpha=0.6)
    axes[0][0].set_yticks(ratios)
    axes[0][0].set_yticklabels([ratio_text(r) for r in ratios])
    axes[0][0].set_ylim(min(ratios) - 0.2, max(ratios) + 0.2)
    axes[0][0].set_ylabel("axis ratio (equatorial : polar)")
    _legend_modes(axes[0][-1], _bracket_legend())
    fig.tight_layout()
    runs = [r for s in oblate for r in s.runs]
    return Figure(capsule3d.figures.png_data_uri(fig),
                  f"Mode map of the oblate spheroids ({fidelity_text(runs)}): one marker per finished run at its G "
                  "(log axis) and axis ratio, one panel per membrane law; marker and colour give the mode of "
                  "summary.json (open markers: quick, raised/lowered slightly per fidelity). Orange bars: the thesis's "
                  "transition brackets (bracket claims of references/capsule3d_modes/claims.json); dashed black: the "
                  "sweep's own bracket, between the largest G that tumbles and the smallest G above it that "
                  "tank-treads (stated below). Compare thesis figs. 6.4-6.10; the thesis draws no such map.")


def line_map(sweeps: list[Sweep]) -> Figure | None:
    rows = [s for s in sweeps if s.family[0] != "oblate_spheroid" and s.runs]
    if not rows:
        return None
    families = sorted({s.family for s in rows}, key=family_sort)
    fig, ax = plt.subplots(figsize=(8.6, 0.9 * len(families) + 1.3))
    gs = _map_gs(rows)
    for i, fam in enumerate(families):
        for s in (s for s in rows if s.family == fam):
            y = i + 0.18 * _offset(s.fidelity)
            _bracket_bars(ax, s, y, 0.12)
            _mode_markers(ax, s, y)
    ax.set_yticks(range(len(families)))
    ax.set_yticklabels([family_title(f) for f in families], fontsize=8)
    ax.set_ylim(-0.6, len(families) - 0.4)
    _log_g_axis(ax, gs)
    ax.grid(True, lw=0.3, alpha=0.6)
    _legend_modes(ax, _bracket_legend())
    runs = [r for s in rows for r in s.runs]
    return Figure(capsule3d.figures.png_data_uri(fig),
                  f"Mode map of the biconcave discoids and the spheres ({fidelity_text(runs)}) against G (log axis), "
                  "one row per family; markers, bars and dashes as in the oblate map. Thesis: the spheres always reach "
                  "steady tank-treading (6.1); the discoids swing at G = 0.47-2.8 and 0.045, tumble at 0.0045 and "
                  "0.0005 (6.3, figs. 6.12-6.17).")


def _swept(sweeps: list[Sweep]) -> list[Sweep]:
    return [s for s in sweeps if s.family[0] != "sphere" and s.runs]


def amplitude_figure(sweeps: list[Sweep], amp: Band) -> Figure | None:
    shown = _swept(sweeps)
    if not shown:
        return None
    fig, axes = plt.subplots(1, 2, figsize=(13.0, 4.0))
    colours = capsule3d._colours(range(len(shown)))
    for i, s in enumerate(shown):
        curves = ([], [])  # the tank-treading points, joined; a tumbling one stands alone
        for g, mode, run in s.points():
            tumbles = mode == TUMBLING
            values = (180.0 if tumbles else _deg(inclination_amplitude(run)),
                      run.metric("taylor_deformation_amplitude"))
            for ax, y, curve in zip(axes, values, curves):
                if y is not None and (ax is axes[1] or y > 0):
                    ax.plot(g, y, MODE_STYLE[mode][0], color=colours[i], ms=7, mfc="white" if tumbles else colours[i])
                    if not tumbles:
                        curve.append((g, y))
        for ax, curve in zip(axes, curves):
            ax.plot(*(zip(*curve) if curve else ([], [])), "-", color=colours[i], lw=1.0,
                    label=s.title if ax is axes[0] else None)
    discoids = any(s.family[0] == "biconcave_discoid" for s in shown)
    if amp.capillary and discoids:
        axes[0].fill_between(list(amp.capillary), amp.lower, amp.upper, color="#f0a030", alpha=0.4, lw=0,
                             label=f"thesis, biconcave: {amp.lower:g}-{amp.upper:g}° at G = "
                                   f"{amp.capillary[0]:g}-{amp.capillary[1]:g} ({amp.source})")
    axes[0].axhline(180.0, color="#d62728", lw=0.8, ls=":",
                    label="tumbling (open markers): drawn at π = 180°, as thesis fig. 6.7")
    axes[0].set_yscale("log")
    axes[0].set_ylabel("inclination amplitude [°] (log)")
    axes[1].set_ylabel("D_xz amplitude [-]")
    gs = [g for s in shown for g, _, _ in s.points()] + list(amp.capillary if discoids and amp.capillary else ())
    for ax in axes:
        _log_g_axis(ax, gs)
    handles, labels = axes[0].get_legend_handles_labels()
    axes[1].legend(handles, labels, fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return Figure(capsule3d._finish(fig, axes, "amplitudes of the inclination and of D_xz against G"),
                  "Oscillation amplitudes against G (log), per sweep "
                  f"({fidelity_text([r for s in shown for r in s.runs])}): left, summary inclination_amplitude "
                  "((max − min)/2 of θ over k t ≥ outputs.average_from; section_inclination_amplitude, the middle "
                  "cross section's θ that thesis fig. 6.14 plots, where the run measured it: the biconcave cells) in "
                  "degrees (log axis); right, "
                  "taylor_deformation_amplitude of D_xz (dimensionless). Markers give the mode; lines join the "
                  "tank-treading runs of a sweep. A tumbling run has no oscillation amplitude (θ decreases without "
                  "bound): it is drawn at π (open markers), as the thesis does in fig. 6.7 ('below which the "
                  "oscillation amplitude the inclination angle equals π')"
                  + (f"; orange band: the thesis's biconcave amplitude ({amp.source})" if discoids else "")
                  + ". Compare thesis fig. 6.7 (ZT 3:2) and section 6.3.1.")


def frequency_figure(sweeps: list[Sweep], freq: Band, external: list[ExternalValue], note: str = "") -> Figure | None:
    pts = [(s, g, run.metric("tank_treading_frequency_per_k")) for s in sweeps for g, _, run in s.points()]
    pts = [p for p in pts if p[2] is not None]
    if not pts:
        return None
    fig, ax = plt.subplots(figsize=(8.4, 3.8))
    shown = [s for s in sweeps if any(p[0] is s for p in pts)]
    colours = capsule3d._colours(range(len(shown)))
    for i, s in enumerate(shown):
        curve = sorted((g, f) for t, g, f in pts if t is s)
        ax.plot(*zip(*curve), "o-", color=colours[i], lw=1.0, ms=6, label=s.title)
    discoids = freq.capillary and any(s.family[0] == "biconcave_discoid" for s in sweeps)
    if discoids:
        ax.fill_between(list(freq.capillary), freq.lower, freq.upper, color="#f0a030", alpha=0.4, lw=0,
                        label=f"thesis, biconcave: f/k = {freq.lower:g}-{freq.upper:g} ({freq.source})")
    for e, style in zip(external, ("--", ":", "-.", (0, (1, 3)))):
        ax.axhline(e.value, color="k", lw=1.0, ls=style, label=f"Tran-Son-Tay et al. 1984, {e.text}")
        ax.axhspan(e.lower, e.upper, color="k", alpha=0.07, lw=0)
    _log_g_axis(ax, [g for _, g, _ in pts] + list(freq.capillary if discoids else ()))
    ax.set_ylabel("tank-treading frequency f/k [-]")
    capsule3d._legend_outside(ax, len(shown) + 2)
    return Figure(capsule3d._finish(fig, ax, "tank-treading frequency against G (thesis fig. 6.15)"),
                  "Tank-treading frequency f/k = 2π/(kT), T the mean time of one membrane revolution (summary "
                  f"tank_treading_frequency_per_k, present only when whole revolutions happened), against G (log), "
                  f"{fidelity_text([r for t in shown for r in t.runs])}. "
                  + (f"Orange band: the thesis's biconcave range ({freq.source}). " if discoids else "")
                  + ("Black lines: Tran-Son-Tay et al. 1984, red cells in a rheoscope (external data, "
                     f"references/{BENCHMARK}/{TRAN_SON_TAY_FILE}: f/γ̇ per row, the mean over the shear rates, grey "
                     "the range of the rows; the thesis compares with the young cells, 0.22). Their shear rates are "
                     "not G: the lines run across the axis." if external else
                     f"Tran-Son-Tay et al. 1984 not drawn: {note or 'no value'}."))


def sphere_area_figure(runs: list[Run], thesis_points, thesis_source: str, sk: Band, cache: dict) -> Figure | None:
    spheres = [r for r in runs if params(r)["shape"] == "sphere" and finite(params(r)["capillary"])]
    if not spheres:
        return None
    fig, ax = plt.subplots(figsize=(8.4, 3.9))
    styles = {"zero_thickness": "#1f4e79", "skalak": "#b03a2e", "neo_hookean": "#6a3d9a"}
    for law in sorted({params(r)["law"] for r in spheres}, key=lambda x: LAW_ORDER.index(x) if x in LAW_ORDER else 9):
        for fid in sorted({r.fidelity for r in spheres}):
            members = sorted((r for r in spheres if params(r)["law"] == law and r.fidelity == fid), key=_g)
            for metric, column, marker, what in (("surface_area_change_max", "surface_area_change", "o-", "total"),
                                                 ("max_area_change_max", "max_area_change", "s:", "largest local")):
                pts = [(_g(r), capsule3d._largest(r, metric, column, cache)[0]) for r in members]
                pts = [(g, 100 * v) for g, v in pts if v is not None and v > 0]
                if pts:
                    ax.plot(*zip(*pts), marker, color=styles.get(law, "#444"), ms=6, lw=1.0,
                            mfc="white" if fid == "quick" else styles.get(law, "#444"),
                            label=f"{LAW_LABELS.get(law, law)}, {what} max|ΔA/A₀| ({fid})")
    ax.plot(*zip(*[(g, 100 * v) for g, v in thesis_points]), "D", color="k", ms=7, mfc="none",
            label=f"thesis, ZT: 0.4 % → 23.5 % ({thesis_source})")
    if sk.capillary:
        ax.plot(sk.capillary[0], 100 * sk.upper, "v", color="#b03a2e", ms=9, mfc="none",
                label=f"thesis, SK C = 100: within {100 * sk.upper:g} % at G = {sk.capillary[0]:g} ({sk.source})")
    _log_g_axis(ax, [_g(r) for r in spheres])
    ax.set_yscale("log")
    ax.set_ylabel("largest area change over the run [%] (log)")
    capsule3d._legend_outside(ax, 8)
    return Figure(capsule3d._finish(fig, ax, "spheres: largest membrane area change against G (thesis 6.1)"),
                  f"Largest membrane area change over the run of the spheres against G ({fidelity_text(spheres)}): "
                  "solid, the total area max|A/A₀ − 1| (summary surface_area_change_max, the thesis's 'maximum "
                  "membrane area change' as the catalogue reads it); dotted, the largest local change over the "
                  "triangles max|Aₑ/Aₑ₀ − 1| (max_area_change_max). Open diamonds: the thesis's ZT values, 0.4 % at "
                  "G = 0.0125 and 23.5 % at G = 0.2; open triangle: its SK bound (an upper bound, not a value).")


# ---- tables ------------------------------------------------------------------------------------------------

def _deg(x):
    return math.degrees(x) if x is not None else None


def inclination_amplitude(run: Run):
    """The run's inclination amplitude (rad): that of the middle cross section
    (``section_inclination_amplitude``, the angle thesis 6.3 plots for the biconcave cells) where the run
    measured it, else that of the equivalent ellipsoid's axis (``inclination_amplitude``)."""
    section = run.metric("section_inclination_amplitude")
    return section if section is not None else run.metric("inclination_amplitude")


def table_row(run: Run, cache: dict) -> dict:
    p = params(run)
    done = run.status == "ok"
    oblate = p["shape"] == "oblate_spheroid" and finite(p.get("aspect_ratio"))
    row = {"run": run, "ratio": ratio_text(p["aspect_ratio"]) if oblate else "",
           "ratio_value": p["aspect_ratio"] if oblate else 0.0,
           "capillary": p["capillary"], "area_dilation": p.get("area_dilation"), "status": run.status_label,
           "done": done, "mode": capsule.mode_of(run) if done else None, "wall": run.perf("wall_time_s")}
    row["mode_text"] = MODE_WORDS.get(row["mode"], row["mode"] or ("no mode" if done else run.status_label))
    for key, metric in (("d_amp", "taylor_deformation_amplitude"), ("d_mean", "taylor_deformation_mean"),
                        ("theta_mean", "inclination_mean"), ("frequency", "tank_treading_frequency_per_k")):
        row[key] = run.metric(metric) if done else None
    row["theta_amp"] = inclination_amplitude(run) if done else None
    row["theta_section"] = done and run.metric("section_inclination_amplitude") is not None
    row["theta_amp"], row["theta_mean"] = _deg(row["theta_amp"]), _deg(row["theta_mean"])
    for key, metric, column in (("area", "surface_area_change_max", "surface_area_change"),
                                ("local", "max_area_change_max", "max_area_change"),
                                ("volume", "volume_change_max", "volume_change")):
        row[key] = capsule3d._largest(run, metric, column, cache)[0] if done else None
    return row


@dataclass
class FamilyTable:
    key: tuple
    title: str
    rows: list[dict] = field(default_factory=list)
    not_run: list[Run] = field(default_factory=list)   #: catalogue cases without a run at a fidelity shown

    @property
    def oblate(self) -> bool:
        return self.key[0] == "oblate_spheroid"

    @property
    def varying_c(self) -> bool:
        return self.key[0] == "biconcave_discoid"


def family_tables(runs: list[Run], cache: dict) -> list[FamilyTable]:
    tables: dict[tuple, FamilyTable] = {}
    for run in runs:
        key = family_key(params(run))
        table = tables.setdefault(key, FamilyTable(key, family_title(key)))
        if run.status == "missing":
            table.not_run.append(run)
        else:
            table.rows.append(table_row(run, cache))
    out = sorted(tables.values(), key=lambda t: family_sort(t.key))
    for t in out:
        t.rows.sort(key=lambda r: (r["ratio_value"], r["capillary"] if finite(r["capillary"]) else 0,
                                   r["run"].fidelity))
        t.not_run.sort(key=lambda r: (str(params(r).get("aspect_ratio")), _g(r), r.fidelity))
    return [t for t in out if t.rows]


# ---- the section ---------------------------------------------------------------------------------------------

#: The thesis figures each group of histories is compared with (capsule3d.shape_histories).
def history_figures(shape: str, ratio, law: str) -> str | None:
    if shape == "sphere":
        return {"zero_thickness": "fig. 6.2 (ZT)", "skalak": "fig. 6.3 (SK, C = 100)"}.get(law, "section 6.1")
    if shape == "biconcave_discoid":
        return "figs. 6.13 (length, width, thickness) and 6.16 (θ at G = 0.0045, 0.015, 0.045)"
    if shape == "oblate_spheroid":
        if law == "zero_thickness":
            return "figs. 6.6 (3:2: D and θ) and 6.7" if finite(ratio) and math.isclose(ratio, 1.5) else "fig. 6.8 (θ)"
        return {"neo_hookean": "fig. 6.10 (θ near the transition)",
                "skalak": "fig. 6.9 (θ, C = 100)"}.get(law, "section 6.2")
    return None


@dataclass
class ClaimVerdict:
    check: capsule.ClaimCheck

    @property
    def anchor(self) -> str:
        return "claim-" + str(self.check.claim.get("id", "")).replace(".", "-")


@dataclass
class Modes3D:
    runs: list[Run] = field(default_factory=list)         #: finished chapter 6 capsule runs
    not_shown: list[Run] = field(default_factory=list)    #: did not finish: listed, not plotted
    sweeps: list[Sweep] = field(default_factory=list)
    oblate_map: Figure | None = None
    line_map: Figure | None = None
    amplitudes: Figure | None = None
    frequency: Figure | None = None
    frequency_note: str = ""
    amplitude_band: Band | None = None
    frequency_band: Band | None = None
    external: list[ExternalValue] = field(default_factory=list)
    external_anchor: str = ""
    discrepancies: dict = field(default_factory=dict)        #: part -> [(key, entry)] of provenance.json
    histories: list = field(default_factory=list)           #: capsule3d.Histories
    sphere_area: Figure | None = None
    tables: list[FamilyTable] = field(default_factory=list)
    claims: list[ClaimVerdict] = field(default_factory=list)
    datasets: list[Dataset] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    @property
    def present(self) -> bool:
        return bool(self.runs or self.not_shown)

    @property
    def claims_checked(self) -> list[ClaimVerdict]:
        return [c for c in self.claims if c.check.verdict != "not checked"]

    @property
    def claims_not_checked(self) -> list[ClaimVerdict]:
        """Values, and trends or bounds without a metric: documentation, listed by id."""
        return [c for c in self.claims if c.check.verdict == "not checked"]

    @property
    def tally(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for c in self.claims:
            out[c.check.verdict] = out.get(c.check.verdict, 0) + 1
        return out


def build(runs: list[Run], refs: ReferenceLibrary, chapter: str,
          claims: list[capsule.ClaimCheck] | None = None) -> Modes3D:
    """The chapter 6 section; ``claims``: the chapter's checks already made by capsule.build (made
    here by capsule.build when not given)."""
    section = Modes3D()
    if chapter != CHAPTER:
        return section
    mine = [r for r in runs if is_mode_run(r)]
    section.runs = [r for r in mine if r.status == "ok"]
    section.not_shown = [r for r in mine if r.status not in ("ok", "missing")]
    if not section.present:
        return section
    cache: dict = {}
    ds = refs.get(BENCHMARK, CLAIMS_FILE)
    claim_docs = dict(ds.claims) if ds is not None else {}
    if ds is None:
        section.problems.append(f"chapter 6 capsules: references/{BENCHMARK}/{CLAIMS_FILE} not found: no thesis "
                                "bracket drawn, the thesis's numbers quoted from its text")
    else:
        section.datasets.append(ds)

    section.discrepancies = capsule3d.discrepancy_notes(refs.benchmarks.get(BENCHMARK, {}), DISCREPANCIES)
    section.sweeps = sweeps_of(mine)
    attach_thesis_brackets(section.sweeps, list(claim_docs.values()), mine)
    section.oblate_map = capsule3d._guarded(section, "chapter 6 oblate mode map", lambda: oblate_map(section.sweeps))
    section.line_map = capsule3d._guarded(section, "chapter 6 mode map", lambda: line_map(section.sweeps))

    section.amplitude_band = band(claim_docs, "amplitude", degrees=True)
    section.frequency_band = band(claim_docs, "frequency")
    section.external, tst, note = tran_son_tay(refs)
    if tst is not None:
        section.datasets.append(tst)
        section.external_anchor = tst.anchor
    if note:
        section.notes.append(note)
    section.amplitudes = capsule3d._guarded(section, "amplitude figure",
                                            lambda: amplitude_figure(section.sweeps, section.amplitude_band))
    section.frequency = capsule3d._guarded(section, "frequency figure", lambda: frequency_figure(
        section.sweeps, section.frequency_band, section.external, note))
    if section.frequency is None:
        section.frequency_note = ("no finished run has tank_treading_frequency_per_k in summary.json (it needs whole "
                                  "membrane revolutions inside the averaging window: at f/k ≈ 0.22 one takes k t ≈ 29)")

    ok = [r for r in section.runs if moving.series(r, cache)]
    histories = capsule3d._guarded(section, "time histories",
                                   lambda: capsule3d.shape_histories(ok, cache, history_figures), [])
    section.histories = sorted(histories, key=lambda h: (family_sort(family_key(params(h.runs[0]))),
                                                         params(h.runs[0]).get("aspect_ratio") or 0))
    points, source = sphere_area_points(claim_docs)
    sk = band(claim_docs, "sphere_sk_area")
    section.sphere_area = capsule3d._guarded(section, "sphere area figure",
                                   lambda: sphere_area_figure(section.runs, points, source, sk, cache))
    section.tables = family_tables(mine, cache)

    if claims is None:
        claims = capsule.build(runs, refs, CHAPTER).claims
    section.claims = [ClaimVerdict(c) for c in claims]
    return section
