"""Moving rigid bodies of a chapter page (thesis sections 2.2.2-2.2.3; external validation in extra/).

A moving run is one whose case has a body with ``motion.type == "prescribed"`` and no membrane
(catalogue/schema.json). Its series.h5 holds per body ``drag_coefficient``, ``lift_coefficient``,
``x``, ``y`` and ``angle``, prefixed ``<body>.`` when the case has several bodies (the two
cylinders are "upper" and "lower"). A uniform-grid twin is the same case (same physics, fine
spacing and fidelity) with ``numerics.grid.refinement = "uniform"``: the thesis's "original IB-LBM".

What a chapter page gets, kept apart as in capsule.py (conventions in references/moving/provenance.json):

- figures: the force histories of each two-block case overlaid with its twin, on Xu & Wang's time
  scale as thesis figs. 2.12 and 2.15; for the two cylinders also C_d against dx = x_upper - x_lower
  with the windows of the drag-trend statement shaded;
- thesis statements (references/moving/claims.json, ids "<chapter>.*"): the drag trend is checked
  on the flow of each run; the statements about the multi-block method (uniform twin, refinement,
  fine fraction and cost) by comparing caplab runs with each other, which is consistency, caplab
  against caplab, not validation. The checks are the C++ scorer's (``caplab claims``,
  solver/score/motion_claims.hpp, through claims.py); this module shows its verdicts (consistent,
  inconsistent, no run, not enough runs, not checked), rows and detail lines;
- verification and consistency: every two-block/twin pair (relative RMS difference of every force
  column, node updates, wall time), and periodicity and period means of periodic motions
  (provenance.json "consistency");
- validation against external data: for a run whose acceptance has time_series entries (the
  Wang 2004 wing), its C_x and C_y against every reference series, the RMS of score.json next to
  this module's own recomputation of it (a scorer and a report that disagree show up), and the RMS
  between the reference series themselves, the yardstick of the tolerance.

Every number shown is computed from the runs and the reference files; the numbers of each check
(windows, tolerances) are read from claims.json and provenance.json, never written here. The
window means drawn in the C_d-against-dx panel (proximity_means) are recomputed here for the
figure only; the verdict on them is caplab's.
"""

from __future__ import annotations

import copy
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import claims as claims_tool  # noqa: E402
from . import figures  # noqa: E402
from .references import Dataset, ReferenceLibrary  # noqa: E402
from .runs import Run, finite  # noqa: E402

BENCHMARK = "moving"
CLAIMS_FILE = "claims.json"
FORCES = ("drag_coefficient", "lift_coefficient")
SYMBOLS = {"drag_coefficient": "C_d", "lift_coefficient": "C_l"}
MIN_SAMPLES = 3  #: fewer samples in a window than this and its mean is not taken


# ---- what a moving run is -------------------------------------------------------------------------

def is_moving(run: Run) -> bool:
    return any(isinstance(b.get("motion"), dict) and b["motion"].get("type") == "prescribed"
               and not isinstance(b.get("membrane"), dict) for b in run.bodies)


def without_statements(refs: ReferenceLibrary) -> ReferenceLibrary:
    """``refs`` without references/moving/, for capsule.build, which takes every claim whose id starts
    with the chapter (these are not capsule statements and are checked here)."""
    view = copy.copy(refs)
    view.datasets = {k: v for k, v in refs.datasets.items() if k[0] != BENCHMARK}
    view.benchmarks = {k: v for k, v in refs.benchmarks.items() if k != BENCHMARK}
    return view


def refinement(run: Run) -> str:
    numerics = run.case.get("numerics") if isinstance(run.case.get("numerics"), dict) else {}
    grid = numerics.get("grid") if isinstance(numerics.get("grid"), dict) else {}
    return str(grid.get("refinement", ""))


def label(run: Run) -> str:
    return f"{run.case_id} ({run.fidelity})"


def symbol(column: str) -> str:
    """"upper.drag_coefficient" -> "upper C_d"."""
    body, _, quantity = column.rpartition(".")
    return (body + " " if body else "") + SYMBOLS.get(quantity, quantity)


def pct(x) -> str:
    return f"{100 * x:.2f} %" if finite(x) else "–"


def num(x, digits: int = 4) -> str:
    return f"{x:.{digits}g}" if finite(x) else "–"


# ---- series -----------------------------------------------------------------------------------------

def series(run: Run, cache: dict) -> dict[str, np.ndarray]:
    """{"t": ..., column: ...} of series.h5 (read once per run); {} when unavailable."""
    key = id(run)
    if key not in cache:
        out: dict[str, np.ndarray] = {}
        if run.series_path is not None and run.status == "ok":
            t, cols, _ = figures.read_series(run.series_path)
            if t is not None:
                out["t"] = t.values
                out.update({c.name: c.values for c in cols})
        cache[key] = out
    return cache[key]


# ---- windows of the relative position ---------------------------------------------------------------

_INTERVAL = re.compile(r"^\s*([\[(])\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*([\])])\s*$")


@dataclass(frozen=True)
class Interval:
    lo: float
    hi: float
    lo_open: bool
    hi_open: bool

    def contains(self, x: np.ndarray) -> np.ndarray:
        above = x > self.lo if self.lo_open else x >= self.lo
        below = x < self.hi if self.hi_open else x <= self.hi
        return above & below

    @property
    def text(self) -> str:
        return f"{self.lo:g} {'<' if self.lo_open else '≤'} dx {'<' if self.hi_open else '≤'} {self.hi:g}"


def parse_interval(text: str) -> Interval:
    """"(0, 3]" -> 0 < x <= 3; raises ValueError for anything else."""
    m = _INTERVAL.match(str(text))
    if not m:
        raise ValueError(f"not an interval: {text!r} (expected e.g. \"(0, 3]\")")
    lo, hi = float(m.group(2)), float(m.group(3))
    if not lo < hi:
        raise ValueError(f"empty interval: {text!r}")
    return Interval(lo, hi, m.group(1) == "(", m.group(4) == ")")


def encounter_time(t: np.ndarray, dx: np.ndarray) -> float | None:
    """The time at which dx first changes sign (linear interpolation), None if it never does."""
    ok = np.isfinite(t) & np.isfinite(dx)
    t, dx = t[ok], dx[ok]
    nonzero = np.flatnonzero(dx != 0)
    if nonzero.size == 0:
        return None
    s0 = np.sign(dx[nonzero[0]])
    after = np.flatnonzero((np.arange(dx.size) > nonzero[0]) & (np.sign(dx) != s0))
    if after.size == 0:
        return None
    i = int(after[0])
    if dx[i] == 0:
        return float(t[i])
    return float(t[i - 1] + (t[i] - t[i - 1]) * dx[i - 1] / (dx[i - 1] - dx[i]))


@dataclass
class WindowMean:
    name: str
    interval: Interval
    phase: str
    mean: float | None = None
    samples: int = 0
    t_span: tuple[float, float] | None = None
    peak: tuple[float, float] | None = None     #: (largest value, its dx)
    trough: tuple[float, float] | None = None   #: (smallest value, its dx)

    @property
    def text(self) -> str:
        return f"{self.interval.text}, {self.phase}"


@dataclass
class Proximity:
    """The windows of the drag-trend statement on one run, for the figure: the baseline, the
    windows, the sign of 'opposing' (the verdict is caplab's, motion_claims.hpp)."""

    baseline: WindowMean
    windows: list[WindowMean]
    sign: float = 1.0          #: C_d times this opposes the body's motion
    encounter: float | None = None
    problem: str = ""


def _window(spec: dict, name: str) -> WindowMean:
    phase = spec.get("phase")
    if phase not in ("approaching", "separating"):
        raise ValueError(f"window {name}: phase must be approaching or separating (got {phase!r})")
    return WindowMean(name, parse_interval(spec.get("dx", "")), phase)


def proximity_means(t, x_body, x_other, values, check: dict) -> Proximity:
    """Means of ``values`` (the body's C_d) over the windows of dx = x_body - x_other of ``check``
    (claims.json ``proximity_means``), as motion_claims.hpp takes them, for the figure."""
    t, x_body, x_other, values = (np.asarray(a, dtype=float) for a in (t, x_body, x_other, values))
    base = _window(check.get("baseline") or {}, "baseline")
    base.name = "baseline"
    windows = [_window(w, w.get("name", f"window {i + 1}")) for i, w in enumerate(check.get("windows") or [])]
    result = Proximity(base, windows)
    if not result.windows:
        result.problem = "the check names no window"
        return result
    dx = x_body - x_other
    result.encounter = encounter_time(t, dx)
    if result.encounter is None:
        result.problem = "dx never changes sign: the bodies do not pass each other in this run"
        return result
    u_x = np.gradient(x_body, t) if t.size > 1 else np.zeros_like(t)
    masks = {}
    for w in [base] + result.windows:
        phase = t < result.encounter if w.phase == "approaching" else t > result.encounter
        masks[w.name] = phase & w.interval.contains(dx) & np.isfinite(values)
    union = np.logical_or.reduce(list(masks.values()))
    mean_u = float(np.mean(u_x[union])) if union.any() else 0.0
    if not abs(mean_u) > 1e-9:
        result.problem = "the body does not move along x in the windows: no drag direction"
        return result
    result.sign = -math.copysign(1.0, mean_u)
    for w in [base] + result.windows:
        sel = masks[w.name]
        w.samples = int(sel.sum())
        if w.samples < MIN_SAMPLES:
            continue
        v = result.sign * values[sel]
        w.mean = float(np.mean(v))
        w.t_span = (float(t[sel].min()), float(t[sel].max()))
        i, j = int(np.argmax(v)), int(np.argmin(v))
        w.peak, w.trough = (float(v[i]), float(dx[sel][i])), (float(v[j]), float(dx[sel][j]))
    if base.mean is None:
        result.problem = f"fewer than {MIN_SAMPLES} samples in the baseline window ({base.text})"
    return result


# ---- differences between runs -----------------------------------------------------------------------

@dataclass
class Difference:
    column: str
    rms: float
    peak: float
    samples: int

    @property
    def relative(self) -> float:
        return self.rms / self.peak if self.peak > 0 else math.nan


def relative_rms(t_run, y_run, t_ref, y_ref, t_from: float, column: str = "") -> Difference | None:
    """RMS of y_run - y_ref over t >= t_from, each interpolated onto the other's samples where
    both exist (the larger of the two directions), and the peak |y_ref| over t >= t_from. A
    non-finite sample makes the RMS NaN (never a pass)."""
    t_run, y_run, t_ref, y_ref = (np.asarray(a, dtype=float) for a in (t_run, y_run, t_ref, y_ref))
    if t_run.size < 2 or t_ref.size < 2:
        return None
    rms_values, counts = [], []
    for ta, ya, tb, yb in ((t_run, y_run, t_ref, y_ref), (t_ref, y_ref, t_run, y_run)):
        sel = (tb >= max(t_from, ta[0])) & (tb <= ta[-1])
        if not sel.any():
            return None
        d = np.interp(tb[sel], ta, ya) - yb[sel]
        rms_values.append(float(np.sqrt(np.mean(d * d))))
        counts.append(int(sel.sum()))
    ref = y_ref[t_ref >= t_from]
    peak = float(np.max(np.abs(ref))) if ref.size else math.nan
    rms = math.nan if any(math.isnan(r) for r in rms_values) else max(rms_values)
    return Difference(column, rms, peak if math.isfinite(peak) else math.nan, min(counts))


def _numerics(run: Run) -> dict:
    numerics = run.case.get("numerics") if isinstance(run.case.get("numerics"), dict) else {}
    return {k: v for k, v in numerics.items() if k not in ("grid", "threads")}


def numerics_differences(a: Run, b: Run) -> list[str]:
    """Keys of numerics (other than the grid) in which two runs differ, e.g. "lattice_velocity"."""
    na, nb = _numerics(a), _numerics(b)
    same = lambda k: json.dumps(na.get(k), sort_keys=True) == json.dumps(nb.get(k), sort_keys=True)  # noqa: E731
    return sorted(k for k in set(na) | set(nb) if not same(k))


def twin_of(run: Run, runs: list[Run]) -> Run | None:
    """The uniform-grid twin of a two-block run among ``runs`` (same physics, fine spacing and
    fidelity); a finished one first, then one named "<case id>_uniform"."""
    if refinement(run) != "two_level":
        return None
    physics = json.dumps(run.physics, sort_keys=True)
    found = [r for r in runs if r is not run and r.fidelity == run.fidelity and refinement(r) == "uniform"
             and json.dumps(r.physics, sort_keys=True) == physics
             and r.fine_spacing is not None and run.fine_spacing is not None
             and math.isclose(r.fine_spacing, run.fine_spacing, rel_tol=1e-9)]
    found.sort(key=lambda r: (r.status != "ok", r.case_id != run.case_id + "_uniform", r.case_id))
    return found[0] if found else None


def fine_fraction(case: dict) -> float | None:
    """Area of numerics.grid.fine_region over the area of physics.domain.size (two-block cases)."""
    numerics = case.get("numerics") if isinstance(case.get("numerics"), dict) else {}
    grid = numerics.get("grid") if isinstance(numerics.get("grid"), dict) else {}
    region = grid.get("fine_region") if isinstance(grid.get("fine_region"), dict) else {}
    physics = case.get("physics") if isinstance(case.get("physics"), dict) else {}
    size = (physics.get("domain") or {}).get("size") if isinstance(physics.get("domain"), dict) else None
    lo, hi = region.get("min"), region.get("max")
    if not (isinstance(size, list) and isinstance(lo, list) and isinstance(hi, list)
            and len(size) == len(lo) == len(hi) and all(finite(v) for v in size + lo + hi)):
        return None
    domain = math.prod(size)
    return math.prod(h - low for low, h in zip(lo, hi)) / domain if domain > 0 else None


def built_fine_fraction(manifest: dict) -> float | None:
    """Extent of the fine block's nodes over the coarse block's (manifest lattice.blocks)."""
    lattice = manifest.get("lattice") if isinstance(manifest.get("lattice"), dict) else {}
    blocks = {b.get("name"): b for b in lattice.get("blocks", []) if isinstance(b, dict)}
    fine, coarse = blocks.get("fine"), blocks.get("coarse")
    if not fine or not coarse:
        return None

    def area(b):
        nodes, dx = b.get("nodes"), b.get("dx")
        if not isinstance(nodes, list) or not finite(dx):
            return math.nan
        return math.prod((n - 1) * dx for n in nodes)

    a_fine, a_coarse = area(fine), area(coarse)
    return a_fine / a_coarse if finite(a_fine) and finite(a_coarse) and a_coarse > 0 else None


@dataclass
class Cost:
    nodes: tuple[float | None, float | None]    #: node updates (two-block, twin)
    walls: tuple[float | None, float | None]    #: wall time in s
    threads: tuple
    mlups: tuple

    @staticmethod
    def _ratio(pair) -> float | None:
        a, b = pair
        return float(b) / float(a) if finite(a) and finite(b) and a > 0 else None

    @property
    def node_ratio(self) -> float | None:
        return self._ratio(self.nodes)

    @property
    def wall_ratio(self) -> float | None:
        return self._ratio(self.walls)

    @staticmethod
    def saving(ratio) -> float | None:
        return 1.0 - 1.0 / ratio if finite(ratio) and ratio > 0 else None


def cost(two_block: Run, twin: Run) -> Cost:
    def nodes(r):
        lattice = r.manifest.get("lattice") if isinstance(r.manifest.get("lattice"), dict) else {}
        v = lattice.get("node_updates")
        return float(v) if finite(v) else None

    def threads(r):
        return r.manifest.get("threads") or r.environment.get("threads")

    wall = lambda r: float(r.perf("wall_time_s")) if finite(r.perf("wall_time_s")) else None  # noqa: E731
    mlups = lambda r: float(r.perf("mlups")) if finite(r.perf("mlups")) else None  # noqa: E731
    return Cost((nodes(two_block), nodes(twin)), (wall(two_block), wall(twin)), (threads(two_block), threads(twin)),
                (mlups(two_block), mlups(twin)))


# ---- periodic motions -------------------------------------------------------------------------------

def period_of(run: Run) -> float | None:
    """The motion parameter T of the case (the same for every body that has one), or None."""
    periods = set()
    for b in run.bodies:
        params = (b.get("motion") or {}).get("parameters") if isinstance(b.get("motion"), dict) else None
        if isinstance(params, dict) and finite(params.get("T")) and params["T"] > 0:
            periods.add(float(params["T"]))
    return periods.pop() if len(periods) == 1 else None


def full_periods(t: np.ndarray, period: float) -> int:
    return int(math.floor(float(t[-1]) / period + 1e-6)) if t.size else 0


def periodicity(t, y, period: float) -> tuple[float, int] | None:
    """(RMS of y(t) - y(t + T) over the second-to-last full period over the peak |y| of the last two,
    number of full periods); None with fewer than three full periods."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    n = full_periods(t, period)
    if n < 3:
        return None
    t0 = (n - 2) * period
    sel = (t >= t0) & (t <= t0 + period)
    if sel.sum() < MIN_SAMPLES:
        return None
    later = np.interp(t[sel] + period, t, y)
    d = y[sel] - later
    peak = max(float(np.max(np.abs(y[sel]))), float(np.max(np.abs(later))))
    return (float(np.sqrt(np.mean(d * d))) / peak if peak > 0 else math.nan), n


def period_mean(t, y, period: float, first: int) -> tuple[float, int] | None:
    """(time average of y over (first - 1) T <= t <= n T, n) with n the full periods of the run."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    n = full_periods(t, period)
    if n < first:
        return None
    sel = (t >= (first - 1) * period) & (t <= n * period)
    if sel.sum() < MIN_SAMPLES:
        return None
    ts, ys = t[sel], y[sel]
    return float(np.sum(0.5 * (ys[1:] + ys[:-1]) * np.diff(ts)) / (ts[-1] - ts[0])), n


# ---- thesis statements: the verdicts of `caplab claims` ----------------------------------------------

@dataclass
class Part:
    """One row of the result of ``caplab claims`` for a statement (solver/score/motion_claims.hpp)."""

    label: str
    anchor: str
    text: str
    ok: bool | None = None   #: None: shown, not judged (or could not be judged)
    details: list[str] = field(default_factory=list)


@dataclass
class StatementCheck:
    claim: dict
    what: str
    group: str                 #: "flow" (checked on each run) | "method" (caplab against caplab)
    parts: list[Part] = field(default_factory=list)
    verdict: str = "no run"    #: caplab's: consistent | inconsistent | no run | not enough runs | not checked
    note: str = ""

    @property
    def check_basis(self) -> str:
        check = self.claim.get("check")
        return str(check.get("basis", "")) if isinstance(check, dict) else ""


def _part(row: dict, by_dir: dict[str, Run]) -> Part:
    run = by_dir.get(str(Path(row.get("directory", "")).resolve()))
    label_ = f"{row.get('run')} ({row.get('fidelity')})" + (f": {row['part']}" if row.get("part") else "")
    value, note = row.get("value"), str(row.get("note") or "")
    text = f"{value} ({note})" if value and note else (value or note or "–")
    ok = {"pass": True, "fail": False}.get(row.get("verdict"))
    return Part(label_, run.anchor if run is not None else "", text, ok, [str(d) for d in row.get("details") or []])


def check_statements(claims: list[dict], runs: list[Run], claims_file: Path | None = None,
                     settings: dict | None = None, only: str | None = None) -> list[StatementCheck]:
    """The verdicts of ``caplab claims`` (claims.py) on ``runs`` for the statements ``claims`` of
    ``claims_file`` (``--only``: ``only``); without a file, on a document of ``claims`` with
    ``settings`` (provenance.json "consistency") beside it. Runs without a directory are about none."""
    t_from = start_left_out(settings)
    checks = {c.get("id"): StatementCheck(c, describe(c, t_from), _group(c)) for c in claims}
    by_dir = {str(r.directory.resolve()): r for r in runs if r.directory is not None}
    if by_dir:
        result = claims_tool.evaluate(claims_file or {"claims": claims}, [Path(d) for d in by_dir], only,
                                      provenance={"consistency": settings or {}})
        for out in result.get("claims", []):
            check = checks.get(out.get("id"))
            if check is None:
                continue
            check.verdict = out.get("verdict") or "not checked"
            check.note = str(out.get("message") or "")
            check.parts = [_part(row, by_dir) for row in out.get("runs", [])]
    for check in checks.values():
        if check.verdict == "no run" and not check.note:
            check.note = "no run of " + ", ".join(sorted(check.claim.get("cases") or []))
    return list(checks.values())


def check_statement(claim: dict, runs: list[Run], cache: dict | None = None, settings: dict | None = None) -> StatementCheck:
    """``check_statements`` for one statement (``cache`` is not used: caplab reads the series)."""
    return check_statements([claim], runs, settings=settings)[0]


def _group(claim: dict) -> str:
    spec = claim.get("check") if isinstance(claim.get("check"), dict) else {}
    return "flow" if spec.get("type") == "proximity_means" else "method"


def start_left_out(settings: dict | None) -> float:
    """t before which run-to-run differences are not taken (provenance.json consistency.twin_difference)."""
    entry = (settings or {}).get("twin_difference")
    value = entry.get("from") if isinstance(entry, dict) else None
    return float(value) if finite(value) else 0.0


def describe(claim: dict, t_from: float = 0.0) -> str:
    """The check of a claim in words, from its numbers (``t_from``: start_left_out)."""
    spec = claim.get("check") if isinstance(claim.get("check"), dict) else {}
    kind = spec.get("type")
    try:
        if kind == "proximity_means":
            body, other, column = spec.get("body"), spec.get("other"), spec.get("column", "drag_coefficient")
            base = parse_interval(spec["baseline"]["dx"])
            parts = [f"dx = x_{body} − x_{other}; mean {body} {SYMBOLS.get(column, column)} (opposing its motion) over "
                     f"{base.text} ({spec['baseline']['phase']}) is the baseline"]
            for w in spec.get("windows", []):
                parts.append(f"the mean over {parse_interval(w['dx']).text} ({w['phase']}) must be {w['expect']} it")
            return "; ".join(parts)
        if kind == "twin":
            return (f"RMS of the difference from the uniform-grid twin after t = {t_from:g}, over the twin's peak, "
                    f"for {', '.join(symbol(c) for c in spec.get('columns', []))}: at most {pct(claim.get('upper'))}")
        if kind == "refinement":
            about, study = spec.get("fine_spacing"), ", ".join(claim.get("cases", []))
            return (f"RMS of the difference from the finest two-block grid of the study ({study}) "
                    f"at the same fidelity, after t = {t_from:g}, over its peak, "
                    f"for {', '.join(symbol(c) for c in spec.get('columns', []))}: at most {pct(claim.get('upper'))}"
                    + (f"; runs coarser than the statement's Δx_f = {about:g} are not judged" if about else ""))
        if kind == "fine_fraction":
            return (f"fine-block area over domain area within {100 * spec['tolerance']:g} % of {100 * claim['value']:g} %; "
                    f"node updates of the uniform twin above those of the two-block run; the saving below that of "
                    f"{spec.get('compare_with')} (section 2.2.1)")
    except (KeyError, TypeError, ValueError) as err:
        return f"malformed check: {err!r}"
    return ""


# ---- verification and consistency --------------------------------------------------------------------

@dataclass
class TwinPair:
    run: Run
    twin: Run
    differences: list[Difference] = field(default_factory=list)
    cost: Cost | None = None
    fraction: float | None = None
    built_fraction: float | None = None
    numerics: list[str] = field(default_factory=list)
    problem: str = ""


def force_columns(data: dict) -> list[str]:
    return [c for c in data if c != "t" and c.rpartition(".")[2] in FORCES]


def twin_pairs(moving_runs: list[Run], all_runs: list[Run], cache: dict, t_from: float) -> list[TwinPair]:
    pairs = []
    for run in moving_runs:
        twin = twin_of(run, all_runs) if run.status == "ok" else None
        if twin is None or twin.status != "ok":
            continue
        pair = TwinPair(run, twin, cost=cost(run, twin), fraction=fine_fraction(run.case),
                        built_fraction=built_fine_fraction(run.manifest), numerics=numerics_differences(run, twin))
        a, b = series(run, cache), series(twin, cache)
        if "t" not in a or "t" not in b:
            pair.problem = "no series.h5 in one of the runs"
        else:
            for c in force_columns(a):
                if c in b:
                    d = relative_rms(a["t"], a[c], b["t"], b[c], t_from, c)
                    if d is not None:
                        pair.differences.append(d)
        pairs.append(pair)
    return pairs


@dataclass
class PeriodicRow:
    run: Run
    period: float
    periods: int = 0
    rows: list[dict] = field(default_factory=list)   #: column, periodicity, ok, mean
    problem: str = ""


def periodic_rows(moving_runs: list[Run], cache: dict, settings: dict) -> list[PeriodicRow]:
    tolerance = settings.get("periodicity", {}).get("tolerance")
    first = int(settings.get("period_means", {}).get("first_period", 2))
    out = []
    for run in moving_runs:
        period = period_of(run)
        if period is None or run.status != "ok":
            continue
        row = PeriodicRow(run, period)
        data = series(run, cache)
        if "t" not in data:
            row.problem = "no series.h5"
            out.append(row)
            continue
        row.periods = full_periods(data["t"], period)
        for c in force_columns(data):
            p = periodicity(data["t"], data[c], period)
            m = period_mean(data["t"], data[c], period, first)
            ok = (p[0] <= tolerance if finite(tolerance) and finite(p[0]) else False) if p else None
            row.rows.append({"column": symbol(c), "periodicity": pct(p[0]) if p else "fewer than 3 periods",
                             "ok": ok, "mean": num(m[0]) if m else "–",
                             "window": f"{first}–{m[1]}" if m else "–"})
        out.append(row)
    return out


# ---- validation against reference series (external data) -------------------------------------------

@dataclass
class ValidationRow:
    metric: str
    reference: str
    dataset: Dataset | None
    window: str
    error: float | None          #: score.json
    tolerance: float | None
    verdict: str
    recomputed: float | None     #: this module's RMS with the scorer's definition
    points: int = 0
    agrees: bool | None = None


@dataclass
class Yardstick:
    metric: str
    a: str
    b: str
    rms: tuple[float, float]     #: a onto b's abscissae, b onto a's

    @property
    def larger(self) -> float:
        return max(self.rms)


@dataclass
class Validation:
    run: Run
    rows: list[ValidationRow] = field(default_factory=list)
    yardsticks: list[Yardstick] = field(default_factory=list)
    figure: str | None = None
    twin: Run | None = None
    problems: list[str] = field(default_factory=list)


def _reference_series(ds: Dataset | None, key: str) -> tuple[np.ndarray, np.ndarray] | None:
    if ds is None or ":" not in key:
        return None
    tcol, _, vcol = key.partition(":")
    t, v = np.asarray(ds.column_values(tcol)), np.asarray(ds.column_values(vcol))
    if t.size < 2 or t.size != v.size:
        return None
    ok = np.isfinite(t) & np.isfinite(v)
    return t[ok], v[ok]


def rms_on_reference(t_run, y_run, t_ref, y_ref, window) -> tuple[float, int] | None:
    """The scorer's time_series error (solver/score/comparators.hpp): RMS over the reference
    abscissae in the overlap of the two series and the window of run(t_i) - ref(t_i)."""
    t_run, y_run, t_ref, y_ref = (np.asarray(a, dtype=float) for a in (t_run, y_run, t_ref, y_ref))
    lo, hi = max(t_run[0], t_ref[0]), min(t_run[-1], t_ref[-1])
    if window:
        lo, hi = max(lo, window[0]), min(hi, window[1])
    sel = (t_ref >= lo) & (t_ref <= hi)
    if not sel.any():
        return None
    d = np.interp(t_ref[sel], t_run, y_run) - y_ref[sel]
    return float(np.sqrt(np.mean(d * d))), int(sel.sum())


def _window_of(entry: dict):
    w = entry.get("window")
    return (float(w[0]), float(w[1])) if isinstance(w, list) and len(w) == 2 and all(finite(x) for x in w) else None


def validation(run: Run, refs: ReferenceLibrary, all_runs: list[Run], cache: dict,
               figure: bool = True) -> Validation | None:
    """The time_series acceptance entries of ``run`` (None without any): score.json, recomputed, the
    yardstick between the references, and (``figure``) the run and its twin against the references."""
    entries = [a for a in run.case.get("acceptance", []) if isinstance(a, dict) and a.get("comparison") == "time_series"]
    if not entries:
        return None
    out = Validation(run)
    if run.status != "ok":
        return out  # shown with its status; nothing to compare
    twin = twin_of(run, all_runs)
    out.twin = twin if twin is not None and twin.status == "ok" else None
    data = series(run, cache)
    scored = run.entries
    curves: dict[str, list[tuple[str, Dataset | None, tuple]]] = {}
    for a in entries:
        metric, reference = a.get("metric", ""), a.get("reference", "")
        res = refs.resolve(reference)
        curve = _reference_series(res.dataset, res.key)
        window = _window_of(a)
        e = next((e for e in scored if e.get("metric") == metric and e.get("reference") == reference), {})
        recomputed = None
        if curve is not None and metric in data and "t" in data:
            recomputed = rms_on_reference(data["t"], data[metric], curve[0], curve[1], window)
        error = e.get("error") if finite(e.get("error")) else None
        row = ValidationRow(metric, reference, res.dataset,
                            f"{window[0]:.4g}–{window[1]:.4g}" if window else "whole run", error,
                            e.get("tolerance") if finite(e.get("tolerance")) else None,
                            str(e.get("verdict") or "not scored"),
                            recomputed[0] if recomputed else None, recomputed[1] if recomputed else 0)
        if error is not None and row.recomputed is not None:
            row.agrees = math.isclose(error, row.recomputed, rel_tol=1e-6, abs_tol=1e-9)
            if not row.agrees:
                out.problems.append(f"{label(run)}: {metric} against {reference}: score.json has RMS {error:.6g}, "
                                    f"the report recomputes {row.recomputed:.6g}")
        if curve is None:
            out.problems.append(f"{label(run)}: reference series {reference} not readable ({res.note or 'no such columns'})")
        else:
            curves.setdefault(metric, []).append((reference, res.dataset, curve, window))
        out.rows.append(row)
    for metric, items in curves.items():
        for i in range(len(items)):
            for j in range(i + 1, len(items)):
                (ra, _, ca, wa), (rb, _, cb, _) = items[i], items[j]
                ab = rms_on_reference(ca[0], ca[1], cb[0], cb[1], wa)
                ba = rms_on_reference(cb[0], cb[1], ca[0], ca[1], wa)
                if ab and ba:
                    out.yardsticks.append(Yardstick(metric, ra, rb, (ab[0], ba[0])))
    try:
        out.figure = _validation_figure(out, curves, cache) if figure else None
    except Exception as err:  # a broken file must not stop the report
        out.problems.append(f"{label(run)}: validation figure failed: {err}")
    return out


def _reference_label(reference: str, ds: Dataset | None) -> str:
    title = (ds.provenance.get("title") if ds is not None and ds.provenance else "") or reference
    return f"{title} ({ds.filename if ds is not None else reference})"


def _validation_figure(v: Validation, curves: dict, cache: dict) -> str | None:
    metrics = [m for m in FORCES if m in curves] + [m for m in curves if m not in FORCES]
    data = series(v.run, cache)
    if not metrics or "t" not in data:
        return None
    fig, axes = plt.subplots(len(metrics), 1, figsize=(11.5, 2.9 * len(metrics) + 0.5), sharex=True, squeeze=False)
    markers = ("o", "s", "^", "D")
    twin = series(v.twin, cache) if v.twin is not None else {}
    for ax, metric in zip(axes[:, 0], metrics):
        if metric in data:
            ax.plot(data["t"], data[metric], lw=1.1, color="#1f4e79", label=f"caplab {label(v.run)}")
        if metric in twin:
            ax.plot(twin["t"], twin[metric], lw=1.0, ls="--", color="#ff7f0e", label=f"caplab {label(v.twin)} (uniform twin)")
        for k, (reference, ds, curve, window) in enumerate(curves[metric]):
            ax.plot(curve[0], curve[1], markers[k % len(markers)], ms=2.6, mfc="none", lw=0,
                    color=("#d62728", "#2ca02c", "#9467bd", "#8c564b")[k % 4],
                    label=f"validation: {_reference_label(reference, ds)}")
        window = next((w for _, _, _, w in curves[metric] if w), None)
        if window:
            ax.axvspan(window[0], window[1], color="#d9d9d9", alpha=0.45, lw=0,
                       label=f"scored window {window[0]:.4g}–{window[1]:.4g}")
        ax.set_ylabel({"drag_coefficient": "C_x = C_d", "lift_coefficient": "C_y = C_l"}.get(metric, metric))
        ax.grid(True, lw=0.3, alpha=0.6)
        ax.legend(fontsize=6.5, loc="upper left", bbox_to_anchor=(1.01, 1.0), framealpha=0.85)
    axes[-1, 0].set_xlabel("t U/c")
    fig.suptitle(f"{v.run.case_id} ({v.run.fidelity}): force histories against the reference series", fontsize=9)
    fig.tight_layout()
    return figures.png_data_uri(fig)


# ---- figures of the two-block runs and their twins --------------------------------------------------

@dataclass
class Family:
    """One two-block case (every fidelity run) with its uniform-grid twins: one figure."""

    case_id: str
    title: str
    runs: list[Run]
    twins: list[Run] = field(default_factory=list)
    figure: str | None = None
    caption: str = ""
    problems: list[str] = field(default_factory=list)


def _time_label(run: Run) -> str:
    length = "c" if any((b.get("shape") or {}).get("type") == "ellipse" for b in run.bodies) else "D"
    return f"t U/{length} (Xu & Wang's time scale)"


def _family_figure(family: Family, columns: list[str], proximity: dict | None, cache: dict,
                   t_from: float) -> str | None:
    curves = [(r, series(r, cache), False) for r in family.runs] + [(r, series(r, cache), True) for r in family.twins]
    curves = [(r, d, twin) for r, d, twin in curves if "t" in d]
    if not curves:
        return None
    columns = [c for c in columns if any(c in d for _, d, _ in curves)]
    if not columns:
        return None
    panels = len(columns) + (1 if proximity else 0)
    fig, axes = plt.subplots(panels, 1, figsize=(9.0, 2.6 * panels + 0.6), squeeze=False)
    cmap = plt.get_cmap("tab10")
    fidelities = sorted({r.fidelity for r, _, _ in curves})
    for ax, column in zip(axes[:, 0], columns):
        levels = []
        for r, d, twin in curves:
            if column not in d:
                continue
            color = cmap(fidelities.index(r.fidelity) % 10)
            ax.plot(d["t"], d[column], lw=1.0 if twin else 1.2, ls="--" if twin else "-",
                    color="#ff7f0e" if twin else color, label=f"{'uniform twin' if twin else 'two-block'}: {label(r)}")
            keep = d["t"] >= t_from
            levels += [float(np.nanmin(d[column][keep])), float(np.nanmax(d[column][keep]))] if keep.any() else []
        if proximity and column == f"{proximity.get('body')}.{proximity.get('column', 'drag_coefficient')}":
            _shade_windows(ax, family, proximity, cache)
        period = period_of(family.runs[0]) if family.runs else None
        if period:
            for k in range(1, int(max(d["t"][-1] for _, d, _ in curves) / period + 1e-6) + 1):
                ax.axvline(k * period, color="#888", lw=0.6, ls=":")
        if levels and all(math.isfinite(x) for x in levels):
            lo, hi = min(levels), max(levels)
            pad = 0.06 * max(hi - lo, 1e-9)
            ax.set_ylim(lo - pad, hi + pad)
        ax.set_ylabel(symbol(column))
        ax.set_xlabel(_time_label(family.runs[0] if family.runs else family.twins[0]))
        ax.grid(True, lw=0.3, alpha=0.6)
        ax.legend(fontsize=6.5, loc="best", framealpha=0.85)
    if proximity:
        _proximity_panel(axes[-1, 0], curves, proximity)
    fig.suptitle(f"{family.title}: two-block run against its uniform-grid twin (consistency)", fontsize=9)
    fig.tight_layout()
    return figures.png_data_uri(fig)


def _proximity_windows(proximity: dict) -> list[tuple[str, Interval, str]]:
    out = [("baseline", parse_interval(proximity["baseline"]["dx"]), proximity["baseline"]["phase"])]
    out += [(w.get("name", ""), parse_interval(w["dx"]), w["phase"]) for w in proximity.get("windows", [])]
    return out


WINDOW_COLORS = ("#bdbdbd", "#d62728", "#2ca02c", "#9467bd")


def _shade_windows(ax, family: Family, proximity: dict, cache: dict) -> None:
    """The time spans of the dx windows in the first two-block run (the same for every run: prescribed motion)."""
    run = next((r for r in family.runs if "t" in series(r, cache)), None)
    if run is None:
        return
    d = series(run, cache)
    body, other = proximity.get("body"), proximity.get("other")
    if f"{body}.x" not in d or f"{other}.x" not in d:
        return
    dx = d[f"{body}.x"] - d[f"{other}.x"]
    t_e = encounter_time(d["t"], dx)
    if t_e is None:
        return
    for k, (name, interval, phase) in enumerate(_proximity_windows(proximity)):
        sel = interval.contains(dx) & ((d["t"] < t_e) if phase == "approaching" else (d["t"] > t_e))
        if sel.any():
            ax.axvspan(float(d["t"][sel].min()), float(d["t"][sel].max()), color=WINDOW_COLORS[k % 4], alpha=0.18, lw=0,
                       label=f"{name}: {interval.text}")


def _stretch_around_encounter(t: np.ndarray, dx: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """The samples of the one uninterrupted stretch with lo <= dx <= hi that holds the encounter
    (not an earlier visit of the same range, e.g. during the oscillations before it)."""
    inside = (dx >= lo) & (dx <= hi)
    t_e = encounter_time(t, dx)
    out = np.zeros_like(inside)
    if t_e is None or not inside.any():
        return out
    i = int(np.clip(np.searchsorted(t, t_e), 0, t.size - 1))
    if not inside[i]:
        return out
    a, b = i, i
    while a > 0 and inside[a - 1]:
        a -= 1
    while b < t.size - 1 and inside[b + 1]:
        b += 1
    out[a:b + 1] = True
    return out


def _proximity_panel(ax, curves, proximity: dict) -> None:
    body, other, column = proximity.get("body"), proximity.get("other"), proximity.get("column", "drag_coefficient")
    windows = _proximity_windows(proximity)
    lo = min(w[1].lo for w in windows)
    hi = max(w[1].hi for w in windows)
    margin = 0.15 * (hi - lo)
    for r, d, twin in curves:
        names = [f"{body}.x", f"{other}.x", f"{body}.{column}"]
        if not all(n in d for n in names):
            continue
        dx = d[names[0]] - d[names[1]]
        sel = _stretch_around_encounter(d["t"], dx, lo - margin, hi + margin)
        if not sel.any():
            continue
        ax.plot(dx[sel], d[names[2]][sel], lw=1.0 if twin else 1.2, ls="--" if twin else "-",
                color="#ff7f0e" if twin else "#1f4e79", label=f"{'uniform twin' if twin else 'two-block'}: {label(r)}")
        if not twin:
            prox = proximity_means(d["t"], d[names[0]], d[names[1]], d[names[2]], proximity)
            for k, w in enumerate([prox.baseline] + prox.windows):
                if w.mean is not None:
                    ax.hlines(prox.sign * w.mean, w.interval.lo, w.interval.hi, colors=WINDOW_COLORS[k % 4] if k else "k",
                              lw=2.0, label=f"mean over {w.interval.text}: {w.mean:.3g}")
    for k, (name, interval, phase) in enumerate(windows):
        ax.axvspan(interval.lo, interval.hi, color=WINDOW_COLORS[k % 4], alpha=0.18, lw=0)
    ax.invert_xaxis()  # dx falls with time: time runs left to right
    ax.set_xlabel(f"dx = x_{body} − x_{other} (D); the cylinders are abreast at dx = 0")
    ax.set_ylabel(symbol(f"{body}.{column}"))
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(fontsize=6.5, loc="best", framealpha=0.85)


# ---- the chapter's moving-body section ---------------------------------------------------------------

@dataclass
class Moving:
    runs: list[Run] = field(default_factory=list)
    families: list[Family] = field(default_factory=list)
    statements: list[StatementCheck] = field(default_factory=list)
    pairs: list[TwinPair] = field(default_factory=list)
    periodic: list[PeriodicRow] = field(default_factory=list)
    validations: list[Validation] = field(default_factory=list)
    consistency: dict = field(default_factory=dict)   #: provenance.json "consistency" of references/moving
    twin_from: float = 0.0
    not_available: str = ""
    datasets: list = field(default_factory=list)
    problems: list[str] = field(default_factory=list)

    @property
    def present(self) -> bool:
        return bool(self.runs)

    def statements_in(self, group: str) -> list[StatementCheck]:
        return [s for s in self.statements if s.group == group]

    @property
    def tally(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for s in self.statements:
            out[s.verdict] = out.get(s.verdict, 0) + 1
        return out


def build(runs: list[Run], refs: ReferenceLibrary, chapter: str) -> Moving:
    section = Moving(runs=[r for r in runs if is_moving(r)])
    if not section.present:
        return section
    cache: dict = {}
    prov = refs.benchmarks.get(BENCHMARK, {})
    section.consistency = prov.get("consistency") if isinstance(prov.get("consistency"), dict) else {}
    used = {}
    claims = [(ds, c) for ds, c in refs.claims(chapter + ".") if ds.benchmark == BENCHMARK]
    by_file: dict[str, tuple] = {}
    for ds, claim in claims:
        by_file.setdefault(ds.anchor, (ds, []))[1].append(claim)
        used[ds.anchor] = ds
    for ds, file_claims in by_file.values():
        try:
            section.statements += check_statements(file_claims, runs, ds.path, section.consistency, chapter + ".")
        except claims_tool.ClaimsUnavailable as err:
            section.problems.append(f"thesis statements of {ds.rel} not checked: {err}")
            t_from = start_left_out(section.consistency)
            section.statements += [StatementCheck(c, describe(c, t_from), _group(c), verdict="not checked",
                                                  note=str(err)) for c in file_claims]
    section.twin_from = start_left_out(section.consistency)
    twin_claims = [c for _, c in claims if (c.get("check") or {}).get("type") == "twin"]
    proximity = [c for _, c in claims if (c.get("check") or {}).get("type") == "proximity_means"]
    two_block = [r for r in section.runs if refinement(r) != "uniform"]
    validated = {r.case_id for r in section.runs if any(
        isinstance(a, dict) and a.get("comparison") == "time_series" for a in r.case.get("acceptance", []))}
    by_case: dict[str, Family] = {}
    for run in sorted(two_block, key=lambda r: (r.case_id, r.fidelity)):
        if run.case_id in validated:
            continue
        fam = by_case.setdefault(run.case_id, Family(run.case_id, run.title, []))
        fam.runs.append(run)
        twin = twin_of(run, runs)
        if twin is not None and twin.status == "ok":
            fam.twins.append(twin)
    for fam in by_case.values():
        named = [c for c in twin_claims if fam.case_id in (c.get("cases") or [])]
        columns = list(dict.fromkeys(col for c in named for col in c["check"].get("columns", [])))
        if not columns:
            columns = list(dict.fromkeys(col for r in fam.runs + fam.twins for col in force_columns(series(r, cache))))
        prox = next((c["check"] for c in proximity if fam.case_id in (c.get("cases") or [])), None)
        try:
            fam.figure = _family_figure(fam, columns, prox, cache, section.twin_from)
        except Exception as err:  # a broken file must not stop the report
            fam.problems.append(f"figure failed: {err}")
        if fam.figure is None and not fam.problems:
            fam.problems.append("no finished run of this case has a force series in series.h5")
        section.families.append(fam)

    try:
        section.pairs = twin_pairs(two_block, runs, cache, section.twin_from)
        section.periodic = periodic_rows(section.runs, cache, section.consistency)
    except Exception as err:
        section.problems.append(f"moving-body consistency checks failed: {err}")
    drawn = set()  # uniform twins drawn in the figure of their two-block run
    for r in section.runs:
        twin = twin_of(r, runs) if r.case_id in validated and r.status == "ok" else None
        if twin is not None and twin.status == "ok":
            drawn.add((twin.case_id, twin.fidelity))
    for run in sorted(section.runs, key=lambda r: (refinement(r) == "uniform", r.case_id, r.fidelity)):
        if run.case_id in validated:
            v = validation(run, refs, runs, cache, figure=(run.case_id, run.fidelity) not in drawn)
            if v is not None:
                section.validations.append(v)
                section.problems += v.problems
                for row in v.rows:
                    if row.dataset is not None:
                        used[row.dataset.anchor] = row.dataset
    extra = refs.benchmarks.get("extra", {}).get("not_available")
    section.not_available = extra if isinstance(extra, str) else ""
    section.datasets = list(used.values())
    return section
