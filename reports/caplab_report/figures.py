"""Figures of the report, rendered with matplotlib (Agg) to PNG and embedded as data URIs.

- ``time_histories``: every series of series.h5 against t, one panel per quantity, labelled with
  the unit attributes; for each acceptance entry that maps to a series the reference (line for a
  mean or final value, mean +- amplitude for an amplitude, band for a bracket, curve for a
  reference series) with its tolerance band at the run's fidelity; the averaging window shaded.
- ``cost_vs_error``: wall time against relative error per scored metric (DESIGN.md section 7).

Readers shared by the chapter modules: ``read_series`` (series.h5) and ``read_meshes``
(the membrane meshes of snapshots.h5).
"""

from __future__ import annotations

import base64
import io
import math
from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .references import ReferenceLibrary  # noqa: E402
from .runs import Run, finite  # noqa: E402

SUFFIXES = ("_mean", "_amplitude", "_final", "_min", "_max", "_rms")
MAX_POINTS = 20000


@dataclass
class Series:
    name: str
    values: np.ndarray
    unit: str
    definition: str


def _attr(ds, key: str) -> str:
    v = ds.attrs.get(key, "")
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    if isinstance(v, np.ndarray):
        v = " ".join(str(x) for x in v.tolist())
    return str(v)


def read_series(path) -> tuple[Series | None, list[Series], str]:
    """(t, other columns, problem) from series.h5; 1-D datasets at the root of the same length as t."""
    try:
        import h5py
    except ImportError as err:  # pragma: no cover - environment problem
        return None, [], f"h5py not available: {err}"
    try:
        with h5py.File(path, "r") as f:
            if "t" not in f:
                return None, [], "series.h5 has no dataset \"t\""
            t_ds = f["t"]
            t = Series("t", np.asarray(t_ds[()], dtype=float).ravel(), _attr(t_ds, "unit"), _attr(t_ds, "definition"))
            cols = []
            for name in f:
                ds = f[name]
                if name == "t" or not hasattr(ds, "shape") or len(ds.shape) != 1 or ds.shape[0] != t.values.size:
                    continue
                cols.append(Series(name, np.asarray(ds[()], dtype=float), _attr(ds, "unit"), _attr(ds, "definition")))
            return t, cols, ""
    except Exception as err:  # h5py raises many types for a damaged file
        return None, [], f"series.h5 unreadable: {err}"


@dataclass
class Mesh:
    """One Lagrangian mesh of snapshots.h5 at one output time (layout: solver/io/snapshot_writer.hpp)."""

    time: float
    name: str
    points: np.ndarray        #: [N][3] (2D: z = 0)
    connectivity: np.ndarray  #: [M][2] segments (2D ring) or [M][3] triangles


def read_meshes(path) -> tuple[list[Mesh], str]:
    """(meshes sorted by time, problem): every group /step_*/<name> holding "points" and
    "connectivity"; grid blocks (which hold neither) are skipped."""
    try:
        import h5py
    except ImportError as err:  # pragma: no cover - environment problem
        return [], f"h5py not available: {err}"
    meshes: list[Mesh] = []
    try:
        with h5py.File(path, "r") as f:
            for step_name in f:
                step = f[step_name]
                if not step_name.startswith("step_") or not hasattr(step, "keys"):
                    continue
                time = np.asarray(step.attrs.get("time", [np.nan]), dtype=float).ravel()
                for name in step:
                    group = step[name]
                    if not hasattr(group, "keys") or "points" not in group or "connectivity" not in group:
                        continue
                    meshes.append(Mesh(float(time[0]) if time.size else math.nan, name,
                                       np.asarray(group["points"][()], dtype=float),
                                       np.asarray(group["connectivity"][()], dtype=int)))
    except Exception as err:  # h5py raises many types for a damaged file
        return [], f"snapshots.h5 unreadable: {err}"
    meshes.sort(key=lambda m: (m.name, m.time))
    return meshes, "" if meshes else "snapshots.h5 holds no membrane mesh"


def png_data_uri(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def pretty(name: str) -> str:
    return name.replace("_", " ")


def axis_label(s: Series) -> str:
    unit = s.unit.strip()
    if not unit or unit == "1":
        return f"{pretty(s.name)} [-]"
    return f"{pretty(s.name)} [{unit}]"


def series_for_metric(metric: str, names: list[str]) -> tuple[str | None, str]:
    """(series column, statistic) an acceptance metric refers to."""
    if metric in names:
        return metric, "series"
    for suffix in SUFFIXES:
        if metric.endswith(suffix) and metric[: -len(suffix)] in names:
            return metric[: -len(suffix)], suffix[1:]
    return None, ""


def tolerance_at(entry: dict, fidelity: str):
    tol = entry.get("tolerance")
    if isinstance(tol, dict):
        tol = tol.get(fidelity)
    return float(tol) if finite(tol) else None


def band(ref: float, tol, comparison: str):
    if tol is None:
        return None
    half = abs(ref) * tol if comparison == "relative" else tol
    return ref - half, ref + half


def _reference_curve(entry: dict, refs: ReferenceLibrary):
    """(t, value) of a time-series reference, from the entry or its CSV; None if unavailable."""
    rs = entry.get("reference_series")
    if isinstance(rs, dict) and isinstance(rs.get("t"), list) and isinstance(rs.get("value"), list):
        return np.asarray(rs["t"], float), np.asarray(rs["value"], float)
    res = refs.resolve(entry.get("reference"))
    if res.dataset is None:
        return None
    ds = res.dataset
    tcol, _, vcol = res.key.partition(":")
    tcol = tcol or (ds.columns[0] if ds.columns else "")
    vcol = vcol or (ds.columns[1] if len(ds.columns) > 1 else "")
    t, v = ds.column_values(tcol), ds.column_values(vcol)
    if not t or not v:
        return None
    return np.asarray(t), np.asarray(v)


def time_histories(run: Run, refs: ReferenceLibrary) -> tuple[str | None, list[Series], str]:
    """(PNG data URI or None, plotted series for the captions, problem)."""
    path = run.series_path
    if path is None:
        return None, [], "no series.h5 in the run directory"
    t, cols, problem = read_series(path)
    if t is None or not cols:
        return None, [], problem or "series.h5 holds no time series besides t"
    names = [c.name for c in cols]
    entries = {e.get("metric"): e for e in run.entries}
    acceptance = [a for a in run.case.get("acceptance", []) if isinstance(a, dict)]
    avg_from = run.average_from

    fig, axes = plt.subplots(len(cols), 1, figsize=(9.0, 2.5 * len(cols) + 0.6), sharex=True, squeeze=False)
    step = max(1, t.values.size // MAX_POINTS)
    tv = t.values[::step]
    for ax, col in zip(axes[:, 0], cols):
        ax.plot(tv, col.values[::step], lw=0.9, color="#1f4e79", label=f"caplab ({run.fidelity})")
        if avg_from is not None and t.values.size and avg_from < t.values[-1]:
            ax.axvspan(avg_from, t.values[-1], color="#d9d9d9", alpha=0.5, lw=0,
                       label=f"averaging window t ≥ {avg_from:g}")
        window = t.values >= (avg_from if avg_from is not None else -math.inf)
        levels: list[float] = []
        for a in acceptance:
            metric = a.get("metric", "")
            column, stat = series_for_metric(metric, names)
            if column != col.name:
                continue
            scored = entries.get(metric, {})
            comparison = a.get("comparison") or scored.get("comparison") or ""
            tol = tolerance_at(a, run.fidelity)
            ref = a.get("reference_value")
            tag = f"{pretty(metric)}"
            if comparison == "bracket" and isinstance(a.get("bracket"), list) and len(a["bracket"]) == 2:
                lo, hi = (float(x) for x in a["bracket"])
                ax.axhspan(lo, hi, color="#2ca02c", alpha=0.15, lw=0, label=f"{tag}: bracket [{lo:g}, {hi:g}]")
                levels += [lo, hi]
            elif comparison == "time_series" or stat == "series":
                curve = _reference_curve(a, refs)
                if curve is not None:
                    ax.plot(curve[0], curve[1], "o", ms=3, color="#d62728", label=f"reference ({a.get('reference', '')})")
                    levels += [float(x) for x in curve[1] if np.isfinite(x)]
            elif finite(ref):
                ref = float(ref)
                tol_txt = ""
                if tol is not None:
                    tol_txt = f" ± {tol * 100:g} %" if comparison == "relative" else f" ± {tol:g}"
                if stat == "amplitude":
                    vals = col.values[window] if window.any() else col.values
                    centre = float(np.nanmean(vals)) if vals.size else 0.0
                    for sign in (+1, -1):
                        level = centre + sign * ref
                        ax.axhline(level, color="#d62728", ls="--", lw=1.0,
                                   label=f"{tag}: run mean ± reference {ref:g}{tol_txt}" if sign > 0 else None)
                        levels.append(level)
                        b = band(ref, tol, comparison)
                        if b:
                            ax.axhspan(centre + sign * b[0], centre + sign * b[1], color="#d62728", alpha=0.12, lw=0)
                            levels += [centre + sign * b[0], centre + sign * b[1]]
                else:
                    ax.axhline(ref, color="#d62728", ls="--", lw=1.0, label=f"{tag}: reference {ref:g}{tol_txt}")
                    levels.append(ref)
                    b = band(ref, tol, comparison)
                    if b:
                        ax.axhspan(b[0], b[1], color="#d62728", alpha=0.15, lw=0)
                        levels += list(b)
                    value = scored.get("value")
                    if finite(value) and stat == "mean":
                        ax.axhline(float(value), color="#1f4e79", ls=":", lw=1.0, label=f"{tag}: caplab {float(value):.4g}")
        ax.set_ylabel(axis_label(col))
        ax.grid(True, lw=0.3, alpha=0.6)
        ax.legend(loc="best", fontsize=7, framealpha=0.85)
        if avg_from is not None and window.any():
            # Zoom on the developed signal (the start-up transient can be far larger), keeping
            # every reference level and tolerance band in view.
            sel = col.values[window & np.isfinite(col.values)]
            if sel.size:
                lo = min([float(sel.min())] + levels)
                hi = max([float(sel.max())] + levels)
                pad = 0.08 * max(hi - lo, 1e-9 * max(1.0, abs(hi)))
                ax.set_ylim(lo - pad, hi + pad)
    axes[-1, 0].set_xlabel(axis_label(t) if t.unit else "t")
    fig.suptitle(f"{run.case_id} ({run.fidelity}): time histories", fontsize=10)
    fig.tight_layout()
    return png_data_uri(fig), [t] + cols, ""


def cost_vs_error(runs: list[Run]) -> str | None:
    """Wall time against error of every scored relative/absolute entry; None without points."""
    points = []
    for run in runs:
        wall = run.perf("wall_time_s")
        if not finite(wall) or wall <= 0:
            continue
        for e in run.entries:
            err = e.get("error")
            if not finite(err) or e.get("comparison") not in ("relative", "absolute"):
                continue
            points.append((float(wall), abs(float(err)), e.get("comparison"), f"{run.case_id}:{e.get('metric')}", run.fidelity))
    if not points:
        return None
    fig, ax = plt.subplots(figsize=(7.0, 3.6))
    markers = {"quick": "o", "standard": "s", "thesis": "^"}
    labels = sorted({p[3] for p in points})
    cmap = plt.get_cmap("tab10")
    for i, label in enumerate(labels):
        for fid in sorted({p[4] for p in points if p[3] == label}):
            pts = sorted((p for p in points if p[3] == label and p[4] == fid), key=lambda p: p[0])
            ax.plot([p[0] for p in pts], [max(p[1], 1e-12) * (100 if p[2] == "relative" else 1) for p in pts],
                    markers.get(fid, "D"), color=cmap(i % 10), ms=6,
                    label=f"{label} ({fid}){' [%]' if pts[0][2] == 'relative' else ' [abs]'}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("error (relative in %, absolute as is)")
    ax.grid(True, which="both", lw=0.3, alpha=0.6)
    ax.legend(fontsize=7, loc="best")
    ax.set_title("run time against error", fontsize=10)
    fig.tight_layout()
    return png_data_uri(fig)
