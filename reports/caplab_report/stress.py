"""Stability maps (``make stress``, DESIGN.md section 8): classification of sweep points, their
accuracy references, the measured boundaries, the theory next to them, and the page.

Input: ``stress.json`` written by scripts/stress (one record per sweep point: the sweep's
declaration from references/stress/sweeps.json, the parameters and the resolved lattice (tau per
block, Mach), caplab's exit code, manifest status and message, the metrics of summary.json, wall
time, and for a diverged run the step, the place, the cause and the series up to the failure).
Output: ``OUT/index.html`` (+ ``index.pdf`` printed by headless Chromium), self-contained.

Classification of a point (``stability_class``, then ``analyse``), in this order:
    input_error   caplab exit code 2: the sweep asked for something caplab rejects (a bug of the
                  sweep file, never a stability verdict);
    failed        timeout, killed, exit code 4 or any status but ok/diverged: neither stable nor
                  unstable, listed as a solver problem;
    unstable      exit code 3 (manifest "diverged"), or a finished run whose classifying metric is
                  not finite or outside the sweep's ``absurd`` bounds (a divergence no guard
                  caught: ``guard_miss``);
    inaccurate    finished, but a criterion's error exceeds its threshold ("stable but inaccurate");
    stable        finished, every criterion with a reference within its threshold.
A criterion compares a metric of summary.json with a reference: ``value`` (a number, e.g. a
thesis bound in references/), or ``sweep`` (the metric of another point of the same sweep: among
the finished points with the same ``group_by`` parameters, and of ``variant`` if given, the one
that minimises or maximises ``choose``, e.g. the lowest-Mach TRT point at the same Reynolds
number). A relative criterion whose reference is below ``min_reference`` in magnitude, or that has
no finished reference point, is "n/a" and does not decide.

The theory (stress_theory.py): for the membrane maps the explicit-coupling stiffness limit
S = U/(G s) < S_crit (tension) and S_b = E_b N_a^2 U/(G s^3) < S_b,crit (bending); for the
fine-block map the kernel reach (the markers must stay two fine spacings inside the block); for
the tau x Mach maps guide lines of constant cell Reynolds number U/nu (lattice units).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import figures, stress_theory  # noqa: E402
from .runs import finite  # noqa: E402

if TYPE_CHECKING:
    from .build import Page

CLASSES = ("stable", "inaccurate", "unstable", "failed", "input_error")
CLASS_LABELS = {"stable": "stable", "inaccurate": "stable but inaccurate", "unstable": "unstable",
                "failed": "failed (not a stability verdict)", "input_error": "input error (sweep bug)"}
#: Marker, colour per class on the maps.
STYLE = {"stable": ("o", "#2ca02c"), "inaccurate": ("s", "#ff9f1c"), "unstable": ("X", "#d62728"),
         "failed": ("^", "#7f7f7f"), "input_error": ("D", "#000000")}
FINISHED = ("stable", "inaccurate")


# ---- parameters of a point ----------------------------------------------------------------------

def param(point: dict, name: str):
    """A parameter of a point by name: an axis, "variant", a physics key, a lattice key, an override path."""
    if name == "variant":
        return point.get("variant")
    for where in ("axes", "physics", "lattice", "overrides"):
        d = point.get(where) or {}
        if name in d:
            return d[name]
    return None


def _key(v):
    if isinstance(v, float):
        return float(f"{v:.6g}")
    if isinstance(v, list):
        return tuple(_key(x) for x in v)
    return v


# ---- stability ------------------------------------------------------------------------------------

def stability_class(point: dict, sweep: dict) -> tuple[str, str, bool]:
    """(class before accuracy: finished | unstable | failed | input_error, reason, guard_miss)."""
    code = point.get("exit_code")
    status = point.get("status")
    if code == 2:
        return "input_error", (point.get("message") or "caplab rejected the input (exit code 2)"), False
    if point.get("timed_out"):
        return "failed", f"killed after the time limit of {point.get('timeout_s', '?')} s", False
    if code == 3 or status == "diverged":
        if code not in (3, None):
            return "failed", f"manifest says diverged but caplab exited {code} (expected 3)", False
        return "unstable", point.get("message") or "exit code 3", False
    if code not in (0, 1):
        what = f"killed by signal {-code}" if isinstance(code, int) and code < 0 else f"exit code {code}"
        return "failed", f"{what}: {point.get('message') or 'no message'}", False
    if status != "ok":
        return "failed", f"exit code {code} but manifest status {status!r}", False
    metrics = point.get("metrics") or {}
    names = [c["metric"] for c in sweep.get("criteria", [])] + list((sweep.get("absurd") or {}).keys())
    for name in dict.fromkeys(names):
        if name not in metrics:
            return "failed", f"finished, but summary.json has no metric {name!r}", False
        v = metrics[name]
        if isinstance(v, str):
            continue
        if v is None or not finite(v):
            return "unstable", f"finished with exit code {code}, but {name} = {v}: a divergence no guard caught", True
    for name, (lo, hi) in (sweep.get("absurd") or {}).items():
        v = metrics.get(name)
        if finite(v) and not (lo <= v <= hi):
            return ("unstable", f"finished with exit code {code}, but {name} = {v:.4g} is outside the plausible "
                    f"range [{lo:g}, {hi:g}]: a divergence no guard caught", True)
    return "finished", "", False


def _reference_point(point: dict, candidates: list[dict], ref: dict) -> dict | None:
    group = ref.get("group_by", [])
    mine = tuple(_key(param(point, g)) for g in group)
    pool = [c for c in candidates
            if tuple(_key(param(c, g)) for g in group) == mine
            and (ref.get("variant") is None or c.get("variant") == ref["variant"])
            and finite(param(c, ref["choose"][0]))]
    if "at" in ref:  # a fixed value of the chosen parameter
        pool = [c for c in pool if _key(param(c, ref["choose"][0])) == _key(ref["at"])]
    if not pool:
        return None
    key = lambda c: float(param(c, ref["choose"][0]))  # noqa: E731
    return min(pool, key=key) if ref["choose"][1] == "min" else max(pool, key=key)


def evaluate_criterion(point: dict, crit: dict, finished: list[dict]) -> dict:
    """{metric, value, reference, reference_point, error, threshold, passed (True/False/None), note}."""
    ref = crit["reference"]
    out = {"metric": crit["metric"], "comparison": crit["comparison"], "threshold": crit["threshold"],
           "value": (point.get("metrics") or {}).get(crit["metric"]), "reference": None,
           "reference_point": None, "error": None, "passed": None, "note": ""}
    if ref["kind"] == "value":
        out["reference"] = ref["value"]
    else:
        rp = _reference_point(point, finished, ref)
        if rp is None:
            out["note"] = "no finished reference point"
            return out
        out["reference"] = (rp.get("metrics") or {}).get(crit["metric"])
        out["reference_point"] = rp.get("key")
    v, r = out["value"], out["reference"]
    if not finite(v) or not finite(r):
        out["note"] = "metric or reference not a number"
        return out
    if crit["comparison"] == "relative":
        if abs(r) < crit.get("min_reference", 0.0) or r == 0:
            out["note"] = f"|reference| = {abs(r):.3g} below {crit.get('min_reference', 0.0):g}: relative error not meaningful"
            return out
        out["error"] = abs(v - r) / abs(r)
    else:
        out["error"] = abs(v - r)
    out["passed"] = out["error"] <= crit["threshold"] * (1 + 1e-9)  # at the threshold passes
    return out


def analyse(sweep: dict) -> dict:
    """Classifies every point of ``sweep`` in place (keys class, reason, guard_miss, criteria,
    error, theory) and returns the sweep."""
    points = sweep.get("points", [])
    for p in points:
        cls, reason, miss = stability_class(p, sweep)
        p["class"], p["reason"], p["guard_miss"] = cls, reason, miss
    finished = [p for p in points if p["class"] == "finished"]
    for p in points:
        p["criteria"] = []
        p["error"] = None
        if p["class"] != "finished":
            continue
        results = [evaluate_criterion(p, c, finished) for c in sweep.get("criteria", [])]
        p["criteria"] = results
        p["error"] = results[0]["error"] if results else None
        failed = [r for r in results if r["passed"] is False]
        p["class"] = "inaccurate" if failed else "stable"
        if failed:
            p["reason"] = "; ".join(f"{r['metric']} error {fmt_error(r)} above {fmt_threshold(r)}" for r in failed)
    for p in points:
        p["theory"] = point_theory(p, sweep)
    return sweep


def fmt_error(r: dict) -> str:
    if r.get("error") is None:
        return "–"
    return f"{100 * r['error']:.2f} %" if r["comparison"] == "relative" else f"{r['error']:.3g}"


def fmt_threshold(r: dict) -> str:
    return f"{100 * r['threshold']:g} %" if r["comparison"] == "relative" else f"{r['threshold']:g}"


# ---- theory per point -----------------------------------------------------------------------------

def point_theory(point: dict, sweep: dict) -> dict | None:
    kind = (sweep.get("theory") or {}).get("kind")
    phys = dict(point.get("physics") or {})
    if kind == "explicit_coupling":
        return stress_theory.explicit_numbers(phys)
    if kind == "cell_reynolds":
        u, tau = phys.get("lattice_velocity"), phys.get("tau_fine")
        if finite(u) and finite(tau):
            return {"cell_reynolds_fine": 3 * u / (tau - 0.5),
                    "cell_reynolds_coarse": 3 * u / (phys["tau_coarse"] - 0.5) if finite(phys.get("tau_coarse")) else None}
    if kind == "kernel_reach":
        return {"reach": sweep["theory"].get("reach_spacings", 2.0) * phys.get("fine_spacing", math.nan),
                "distance": param(point, sweep["theory"].get("axis", "distance"))}
    return None


def theory_at(point: dict, sweep: dict, axis: dict, value: float) -> dict | None:
    """The explicit-coupling numbers of ``point`` with the parameter of ``axis`` set to ``value``."""
    phys = dict(point.get("physics") or {})
    if axis["kind"] == "marker_spacing":
        phys["nodes"] = 2 * math.pi * (0.5 * phys["diameter"] / phys["fine_spacing"]) / value
    elif axis.get("physics_key"):
        phys[axis["physics_key"]] = value
    else:
        return None
    return stress_theory.explicit_numbers(phys)


def theory_crossing(point: dict, sweep: dict, axis: dict, lo: float, hi: float, key: str = "ratio") -> float | None:
    """Value of ``axis`` in [lo, hi] (log-spaced search) where the predicted ratio ``key``
    (ratio_viscous: bound (i); ratio_inertial: bound (ii'); ratio: the stricter) is 1."""
    if lo <= 0 or hi <= 0:
        return None
    xs = np.geomspace(lo, hi, 61)
    r = []
    for x in xs:
        t = theory_at(point, sweep, axis, float(x))
        r.append(t[key] if t else math.nan)
    r = np.log(np.asarray(r))
    for i in range(len(xs) - 1):
        if np.isfinite(r[i]) and np.isfinite(r[i + 1]) and (r[i] - 0) * (r[i + 1] - 0) <= 0 and r[i] != r[i + 1]:
            f = r[i] / (r[i] - r[i + 1])
            return float(math.exp(math.log(xs[i]) + f * (math.log(xs[i + 1]) - math.log(xs[i]))))
    return None


# ---- divergence onset -------------------------------------------------------------------------------

def onset(t, columns: dict, dt_coarse: float, caught_step, factor: float = 5.0) -> dict:
    """When the series started to run away, against the step the guard stopped the run.

    For each column the sample-to-sample change |dx| is compared with its median over the first
    half of the finite samples; the onset is the first sample of the final run of changes above
    ``factor`` times that median (the earliest over the columns). Fewer than 8 samples, or a series
    without such a final run (the divergence grew within the last sampling interval), give no onset."""
    t = np.asarray(t, dtype=float)
    out = {"samples": int(t.size), "onset_t": None, "onset_step": None, "caught_step": caught_step,
           "delay_steps": None, "column": None, "note": ""}
    if t.size < 8:
        out["note"] = f"{t.size} sample(s) before the failure: divergence within the first sampling intervals"
        return out
    best = None
    for name, x in columns.items():
        x = np.asarray(x, dtype=float)
        n = int(np.argmax(~np.isfinite(x))) if not np.all(np.isfinite(x)) else x.size
        if n < 8:
            continue
        d = np.abs(np.diff(x[:n]))
        base = float(np.median(d[: max(3, d.size // 2)]))
        scale = max(base, 1e-12 * max(1.0, float(np.max(np.abs(x[:n])))))
        big = d > factor * scale
        if not big[-1]:
            continue
        i = d.size - 1
        while i > 0 and big[i - 1]:
            i -= 1
        if best is None or t[i] < best[0]:
            best = (float(t[i]), name)
    if best is None:
        out["note"] = "no run-away visible in the sampled series: it grew within the last sampling interval"
        return out
    out["onset_t"], out["column"] = best
    if finite(dt_coarse) and dt_coarse > 0:
        out["onset_step"] = int(round(best[0] / dt_coarse))
        if isinstance(caught_step, (int, float)):
            out["delay_steps"] = int(caught_step - out["onset_step"])
    return out


# ---- boundaries -----------------------------------------------------------------------------------

def _axes_of(sweep: dict) -> list[dict]:
    return [a for a in sweep.get("axes", []) if len(a.get("values", [])) > 0]


def lines_along(sweep: dict, variant: str, along: dict) -> list[tuple[dict, list[dict]]]:
    """Points of ``variant`` grouped into lines along axis ``along`` (other axes fixed), sorted."""
    others = [a for a in _axes_of(sweep) if a["name"] != along["name"]]
    groups: dict[tuple, list[dict]] = {}
    for p in sweep.get("points", []):
        if p.get("variant") != variant:
            continue
        k = tuple(_key(p["axes"].get(a["name"])) for a in others)
        groups.setdefault(k, []).append(p)
    out = []
    for k, pts in sorted(groups.items(), key=lambda kv: tuple(x if x is not None else 0 for x in kv[0])):
        fixed = {a["name"]: v for a, v in zip(others, k)}
        out.append((fixed, sorted(pts, key=lambda p: p["axes"][along["name"]])))
    return out


def transitions(points: list[dict], axis: str) -> list[dict]:
    """Neighbouring pairs along a line where stability changes (finished <-> unstable)."""
    out = []
    seq = [p for p in points if p["class"] in FINISHED + ("unstable",)]
    for a, b in zip(seq, seq[1:]):
        sa, sb = a["class"] in FINISHED, b["class"] in FINISHED
        if sa != sb:
            stable, unstable = (a, b) if sa else (b, a)
            out.append({"stable": stable["axes"][axis], "unstable": unstable["axes"][axis],
                        "stable_key": stable["key"], "unstable_key": unstable["key"]})
    return out


def ranges(points: list[dict], axis: str, classes: tuple[str, ...]) -> list[tuple[float, float]]:
    """Contiguous runs of points (along ``axis``) whose class is in ``classes``."""
    out, cur = [], None
    for p in points:
        if p["class"] in ("failed", "input_error"):
            continue
        if p["class"] in classes:
            v = p["axes"][axis]
            cur = [v, v] if cur is None else [cur[0], v]
        elif cur is not None:
            out.append(tuple(cur))
            cur = None
    if cur is not None:
        out.append(tuple(cur))
    return out


def fmt_value(v, axis: dict | None = None) -> str:
    if v is None:
        return "–"
    if isinstance(v, str):
        return v
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(fmt_value(x) for x in v) + "]"
    if not finite(v):
        return str(v)
    return f"{v:.4g}"


def _range_text(rs, axis) -> str:
    sym = axis.get("symbol", axis["name"])
    parts = []
    for lo, hi in rs:
        parts.append(f"{sym} = {fmt_value(lo)}" if lo == hi else f"{fmt_value(lo)} ≤ {sym} ≤ {fmt_value(hi)}")
    return " and ".join(parts) if parts else "nowhere"


def region_statements(sweep: dict) -> dict[str, list[str]]:
    """Per variant, the stable region in words: one sentence per line along the boundary axis."""
    axes = _axes_of(sweep)
    along = next((a for a in axes if a["name"] == sweep.get("boundary_axis")), axes[0])
    out = {}
    for v in variant_ids(sweep):
        sentences = []
        for fixed, pts in lines_along(sweep, v, along):
            if not pts:
                continue
            head = ", ".join(f"{next(a for a in axes if a['name'] == k).get('symbol', k)} = {fmt_value(x)}"
                             for k, x in fixed.items())
            stable = ranges(pts, along["name"], FINISHED)
            accurate = ranges(pts, along["name"], ("stable",))
            tr = transitions(pts, along["name"])
            s = (f"{head + ': ' if head else ''}stable for {_range_text(stable, along)}; accurate for "
                 f"{_range_text(accurate, along)}")
            if tr:
                s += "; boundary between " + ", ".join(
                    f"{fmt_value(t['stable'])} (stable) and {fmt_value(t['unstable'])} (unstable)" for t in tr)
            bad = [p for p in pts if p["class"] in ("failed", "input_error")]
            if bad:
                s += f"; {len(bad)} point(s) failed without a stability verdict"
            sentences.append(s + ".")
        out[v] = sentences
    return out


def theory_comparison(sweep: dict) -> list[dict]:
    """Rows: per variant and line along the boundary axis, measured bracket vs predicted value."""
    kind = (sweep.get("theory") or {}).get("kind")
    axes = _axes_of(sweep)
    if not axes:
        return []
    along = next((a for a in axes if a["name"] == sweep.get("boundary_axis")), axes[0])
    rows = []
    for v in variant_ids(sweep):
        for fixed, pts in lines_along(sweep, v, along):
            if not pts:
                continue
            tr = transitions(pts, along["name"])
            row = {"variant": variant_label(sweep, v), "fixed": ", ".join(
                f"{next(a for a in axes if a['name'] == k).get('symbol', k)} = {fmt_value(x)}" for k, x in fixed.items()),
                   "measured": "; ".join(f"between {fmt_value(t['unstable'])} (unstable) and {fmt_value(t['stable'])} "
                                         f"(stable)" for t in tr) or "no transition in the range swept",
                   "predicted": "–", "agreement": "–"}
            pred = None
            if kind == "cell_reynolds" and tr:
                by_key = {p["key"]: p for p in pts}
                cell = lambda k: (by_key[k].get("theory") or {}).get("cell_reynolds_fine")  # noqa: E731
                row["measured"] += " — U/ν_f " + "; ".join(
                    f"{fmt_value(cell(t['stable_key']))} (stable), {fmt_value(cell(t['unstable_key']))} (unstable)" for t in tr)
            if kind == "explicit_coupling":
                vals = [p["axes"][along["name"]] for p in pts]
                lo, hi = min(vals) / 30, max(vals) * 30
                sym = along.get("symbol", along["name"])
                preds = {k: theory_crossing(pts[0], sweep, along, lo, hi, k) for k in ("ratio_viscous", "ratio_inertial")}
                row["predicted"] = "; ".join(f"{label}: {sym} = {preds[k]:.3g}" for k, label in
                                             (("ratio_viscous", "(i)"), ("ratio_inertial", "(ii′)")) if preds[k] is not None) or "–"
                by_key = {p["key"]: p for p in pts}
                elu = lambda k: (by_key[k].get("theory") or {}).get("E_B_lu" if "bending" in along["name"] else "E_lu")  # noqa: E731
                if tr:
                    row["measured"] += (" — E_B,lu " if "bending" in along["name"] else " — E_lu = νU/G ") + "; ".join(
                        f"{fmt_value(elu(t['unstable_key']))} (unstable), {fmt_value(elu(t['stable_key']))} (stable)" for t in tr)
                agree = []
                for k, label in (("ratio_viscous", "(i)"), ("ratio_inertial", "(ii′)")):
                    if preds[k] is not None and tr:
                        agree.append(f"{label} {bracket_agreement(preds[k], tr[0])}")
                row["agreement"] = "; ".join(agree) or "–"
            elif kind == "kernel_reach":
                pred = kernel_reach_prediction(sweep, v)
                if pred is not None:
                    row["predicted"] = f"{along.get('symbol', along['name'])} = {pred:.3g}"
            if pred is not None and tr:
                row["agreement"] = bracket_agreement(pred, tr[0])
            rows.append(row)
    return rows


def separating_constant(sweeps: list[dict], key: str) -> dict | None:
    """Whether one value of the theory quantity ``key`` (e.g. E_lu = nu U/G, or S = U/(G s))
    separates stable from unstable on every measured transition of ``sweeps`` (along their
    boundary axes): (largest value at a stable neighbour, smallest at an unstable one). Only the
    transitions where the unstable neighbour has the larger value count (the mechanism the quantity
    measures); the others (e.g. a soft capsule leaving a small fine block) are counted apart."""
    stable_vals, unstable_vals, n, other = [], [], 0, 0
    for sweep in sweeps:
        axes = _axes_of(sweep)
        if not axes:
            continue
        along = next((a for a in axes if a["name"] == sweep.get("boundary_axis")), axes[0])
        for v in variant_ids(sweep):
            for _, pts in lines_along(sweep, v, along):
                by_key = {p["key"]: p for p in pts}
                for tr in transitions(pts, along["name"]):
                    s = (by_key[tr["stable_key"]].get("theory") or {}).get(key)
                    u = (by_key[tr["unstable_key"]].get("theory") or {}).get(key)
                    if finite(s) and finite(u):
                        if u <= s:
                            other += 1
                            continue
                        stable_vals.append(s)
                        unstable_vals.append(u)
                        n += 1
    if not n:
        return None
    lo, hi = max(stable_vals), min(unstable_vals)
    return {"key": key, "transitions": n, "stable_max": lo, "unstable_min": hi, "separates": lo < hi,
            "other_transitions": other}


def bracket_agreement(pred: float, t: dict) -> str:
    lo, hi = sorted((t["stable"], t["unstable"]))
    if lo <= pred <= hi:
        return "inside the measured bracket"
    mid = math.sqrt(lo * hi) if lo > 0 else 0.5 * (lo + hi)
    return f"predicted / measured = {pred / mid:.2g}" if mid else "–"


def kernel_reach_prediction(sweep: dict, variant: str) -> float | None:
    """Closest distance from the capsule centre to a fine-block face at which the deformed
    membrane (ellipse with the reference point's D_xy and inclination, area pi a^2) keeps its
    kernel stencil inside: extent + reach_spacings * h_f (+ h_f for the ghost layer)."""
    th = sweep.get("theory") or {}
    pts = [p for p in sweep.get("points", []) if p.get("variant") == variant and p["class"] in FINISHED]
    if not pts:
        return None
    axis = th.get("axis", "distance")
    far = max(pts, key=lambda p: p["axes"][axis])
    m = far.get("metrics") or {}
    d, theta = m.get("taylor_deformation_mean"), m.get("inclination_mean")
    a = 0.5 * far["physics"]["diameter"]
    h = far["physics"]["fine_spacing"]
    if not finite(d) or not finite(theta):
        return None
    L = a * math.sqrt((1 + d) / (1 - d))
    B = a * a / L
    ext_x = math.sqrt((L * math.cos(theta)) ** 2 + (B * math.sin(theta)) ** 2)
    ext_y = math.sqrt((L * math.sin(theta)) ** 2 + (B * math.cos(theta)) ** 2)
    ext = ext_x if th.get("direction", "x") == "x" else max(ext_x, ext_y)
    return ext + (th.get("reach_spacings", 2.0) + 1.0) * h


# ---- figures ----------------------------------------------------------------------------------------

def variant_ids(sweep: dict) -> list[str]:
    vs = [v["id"] for v in sweep.get("variants", [])] or [None]
    return vs


def variant_label(sweep: dict, vid) -> str:
    for v in sweep.get("variants", []):
        if v["id"] == vid:
            return v.get("label", vid)
    return vid or ""


def _axis_coord(axis: dict, values):
    values = np.asarray(values, dtype=float)
    return values - 0.5 if axis.get("scale") == "log_minus_half" else values


def _setup_axis(ax, axis: dict, which: str):
    scale = axis.get("scale", "linear")
    setter = ax.set_xscale if which == "x" else ax.set_yscale
    setter("log" if scale in ("log", "log_minus_half") else "linear")
    label = axis.get("label", axis["name"])
    (ax.set_xlabel if which == "x" else ax.set_ylabel)(label, fontsize=8)
    if scale == "log_minus_half":
        vals = np.asarray(axis["values"], dtype=float)
        ticks = vals - 0.5
        (ax.set_xticks if which == "x" else ax.set_yticks)(ticks)
        (ax.set_xticklabels if which == "x" else ax.set_yticklabels)([f"{v:g}" for v in vals], fontsize=7,
                                                                       rotation=45 if which == "x" else 0)
        (ax.xaxis if which == "x" else ax.yaxis).set_minor_locator(matplotlib.ticker.NullLocator())


def map_figure(sweep: dict) -> str | None:
    axes = _axes_of(sweep)
    if not sweep.get("points"):
        return None
    variants = variant_ids(sweep)
    if len(axes) == 1:
        return line_figure(sweep, axes[0], variants)
    ax_x, ax_y = axes[0], axes[1]
    n = len(variants)
    fig, panels = plt.subplots(1, n, figsize=(min(5.2 * n, 11.5), 4.3), squeeze=False, sharey=True)
    for panel, vid in zip(panels[0], variants):
        pts = [p for p in sweep["points"] if p.get("variant") == vid]
        for cls in CLASSES:
            sel = [p for p in pts if p["class"] == cls]
            if not sel:
                continue
            mk, col = STYLE[cls]
            panel.scatter(_axis_coord(ax_x, [p["axes"][ax_x["name"]] for p in sel]),
                          _axis_coord(ax_y, [p["axes"][ax_y["name"]] for p in sel]),
                          marker=mk, c=col, s=46, edgecolors="k", linewidths=0.4, label=CLASS_LABELS[cls], zorder=3)
        _draw_boundary(panel, pts, ax_x, ax_y)
        _draw_theory(panel, sweep, pts, ax_x, ax_y)
        _setup_axis(panel, ax_x, "x")
        _setup_axis(panel, ax_y, "y")
        _secondary(panel, sweep, ax_x, ax_y)
        panel.set_title(variant_label(sweep, vid) or sweep["title"], fontsize=9)
        panel.grid(True, which="both", lw=0.3, alpha=0.5)
    handles, labels = [], []
    for panel in panels[0]:
        for h, l in zip(*panel.get_legend_handles_labels()):
            if l not in labels:
                handles.append(h)
                labels.append(l)
    fig.legend(handles, labels, loc="lower center", ncol=min(4, len(labels)), fontsize=7, frameon=False)
    fig.suptitle(sweep["title"], fontsize=10)
    fig.tight_layout(rect=(0, 0.1 + 0.03 * (len(labels) > 4), 1, 1))
    return figures.png_data_uri(fig)


def _grid(pts, ax_x, ax_y, value):
    xs = sorted({p["axes"][ax_x["name"]] for p in pts})
    ys = sorted({p["axes"][ax_y["name"]] for p in pts})
    Z = np.full((len(ys), len(xs)), np.nan)
    for p in pts:
        v = value(p)
        if v is not None:
            Z[ys.index(p["axes"][ax_y["name"]]), xs.index(p["axes"][ax_x["name"]])] = v
    return xs, ys, Z


def _draw_boundary(panel, pts, ax_x, ax_y):
    """Measured boundaries: contour 1/2 of the indicator (finished = 1, unstable = 0) and, dashed,
    of accurate (stable = 1, else 0), in the plotting coordinates of the axes."""
    if len(pts) < 4:
        return
    xs, ys, Z = _grid(pts, ax_x, ax_y, lambda p: {"stable": 1.0, "inaccurate": 1.0, "unstable": 0.0}.get(p["class"]))
    _, _, A = _grid(pts, ax_x, ax_y, lambda p: {"stable": 1.0, "inaccurate": 0.0, "unstable": 0.0}.get(p["class"]))
    if len(xs) < 2 or len(ys) < 2:
        return
    X, Y = np.meshgrid(_axis_coord(ax_x, xs), _axis_coord(ax_y, ys))
    logx = ax_x.get("scale", "linear") != "linear"
    logy = ax_y.get("scale", "linear") != "linear"
    # Contour in index-like coordinates (log where the axis is log) so that the line sits halfway.
    CX = np.log(X) if logx else X
    CY = np.log(Y) if logy else Y
    for data, style, label in ((Z, "-", "measured stability boundary"), (A, "--", "measured accuracy boundary")):
        if np.nanmin(data) == np.nanmax(data) or np.isnan(data).all():
            continue
        try:
            cs = plt.contour(CX, CY, np.ma.masked_invalid(data), levels=[0.5])
        except (ValueError, TypeError):
            continue
        first = True
        for seg in cs.allsegs[0]:
            sx = np.exp(seg[:, 0]) if logx else seg[:, 0]
            sy = np.exp(seg[:, 1]) if logy else seg[:, 1]
            panel.plot(sx, sy, style, color="#444444" if style == "-" else "#ff9f1c", lw=1.4,
                       label=label if first else None, zorder=2)
            first = False
        for coll in cs.collections:
            coll.remove()


def _draw_theory(panel, sweep, pts, ax_x, ax_y):
    th = sweep.get("theory") or {}
    kind = th.get("kind")
    if kind == "explicit_coupling":
        along = ax_x if sweep.get("boundary_axis") == ax_x["name"] else ax_y
        other = ax_y if along is ax_x else ax_x
        for key, style, colour, label in (
                ("ratio_viscous", ":", "#1f4e79", "predicted limit (i), viscous: S = S_crit"),
                ("ratio_inertial", "-.", "#7b3294", "predicted limit (ii′), lattice inertial: E_lu = E_crit")):
            line = []
            for ov in sorted({p["axes"][other["name"]] for p in pts}):
                line_pts = [p for p in pts if p["axes"][other["name"]] == ov]
                vals = [p["axes"][along["name"]] for p in line_pts]
                c = theory_crossing(line_pts[0], sweep, along, min(vals) / 30, max(vals) * 30, key)
                if c is not None:
                    line.append((c, ov) if along is ax_x else (ov, c))
            if line:
                line.sort(key=lambda xy: xy[1] if along is ax_x else xy[0])
                panel.plot(_axis_coord(ax_x, [x for x, _ in line]), _axis_coord(ax_y, [y for _, y in line]), style,
                           color=colour, lw=1.8, marker="+", ms=8, label=label, zorder=2)
    elif kind == "cell_reynolds":
        # Ma = Re_cell * umax * (tau - 1/2) / sqrt(3): straight lines in (tau - 1/2, Ma), log-log.
        umax = next((p["physics"].get("max_speed") for p in pts if p.get("physics")), 1.0) or 1.0
        tx = np.geomspace(min(ax_x["values"]) - 0.5, max(ax_x["values"]) - 0.5, 50)
        ylo, yhi = min(ax_y["values"]), max(ax_y["values"])
        for k, rc in enumerate(th.get("lines", [])):
            ma = rc * umax * tx / math.sqrt(3)
            keep = (ma >= ylo / 1.5) & (ma <= yhi * 1.5)
            if keep.any():
                panel.plot(tx[keep], ma[keep], ":", color="#1f4e79", lw=1.0,
                           label="guide: cell Reynolds number U/ν_f = const" if k == 0 else None, zorder=1)
                j = np.flatnonzero(keep)[-1]
                panel.annotate(f"U/ν={rc:g}", (tx[j], ma[j]), fontsize=6, color="#1f4e79")


def _secondary(panel, sweep, ax_x, ax_y):
    """Physical-terms axis: tau_c for a tau_f axis (two-level grids), Re or U for the others."""
    sec = sweep.get("secondary_axis")
    if not sec:
        return
    if sec == "tau_coarse" and ax_x.get("scale") == "log_minus_half":
        top = panel.secondary_xaxis("top", functions=(lambda x: x / 2, lambda x: 2 * x))
        top.set_xlabel("τ_c − ½ (coarse block)", fontsize=7)
        top.tick_params(labelsize=6)


def line_figure(sweep: dict, axis: dict, variants) -> str:
    metric = sweep["criteria"][0]["metric"] if sweep.get("criteria") else None
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10.5, 3.8))
    th = sweep.get("theory") or {}
    for k, vid in enumerate(variants):
        pts = sorted([p for p in sweep["points"] if p.get("variant") == vid], key=lambda p: p["axes"][axis["name"]])
        lab = variant_label(sweep, vid)
        xs = [p["axes"][axis["name"]] for p in pts]
        vals = [(p.get("metrics") or {}).get(metric) if p["class"] in FINISHED else None for p in pts]
        ok = [(x, v) for x, v in zip(xs, vals) if finite(v)]
        if ok:
            ax1.plot([x for x, _ in ok], [v for _, v in ok], "-", color=f"C{k}", lw=0.8, label=lab or None)
        for p, x, v in zip(pts, xs, vals):
            mk, col = STYLE[p["class"]]
            y = v if finite(v) else (min([vv for _, vv in ok]) if ok else 0.0)
            ax1.scatter([x], [y], marker=mk, c=col, s=46, edgecolors="k", linewidths=0.4, zorder=3)
            th_p = p.get("theory") or {}
            if finite(th_p.get("ratio_viscous")):
                ax2.scatter([x], [th_p["ratio_viscous"]], marker=mk, c=col, s=46, edgecolors="k", linewidths=0.4, zorder=3)
            if finite(th_p.get("ratio_inertial")):
                ax2.scatter([x], [th_p["ratio_inertial"]], marker="v", facecolors="none", edgecolors=col, s=40,
                            linewidths=1.2, zorder=3)
        if th.get("kind") == "kernel_reach":
            d = kernel_reach_prediction(sweep, vid)
            if d is not None:
                ax1.axvline(d, color=f"C{k}", ls=":", lw=1.5, label=f"predicted reach limit ({lab})" if lab else "predicted reach limit")
    for cls in CLASSES:
        if any(p["class"] == cls for p in sweep["points"]):
            mk, col = STYLE[cls]
            ax1.scatter([], [], marker=mk, c=col, edgecolors="k", linewidths=0.4, label=CLASS_LABELS[cls])
    for ax in (ax1, ax2):
        ax.set_xscale("log" if axis.get("scale") == "log" else "linear")
        ax.set_xlabel(axis.get("label", axis["name"]), fontsize=8)
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax1.set_ylabel(f"{metric} (finished points)", fontsize=8)
    ax1.legend(fontsize=6)
    if th.get("kind") == "explicit_coupling":
        ax2.axhline(1.0, color="#1f4e79", ls=":", lw=2, label="predicted limit: ratio = 1")
        ax2.scatter([], [], marker="o", c="#bbbbbb", edgecolors="k", label="(i) S/S_crit (filled, class colour)")
        ax2.scatter([], [], marker="v", facecolors="none", edgecolors="#444444", label="(ii′) E_lu/E_crit (open)")
        ax2.set_yscale("log")
        ax2.set_ylabel("predicted ratio (theory)", fontsize=8)
        ax2.legend(fontsize=6)
    else:
        vals = [(p.get("criteria") or [{}])[0].get("error") for p in sweep["points"]]
        for p in sweep["points"]:
            e = (p.get("criteria") or [{}])[0].get("error") if p.get("criteria") else None
            if finite(e):
                mk, col = STYLE[p["class"]]
                ax2.scatter([p["axes"][axis["name"]]], [max(e, 1e-6)], marker=mk, c=col, s=46, edgecolors="k", linewidths=0.4)
        if any(finite(v) for v in vals):
            ax2.set_yscale("log")
            ax2.axhline(sweep["criteria"][0]["threshold"], color="#ff9f1c", ls="--", lw=1.2, label="inaccuracy threshold")
            ax2.legend(fontsize=6)
        ax2.set_ylabel(f"error of {metric}", fontsize=8)
    fig.suptitle(sweep["title"], fontsize=10)
    fig.tight_layout()
    return figures.png_data_uri(fig)


def divergence_figure(point: dict) -> str | None:
    s = point.get("series") or {}
    t = s.get("t")
    cols = {k: v for k, v in s.items() if k != "t"}
    if not t or not cols:
        return None
    fig, axes = plt.subplots(1, len(cols), figsize=(3.2 * len(cols), 2.3), squeeze=False)
    on = point.get("onset") or {}
    for ax, (name, v) in zip(axes[0], cols.items()):
        y = np.array([x if x is not None else np.nan for x in v], dtype=float)
        ax.plot(t, y, lw=0.9, color="#1f4e79")
        good = y[np.isfinite(y)]
        if good.size > 4:  # keep the axes readable when the last samples run away by orders of magnitude
            lo, hi = np.percentile(good, [2, 98])
            pad = 0.5 * max(hi - lo, 1e-6 * max(1.0, abs(hi)))
            top = min(float(good.max()), hi + 4 * pad)
            bottom = max(float(good.min()), lo - 4 * pad)
            ax.set_ylim(bottom - pad, top + pad)
        ax.yaxis.set_major_locator(matplotlib.ticker.MaxNLocator(4))
        ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(4))
        if on.get("onset_t") is not None:
            ax.axvline(on["onset_t"], color="#ff9f1c", ls="--", lw=1, label="onset (series)")
        dt = (point.get("lattice") or {}).get("dt_coarse")
        step = (point.get("diverged") or {}).get("step")
        if finite(dt) and isinstance(step, (int, float)):
            ax.axvline(step * dt, color="#d62728", ls="-", lw=1, label="stopped by guard")
        ax.set_title(name, fontsize=7)
        ax.tick_params(labelsize=6)
        ax.grid(True, lw=0.3, alpha=0.5)
    axes[0][0].legend(fontsize=6)
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.15, top=0.88, wspace=0.35)
    return figures.png_data_uri(fig)


# ---- the page ---------------------------------------------------------------------------------------

def example_divergences(sweep: dict, n: int = 3) -> list[dict]:
    """A few unstable points with their messages: the earliest, the latest and one in between
    (by the step at which caplab stopped), plus every guard miss."""
    un = [p for p in sweep["points"] if p["class"] == "unstable" and not p.get("guard_miss")]
    un.sort(key=lambda p: ((p.get("diverged") or {}).get("step") or 0))
    picks = []
    if un:
        picks = [un[0]] + ([un[len(un) // 2]] if len(un) > 2 else []) + ([un[-1]] if len(un) > 1 else [])
    picks += [p for p in sweep["points"] if p.get("guard_miss")]
    seen, out = set(), []
    for p in picks:
        if p["key"] not in seen:
            seen.add(p["key"])
            out.append(p)
    return out[: n + 3]


def point_row(p: dict, sweep: dict) -> dict:
    lat = p.get("lattice") or {}
    d = p.get("diverged") or {}
    crit = p.get("criteria") or []
    th = p.get("theory") or {}
    return {
        "key": p["key"], "variant": variant_label(sweep, p.get("variant")),
        "axes": [fmt_value(p["axes"].get(a["name"])) for a in _axes_of(sweep)],
        "reynolds": fmt_value((p.get("physics") or {}).get("reynolds")),
        "u": fmt_value((p.get("physics") or {}).get("lattice_velocity")),
        "tau_f": fmt_value(lat.get("tau_fine")), "tau_c": fmt_value(lat.get("tau_coarse")),
        "mach": fmt_value(lat.get("mach")),
        "cls": p["class"], "label": CLASS_LABELS.get(p["class"], p["class"]),
        "metric": fmt_value(crit[0]["value"]) if crit else "–",
        "errors": "; ".join(f"{r['metric']}: {fmt_error(r)}" + (f" ({r['note']})" if r.get("note") and r.get("error") is None else "")
                            for r in crit) or "–",
        "theory": (f"{th['ratio_viscous']:.3g} / {th['ratio_inertial']:.3g}" if finite(th.get("ratio_viscous")) else
                   f"{th['cell_reynolds_fine']:.3g}" if finite(th.get("cell_reynolds_fine")) else "–"),
        "wall": f"{p['wall_time_s']:.1f}" if finite(p.get("wall_time_s")) else "–",
        "step": fmt_value(d.get("step")) if d else "–",
        "reason": p.get("reason", "") if p["class"] not in FINISHED or p["class"] == "inaccurate" else "",
        "guard_miss": p.get("guard_miss", False),
    }


def sweep_view(sweep: dict) -> dict:
    analyse(sweep)
    counts = {c: sum(1 for p in sweep["points"] if p["class"] == c) for c in CLASSES}
    wall = sum(p.get("wall_time_s") or 0.0 for p in sweep["points"] if not p.get("cached_from_other_sweep"))
    examples = []
    for p in example_divergences(sweep):
        d = p.get("diverged") or {}
        on = p.get("onset") or {}
        examples.append({"row": point_row(p, sweep), "message": p.get("message") or d.get("error") or p.get("reason", ""),
                         "where": d.get("where", ""), "step": d.get("step"), "steps_total": p.get("steps_total"),
                         "onset": on, "figure": divergence_figure(p), "guard_miss": p.get("guard_miss", False),
                         "guard_every": (p.get("physics") or {}).get("guard_every")})
    separation = []
    if (sweep.get("theory") or {}).get("kind") == "explicit_coupling":
        keys = ("E_B_lu", "S_b") if sweep.get("boundary_axis") == "bending_ratio" else ("E_lu", "S")
        separation = [x for x in (separating_constant([sweep], k) for k in keys) if x]
    return {"sweep": sweep, "figure": map_figure(sweep), "counts": counts, "wall": wall, "separation": separation,
            "regions": region_statements(sweep), "comparison": theory_comparison(sweep),
            "rows": [point_row(p, sweep) for p in sorted(sweep["points"], key=lambda p: (str(p.get("variant")),
                     tuple(p["axes"].get(a["name"]) or 0 for a in _axes_of(sweep))))],
            "axes": _axes_of(sweep), "examples": examples,
            "variant_labels": {v: variant_label(sweep, v) for v in variant_ids(sweep)},
            "criteria_text": [criterion_text(c) for c in sweep.get("criteria", [])]}


def criterion_text(c: dict) -> str:
    ref = c["reference"]
    if ref["kind"] == "value":
        r = f"the value {ref['value']:g}" + (f" ({ref['source']})" if ref.get("source") else "")
    else:
        pick = "lowest" if ref["choose"][1] == "min" else "highest"
        r = (f"the finished point of this sweep with the {pick} {ref['choose'][0]}"
             + (f" of variant {ref['variant']}" if ref.get("variant") else "")
             + (f" at the same {', '.join(ref['group_by'])}" if ref.get("group_by") else ""))
    thr = f"{100 * c['threshold']:g} % (relative)" if c["comparison"] == "relative" else f"{c['threshold']:g} (absolute)"
    extra = f"; not applied where |reference| < {c['min_reference']:g}" if c.get("min_reference") else ""
    why = f" — {c['why']}" if c.get("why") else ""
    return f"{c['metric']} against {r}: inaccurate above {thr}{extra}{why}"


def render(data: dict, out: Path) -> str:
    from .build import environment

    views = [sweep_view(s) for s in data.get("sweeps", [])]
    env = environment()
    env.filters["fmtv"] = fmt_value
    tension_2d = [v["sweep"] for v in views if (v["sweep"].get("theory") or {}).get("kind") == "explicit_coupling"
                  and v["sweep"].get("boundary_axis") == "capillary"
                  and all((p.get("physics") or {}).get("dimension") == 2 for p in v["sweep"]["points"])]
    theory = {"tension_table": tension_table(),
              "separation_2d": [x for x in (separating_constant(tension_2d, k) for k in ("E_lu", "S")) if x],
              "tension_2d_ids": [s["id"] for s in tension_2d]}
    totals = {c: sum(v["counts"][c] for v in views) for c in CLASSES}
    build = (data.get("environment") or {}).get("build") or {}
    sha = str(build.get("git_sha", "–"))[:12] + ("+dirty" if build.get("git_dirty") else "")
    meta = {"generated": data.get("generated", "–"), "results": str(out), "report_git_sha": f"{sha}, the caplab build's"}
    return env.get_template("stress.html.j2").render(
        title="caplab — stability maps (make stress)", data=data, views=views, theory=theory, totals=totals,
        total_points=sum(len(v["sweep"]["points"]) for v in views), meta=meta, labels=CLASS_LABELS, root="")


def tension_table() -> list[dict]:
    rows = []
    for s in (0.3, 0.5, 0.79, 1.0, 1.5, 2.0):
        t = stress_theory.tension_limit(s, 1 / 6)
        b = stress_theory.bending_limit(s)
        t3 = stress_theory.tension_limit(s, 1 / 6, 3, "cosine4", 4 / 3)
        li = stress_theory.lattice_inertial_limit(s)
        li3 = stress_theory.lattice_inertial_limit(s, 3, "cosine4", 4 / 3)
        rows.append({"s": s, "S_crit": t["viscous"], "U_over_G": t["viscous"] * s, "inertial": t["inertial"],
                     "wavelength": t["wavelength_h"], "S_b_crit": b["critical"], "S3_crit": t3["critical"],
                     "U_over_G_3d": t3["critical"] * s, "E_crit": li["E_crit"], "E_crit_wavelength": li["wavelength_h"],
                     "E_crit_3d": li3["E_crit"], "E_B_crit": li["E_B_crit"]})
    return rows


def build_page(stress_json: Path, out: Path, pdf: bool = True, chromium: str = "chromium") -> Page:
    from .build import publish

    data = json.loads(Path(stress_json).read_text(encoding="utf-8"))
    out.mkdir(parents=True, exist_ok=True)
    return publish(out, render(data, out), pdf, chromium)
