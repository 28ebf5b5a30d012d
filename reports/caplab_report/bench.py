"""The benchmark page (``make bench``, DESIGN.md section 8): how close the fluid update comes to the
memory roofline, what share of a step the coupling takes per catalogue family, and run time against
error per benchmark family.

Inputs:
  ``bench.json``            written by ``caplab bench`` (solver/bench/bench.cpp, schema caplab.bench/1):
                            environment, bandwidth per thread count, fluid MLUPS rows with their roofline;
  a results tree            ``RESULTS/<fidelity>/<case dir>/manifest.json`` as ``make reproduce*`` writes it:
                            wall time, MLUPS and the share of time per stage of every catalogue run;
  the error series          solver/bench/error_series.json (``load_series`` documents and checks it) and
                            its results folder ``ERR/<family>/<point>/`` written by scripts/bench-error.
Output: ``OUT/index.html`` (+ ``index.pdf`` printed by headless Chromium), self-contained.

Definitions used on the page:
  roofline_mlups   in-place update bandwidth / bytes per update (bench.json "roofline"); fraction = MLUPS /
                   roofline; roofline_mlups_copy the same with the copy bandwidth;
  two-level overhead   uniform MLUPS / two-level MLUPS - 1 at the same lattice, collision, precision and
                   threads (bench.json "overhead_vs_uniform"), the uniform box of the same coarse size
                   timed in batches alternating with the two-level ones ("uniform_twin_mlups"), the
                   median over batch pairs: the extra time per node update that the block coupling
                   costs;
  stage shares     manifest "stage_share": fluid (the update without the parts below), coupling (the
                   two-level grid coupling: the band's coarse step, the capture of the coarse planes,
                   the fine ghosts' fill), ib (interpolation, spreading, forced
                   collision), membrane (forces, node motion), diagnostics, output. "IB + membrane" is the
                   fluid-structure coupling of DESIGN.md section 8. A family's share is wall-time weighted:
                   sum(share x wall) / sum(wall) over its runs;
  error            |value - reference| / |reference| of a metric of summary.json, against an external value
                   (validation) or against the Richardson extrapolation of the series' own points to zero
                   spacing (verification, caplab against caplab);
  Pareto front     the points that no other point beats in both wall time and error (``pareto_front``).
Timings come from a shared, noisy machine: they are reported, never judged pass/fail.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import ticker  # noqa: E402

from .convergence import observed_order  # noqa: E402
from .figures import png_data_uri  # noqa: E402
from .references import ReferenceLibrary  # noqa: E402
from .runs import catalogue_cases, held_by_a_live_run  # noqa: E402

if TYPE_CHECKING:
    from .build import Page

LEVELS = ("quick", "standard", "thesis")
STAGES = ("fluid", "coupling", "ib", "membrane", "diagnostics", "output")
STAGE_COLOURS = {"fluid": "#4c78a8", "coupling": "#f58518", "ib": "#e45756", "membrane": "#72b7b2",
                 "diagnostics": "#b279a2", "output": "#9d755d", "other": "#bab0ac"}
#: Stamp and log next to each point's run directory (the naming of scripts/reproduce).
STAMP_SUFFIX = ".reproduce.json"
LOG_SUFFIX = ".log"


def _num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _read(path: Path):
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


# ---- bench.json: bandwidth, roofline, MLUPS ------------------------------------------------------

def bandwidth_rows(bench: dict) -> list[dict]:
    """Best copy/triad/update bandwidth per thread count, with the before/after update runs beside it."""
    bw = bench.get("bandwidth") or {}
    runs = bw.get("runs") or []
    rows = []
    for b in bw.get("per_threads") or []:
        t = b.get("threads")
        mine = [r for r in runs if r.get("threads") == t]
        rows.append({"threads": t, "copy_gbs": b.get("copy_gbs"), "triad_gbs": b.get("triad_gbs"),
                     "update_gbs": b.get("update_gbs"),
                     "copy_median": b.get("copy_gbs_median"), "triad_median": b.get("triad_gbs_median"),
                     "update_median": b.get("update_gbs_median"),
                     "validated": b.get("validated"),
                     "runs": ", ".join(f"{r.get('when', '?')} {r.get('update_gbs', float('nan')):.1f}" for r in mine
                                       if _num(r.get("update_gbs")))})
    return rows


def fluid_rows(bench: dict, kind: str = "uniform") -> list[dict]:
    """The fluid rows of ``kind`` (uniform | two_level), sorted by lattice, collision, precision, threads."""
    rows = [dict(r) for r in bench.get("rows") or [] if r.get("kind") == kind]
    for r in rows:
        size = r.get("size") or []
        r["size_text"] = f"{size[0]}^{len(size)}" if size else "–"
        if not _num(r.get("fraction")) and _num(r.get("mlups")) and _num(r.get("roofline_mlups")) and r["roofline_mlups"] > 0:
            r["fraction"] = r["mlups"] / r["roofline_mlups"]
    return sorted(rows, key=lambda r: (str(r.get("lattice")), str(r.get("collision")), str(r.get("precision")),
                                       r.get("threads") or 0))


def bytes_per_update(bench: dict) -> list[dict]:
    """One row per lattice and precision: bytes moved per node update (2 Q sizeof T, in place) and the
    roofline MLUPS per thread count."""
    out: dict[tuple, dict] = {}
    for r in fluid_rows(bench):
        key = (r.get("lattice"), r.get("precision"))
        row = out.setdefault(key, {"lattice": key[0], "precision": key[1], "bytes": r.get("bytes_per_update"),
                                   "roofline": {}})
        row["roofline"][r.get("threads")] = r.get("roofline_mlups")
    return list(out.values())


def roofline_figure(bench: dict) -> str | None:
    """Measured MLUPS against the roofline of each fluid row (log-log), lines of constant fraction."""
    rows = [r for r in fluid_rows(bench) + fluid_rows(bench, "two_level")
            if _num(r.get("mlups")) and _num(r.get("roofline_mlups")) and r["mlups"] > 0 and r["roofline_mlups"] > 0]
    if not rows:
        return None
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    markers = {"D2Q9": "o", "D3Q19": "s"}
    colours = {"double": "#1f77b4", "float": "#d62728", "single": "#d62728"}
    seen = set()
    for r in rows:
        two = r.get("kind") == "two_level"
        label = f"{r.get('lattice')} {r.get('precision')}{' two-level' if two else ''}"
        ax.plot(r["roofline_mlups"], r["mlups"], markers.get(r.get("lattice"), "D"),
                color=colours.get(r.get("precision"), "#555"), mfc="none" if two else colours.get(r.get("precision"), "#555"),
                ms=4 + 2 * min(int(r.get("threads") or 1), 4), label=None if label in seen else label)
        seen.add(label)
        ax.annotate(f"{r.get('collision')} {r.get('threads')}t", (r["roofline_mlups"], r["mlups"]), fontsize=6,
                    xytext=(3, 2), textcoords="offset points")
    lo = min(min(r["mlups"] for r in rows), min(r["roofline_mlups"] for r in rows)) / 1.5
    hi = max(max(r["mlups"] for r in rows), max(r["roofline_mlups"] for r in rows)) * 1.5
    for f, style in ((1.0, "-"), (0.5, "--"), (0.25, ":")):
        ax.plot([lo, hi], [f * lo, f * hi], style, color="#777", lw=0.8)
        ax.text(hi / 1.1, f * hi / 1.1, f"{f:g} × roofline", fontsize=7, ha="right", va="bottom", color="#555")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    ax.set_xlabel("roofline [MLUPS] = in-place update bandwidth / bytes per update")
    ax.set_ylabel("measured [MLUPS]")
    ax.grid(True, which="both", lw=0.3, alpha=0.6)
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("fluid update against the memory roofline (open: two-level)", fontsize=10)
    fig.tight_layout()
    return png_data_uri(fig)


def environment_view(bench: dict) -> dict:
    env = bench.get("environment") or {}
    build = env.get("build") or {}
    load = bench.get("load_average") or {}
    return {"cpu": env.get("cpu_model", "–"), "host": env.get("host", "–"), "date": env.get("date_utc", "–"),
            "hardware_threads": env.get("hardware_threads"), "usable": env.get("usable_processors"),
            "threads": (bench.get("options") or {}).get("threads"), "git_sha": str(build.get("git_sha", "–"))[:12]
            + ("+dirty" if build.get("git_dirty") else ""), "compiler": build.get("compiler", "–"),
            "flags": build.get("flags", "–"), "build_type": build.get("build_type", "–"),
            "version": build.get("version", "–"), "llc": env.get("llc_bytes_reported"),
            "load_start": load.get("start"), "load_end": load.get("end"), "quick": (bench.get("options") or {}).get("quick")}


# ---- stage shares per catalogue family -------------------------------------------------------------

#: (id, title) of the catalogue families, in page order; ``family_of`` assigns a case.
FAMILIES = (("cylinder", "ch2 cylinder (fixed bodies)"),
            ("moving", "ch2 moving bodies (prescribed motion)"),
            ("capsules_2d", "2D capsules (ch2-4)"),
            ("capsules_3d", "3D capsules (ch5)"),
            ("ch6", "3D capsules near walls and other shapes (ch6)"))


def family_of(case_id: str, case: dict | None) -> str | None:
    """The family of a case, from its chapter and its bodies (a membrane: capsule; a prescribed
    motion: moving; else fixed); None for cases outside the five families (catalogue/extra)."""
    chapter = case_id.split("/", 1)[0]
    bodies = ((case or {}).get("physics") or {}).get("bodies") or []
    membrane = any(isinstance(b, dict) and "membrane" in b for b in bodies)
    moving = any(isinstance(b, dict) and ((b.get("motion") or {}).get("type") not in (None, "fixed")) for b in bodies)
    if chapter == "ch5":
        return "capsules_3d"
    if chapter == "ch6":
        return "ch6"
    if chapter in ("ch3", "ch4") or (chapter == "ch2" and membrane):
        return "capsules_2d"
    if chapter == "ch2":
        return "moving" if moving else "cylinder"
    return None


def _stage_shares(manifest: dict) -> dict[str, float]:
    share = manifest.get("stage_share")
    if not isinstance(share, dict):
        return {}
    return {k: float(v) for k, v in share.items() if _num(v)}


def stage_families(results: Path | None, fidelity: str = "standard", catalogue: Path | None = None) -> list[dict]:
    """One view per family: its finished runs at ``fidelity`` (case, wall time, MLUPS, threads,
    shares), the wall-time weighted shares, the MLUPS range and how many catalogue cases ran."""
    cases = catalogue_cases(catalogue)
    runs: dict[str, list[dict]] = {f: [] for f, _ in FAMILIES}
    problems: dict[str, list[str]] = {f: [] for f, _ in FAMILIES}
    base = Path(results) / fidelity if results is not None else None
    if base is not None and base.is_dir():
        for d in sorted(p for p in base.iterdir() if p.is_dir() and not p.name.startswith(".")):
            manifest = _read(d / "manifest.json")
            if not isinstance(manifest, dict):
                continue
            case = _read(d / "case.json")
            cid = manifest.get("case_id") or (case or {}).get("id") or d.name.replace("__", "/")
            fam = family_of(cid, case if isinstance(case, dict) else (cases.get(cid) or (None, None))[1])
            if fam is None:
                continue
            if manifest.get("status") != "ok":
                problems[fam].append(f"{cid}: status {manifest.get('status')!r}, not counted")
                continue
            runs[fam].append({"case": cid, "wall": manifest.get("wall_time_s"), "mlups": manifest.get("mlups"),
                              "threads": manifest.get("threads") or (manifest.get("environment") or {}).get("threads"),
                              "shares": _stage_shares(manifest)})
    in_catalogue = {f: 0 for f, _ in FAMILIES}
    for cid, (_, case) in cases.items():
        fam = family_of(cid, case)
        if fam is not None:
            in_catalogue[fam] += 1
    views = []
    for fam, title in FAMILIES:
        rs = runs[fam]
        total = sum(float(r["wall"]) for r in rs if _num(r["wall"]))
        shares = {}
        if total > 0:
            for s in STAGES:
                shares[s] = sum(r["shares"].get(s, 0.0) * float(r["wall"]) for r in rs if _num(r["wall"])) / total
            shares["other"] = max(0.0, 1.0 - sum(shares.values()))
        mlups = sorted(float(r["mlups"]) for r in rs if _num(r["mlups"]))
        for r in rs:
            r["fsi"] = r["shares"].get("ib", 0.0) + r["shares"].get("membrane", 0.0)
            r["bar"] = share_bar(r["shares"])
        views.append({"id": fam, "title": title, "runs": rs, "shares": shares, "bar": share_bar(shares),
                      "fsi": (shares.get("ib", 0.0) + shares.get("membrane", 0.0)) if shares else None,
                      "wall": total, "mlups_median": mlups[len(mlups) // 2] if mlups else None,
                      "mlups_min": mlups[0] if mlups else None, "mlups_max": mlups[-1] if mlups else None,
                      "in_catalogue": in_catalogue[fam], "problems": problems[fam]})
    return views


def share_bar(shares: dict[str, float]) -> list[dict]:
    total = sum(v for v in shares.values() if v > 0) or 1.0
    return [{"name": k, "width": 100.0 * v / total, "colour": STAGE_COLOURS.get(k, "#999"), "share": v}
            for k, v in shares.items() if v > 0]


# ---- the error series file -------------------------------------------------------------------------

class SeriesError(ValueError):
    """A problem of the series file: names the file, the JSON path and the value."""


_LABEL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")
_TOP_KEYS = {"description", "families"}
_FAMILY_KEYS = {"id", "title", "description", "case", "fidelity", "resolution", "metrics", "points"}
_METRIC_KEYS = {"name", "symbol", "references"}
_POINT_KEYS = {"label", "set", "case", "fidelity", "level", "quick", "note"}
_REF_KEYS = {"external": {"kind", "value", "source", "label"},
             "richardson": {"kind", "over", "points", "quick_points", "order", "label"}}


def _fail(file, pointer: str, problem: str, value) -> SeriesError:
    shown = json.dumps(value)
    if len(shown) > 120:
        shown = shown[:117] + "..."
    return SeriesError(f"{file}: {pointer or '/'}: {problem} (got {shown})")


def load_series(path: Path, repo: Path | None = None, data: dict | None = None) -> dict:
    """Reads and checks the error series file; raises SeriesError naming the file, the JSON path
    (JSON pointer) and the value of the first problem. Returns the data with defaults filled in
    (family fidelity "standard", point fidelity = family fidelity, quick False)."""
    path = Path(path)
    repo = Path(repo) if repo is not None else Path(__file__).resolve().parents[2]
    if data is None:
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as err:
            raise SeriesError(f"{path}: cannot read: {err}") from err
        try:
            data = json.loads(text)
        except ValueError as err:
            raise SeriesError(f"{path}: not JSON: {err}") from err

    def keys(obj, allowed, at):
        if not isinstance(obj, dict):
            raise _fail(path, at, "expected an object", obj)
        for k in obj:
            if k not in allowed:
                raise _fail(path, f"{at}/{k}", f"unknown key; allowed: {', '.join(sorted(allowed))}", obj[k])

    def text(obj, key, at, required=True):
        v = obj.get(key)
        if v is None and not required:
            return None
        if not isinstance(v, str) or not v.strip():
            raise _fail(path, f"{at}/{key}", "expected a non-empty string", v)
        return v

    keys(data, _TOP_KEYS, "")
    fams = data.get("families")
    if not isinstance(fams, list) or not fams:
        raise _fail(path, "/families", "expected a non-empty list of families", fams)
    ids = set()
    for i, fam in enumerate(fams):
        at = f"/families/{i}"
        keys(fam, _FAMILY_KEYS, at)
        fid = text(fam, "id", at)
        if not _LABEL.match(fid) or fid in ids:
            raise _fail(path, f"{at}/id", "expected a unique name of letters, digits, _ . + -", fid)
        ids.add(fid)
        text(fam, "title", at)
        case = text(fam, "case", at)
        if not (repo / case).is_file():
            raise _fail(path, f"{at}/case", f"no such case file under {repo}", case)
        fam.setdefault("fidelity", "standard")
        if fam["fidelity"] not in LEVELS:
            raise _fail(path, f"{at}/fidelity", f"expected one of {', '.join(LEVELS)}", fam["fidelity"])
        if "resolution" in fam:
            keys(fam["resolution"], {"path", "label"}, f"{at}/resolution")
            text(fam["resolution"], "path", f"{at}/resolution")
        points = fam.get("points")
        if not isinstance(points, list) or not points:
            raise _fail(path, f"{at}/points", "expected a non-empty list of points", points)
        labels: dict[str, dict] = {}
        levels: dict[str, str] = {}
        for j, p in enumerate(points):
            pat = f"{at}/points/{j}"
            keys(p, _POINT_KEYS, pat)
            label = text(p, "label", pat)
            if not _LABEL.match(label) or label in labels:
                raise _fail(path, f"{pat}/label", "expected a unique label of letters, digits, _ . + - "
                            "(it names the run directory)", label)
            labels[label] = p
            p.setdefault("set", {})
            if not isinstance(p["set"], dict):
                raise _fail(path, f"{pat}/set", "expected an object of dotted case paths to JSON values", p["set"])
            for k, v in p["set"].items():
                if not re.match(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z0-9_]+)*$", k):
                    raise _fail(path, f"{pat}/set/{k}", "expected a dotted case path such as numerics.end_time", k)
                if v is None or isinstance(v, dict):
                    raise _fail(path, f"{pat}/set/{k}", "expected a number, string, boolean or list", v)
            if "case" in p:
                own = text(p, "case", pat)
                if not (repo / own).is_file():
                    raise _fail(path, f"{pat}/case", f"no such case file under {repo}", own)
                if "level" in p:
                    raise _fail(path, f"{pat}/case", "a catalogue level point runs the family's case", own)
            p.setdefault("fidelity", fam["fidelity"])
            if p["fidelity"] not in LEVELS:
                raise _fail(path, f"{pat}/fidelity", f"expected one of {', '.join(LEVELS)}", p["fidelity"])
            p.setdefault("quick", False)
            if not isinstance(p["quick"], bool):
                raise _fail(path, f"{pat}/quick", "expected true or false", p["quick"])
            if "level" in p:
                lv = p["level"]
                if lv not in LEVELS:
                    raise _fail(path, f"{pat}/level", f"expected one of {', '.join(LEVELS)}", lv)
                if lv in levels:
                    raise _fail(path, f"{pat}/level", f"level already marks point {levels[lv]!r}", lv)
                if p["fidelity"] != lv or p["set"].keys() - {"numerics.threads"}:
                    raise _fail(path, f"{pat}/level", "a catalogue level is the case run at that fidelity with no "
                                "overrides: give \"fidelity\": \"" + str(lv) + "\" and an empty \"set\"",
                                {"level": lv, "fidelity": p["fidelity"], "set": p["set"]})
                levels[lv] = label
        metrics = fam.get("metrics")
        if not isinstance(metrics, list) or not metrics:
            raise _fail(path, f"{at}/metrics", "expected a non-empty list of metrics", metrics)
        for k, m in enumerate(metrics):
            mat = f"{at}/metrics/{k}"
            keys(m, _METRIC_KEYS, mat)
            text(m, "name", mat)
            m.setdefault("symbol", m["name"])
            refs = m.get("references")
            if not isinstance(refs, list) or not refs:
                raise _fail(path, f"{mat}/references", "expected a non-empty list of references", refs)
            for r_i, ref in enumerate(refs):
                rat = f"{mat}/references/{r_i}"
                kind = ref.get("kind") if isinstance(ref, dict) else None
                if kind not in _REF_KEYS:
                    raise _fail(path, f"{rat}/kind", "expected \"external\" or \"richardson\"", kind)
                keys(ref, _REF_KEYS[kind], rat)
                if kind == "external":
                    if not _num(ref.get("value")) or ref["value"] == 0:
                        raise _fail(path, f"{rat}/value", "expected a non-zero number", ref.get("value"))
                    src = text(ref, "source", rat)
                    if not src.startswith("references/"):
                        raise _fail(path, f"{rat}/source", "expected references/<benchmark>/<file>#<key>", src)
                else:
                    over = text(ref, "over", rat)
                    order = ref.setdefault("order", "observed")
                    if order != "observed" and not (_num(order) and order > 0):
                        raise _fail(path, f"{rat}/order", "expected \"observed\" or a positive number", order)
                    for which, quick in (("points", False), ("quick_points", True)):
                        if which not in ref:
                            continue
                        lst = ref[which]
                        need = 3 if order == "observed" else 2
                        if not isinstance(lst, list) or len(lst) < need:
                            raise _fail(path, f"{rat}/{which}", f"expected a list of at least {need} point labels "
                                        f"(order {order})", lst)
                        for q, lab in enumerate(lst):
                            p = labels.get(lab)
                            if p is None:
                                raise _fail(path, f"{rat}/{which}/{q}", "no point of this family has this label", lab)
                            if p["quick"] != quick:
                                raise _fail(path, f"{rat}/{which}/{q}", f"point is {'not ' if quick else ''}in the "
                                            "quick set", lab)
                            if not _num(p["set"].get(over)) and "level" not in p:
                                raise _fail(path, f"{rat}/{which}/{q}", f"point does not set {over} to a number (only "
                                            "a catalogue level point may take it from its run's case.json)", lab)
                    if "points" not in ref and "quick_points" not in ref:
                        raise _fail(path, rat, "a richardson reference needs \"points\" or \"quick_points\"", ref)
    return data


def point_overrides(point: dict) -> list[str]:
    """The ``--set`` arguments of a point, in the file's order: path=JSON value."""
    return [f"{k}={json.dumps(v)}" for k, v in point.get("set", {}).items()]


def point_case_file(family: dict, point: dict) -> str:
    """The case file of a point, relative to the repository: its own "case", else the family's."""
    return point.get("case") or family["case"]


def points_of(family: dict, quick: bool) -> list[dict]:
    return [p for p in family["points"] if p.get("quick", False) == quick]


# ---- Pareto front and Richardson extrapolation ---------------------------------------------------------

def pareto_front(points: list[tuple[float, float]]) -> list[int]:
    """Indices of the points (cost, error) that no other point dominates (cost and error both no
    larger, one of them smaller), sorted by cost. Points with a non-finite or negative coordinate
    are never on the front. Equal points are all on it (neither dominates the other)."""
    ok = [i for i, (c, e) in enumerate(points) if _num(c) and _num(e) and c >= 0 and e >= 0]
    front = []
    for i in ok:
        ci, ei = points[i]
        dominated = any(points[j][0] <= ci and points[j][1] <= ei and (points[j][0] < ci or points[j][1] < ei)
                        for j in ok if j != i)
        if not dominated:
            front.append(i)
    return sorted(front, key=lambda i: (points[i][0], points[i][1]))


def richardson(h: list[float], f: list[float], order="observed") -> dict:
    """Extrapolation of f(h) = f0 + C h^p to h = 0: {value, order, note}; value None when it cannot
    be done (fewer points than needed, oscillating or non-convergent values).

    ``order`` "observed": the three smallest h; p from (f1 - f2)/(f2 - f3) = (h1^p - h2^p)/(h2^p - h3^p)
    (any ratios; convergence.observed_order). A number: least squares over all points."""
    pts = sorted((float(a), float(b)) for a, b in zip(h, f) if _num(a) and _num(b) and a > 0)
    if order != "observed":
        if len(pts) < 2:
            return {"value": None, "order": order, "note": f"{len(pts)} finished point(s); 2 needed"}
        xs = [a ** order for a, _ in pts]
        ys = [b for _, b in pts]
        n = len(xs)
        mx, my = sum(xs) / n, sum(ys) / n
        sxx = sum((x - mx) ** 2 for x in xs)
        if sxx == 0:
            return {"value": None, "order": order, "note": "all points at the same spacing"}
        slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
        return {"value": my - slope * mx, "order": float(order), "note": f"least squares, fixed order {order:g}"}
    if len(pts) < 3:
        return {"value": None, "order": None, "note": f"{len(pts)} finished point(s); 3 needed for the observed order"}
    (h3, f3), (h2, f2), (h1, f1) = pts[:3]
    if not h3 < h2 < h1:
        return {"value": None, "order": None, "note": "two of the three finest points have the same spacing"}
    d12, d23 = f1 - f2, f2 - f3
    if d23 == 0 or d12 == 0 or (d12 > 0) != (d23 > 0):
        return {"value": None, "order": None,
                "note": f"not monotone in h ({f1:.6g}, {f2:.6g}, {f3:.6g}): no asymptotic range, no extrapolation"}
    found = observed_order([h1, h2, h3], [f1, f2, f3])
    if found is None:
        return {"value": None, "order": None,
                "note": f"ratio of differences {d12 / d23:.3g} gives no order in (0.05, 20)"}
    return {"value": found.extrapolated, "order": found.order,
            "note": f"observed order {found.order:.2f} from the three finest points"}


# ---- the error series: results per point --------------------------------------------------------------

@dataclass
class PointResult:
    point: dict
    state: str = "not run"        # not run | ok | failed | stale | running
    message: str = ""
    wall: float | None = None
    mlups: float | None = None
    node_updates: float | None = None
    threads: int | None = None
    resolved: dict = field(default_factory=dict)  # the run's case.json
    values: dict = field(default_factory=dict)    # metric -> value
    errors: dict = field(default_factory=dict)    # (metric, reference index) -> error
    front: set = field(default_factory=set)       # (metric, reference index) where on the Pareto front

    @property
    def label(self) -> str:
        return self.point["label"]

    @property
    def level(self) -> str | None:
        return self.point.get("level")


def read_point(family: dict, point: dict, results: Path) -> PointResult:
    """What scripts/bench-error left for ``point``: its stamp (``<label>.reproduce.json``) and run
    directory (``<label>/``) under ``results/<family id>/``."""
    res = PointResult(point)
    base = Path(results) / family["id"]
    stamp = _read(base / (point["label"] + STAMP_SUFFIX))
    manifest = _read(base / point["label"] / "manifest.json")
    if not isinstance(stamp, dict) and not isinstance(manifest, dict):
        return res
    stamp = stamp if isinstance(stamp, dict) else {}
    manifest = manifest if isinstance(manifest, dict) else {}
    code, status = stamp.get("exit_code"), manifest.get("status")
    if stamp and (stamp.get("overrides", []) != point_overrides(point) or stamp.get("fidelity") != point["fidelity"]
                  or not str(stamp.get("case_file", "")).endswith(point_case_file(family, point))):
        res.state, res.message = "stale", ("the series file changed since this point ran (case, overrides or "
                                           "fidelity differ from its stamp): rerun scripts/bench-error")
    elif status == "ok" and code in (0, 1, None):
        res.state = "ok"
    elif stamp and code is None:
        res.state, res.message = "running", ("started, not finished: running now" if held_by_a_live_run(
            base / point["label"]) else "started, not finished: killed (rerun scripts/bench-error)")
    else:
        res.state = "failed"
        what = f"exit code {code} ({stamp.get('meaning', '?')})" if code is not None else "no stamp"
        res.message = f"{what}, manifest status {status or 'missing'}" + (
            f": {manifest.get('error')}" if manifest.get("error") else (f": {stamp['error']}" if stamp.get("error") else ""))
    res.wall = manifest.get("wall_time_s") if _num(manifest.get("wall_time_s")) else None
    res.mlups = manifest.get("mlups") if _num(manifest.get("mlups")) else None
    res.threads = manifest.get("threads")
    nu = (manifest.get("lattice") or {}).get("node_updates")
    res.node_updates = nu if _num(nu) else None
    case = _read(base / point["label"] / "case.json")
    res.resolved = case if isinstance(case, dict) else {}
    if res.state == "ok":
        summary = _read(base / point["label"] / "summary.json") or {}
        metrics = summary.get("metrics") if isinstance(summary.get("metrics"), dict) else {}
        for m in family["metrics"]:
            entry = metrics.get(m["name"])
            v = entry.get("value") if isinstance(entry, dict) else entry
            if _num(v):
                res.values[m["name"]] = float(v)
            else:
                res.message = (res.message + "; " if res.message else "") + f"summary.json has no number {m['name']}"
    return res


def spacing(r: "PointResult", over: str):
    """The value of the dotted case path ``over`` for a point: its override, else its run's case.json."""
    if over in r.point.get("set", {}):
        return r.point["set"][over]
    node = r.resolved
    for part in over.split("."):
        if isinstance(node, dict):
            node = node.get(part)
        elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            return None
    return node if _num(node) else None


def family_view(family: dict, results: Path | None, quick: bool, refs: ReferenceLibrary) -> dict:
    """Points of the mode with their results, the reference value of every (metric, reference),
    the errors, the Pareto fronts and the figure."""
    pts = points_of(family, quick)
    rs = [read_point(family, p, results) if results is not None else PointResult(p) for p in pts]
    by_label = {r.label: r for r in rs}
    metrics = []
    for m in family["metrics"]:
        mview = {"name": m["name"], "symbol": m["symbol"], "references": []}
        for k, ref in enumerate(m["references"]):
            rv = {"index": k, "kind": ref["kind"], "value": None, "note": "", "provenance": None}
            if ref["kind"] == "external":
                rv["value"] = float(ref["value"])
                resolved = refs.resolve(ref["source"], ref["value"])
                rv["label"] = ref.get("label") or "external"
                rv["what"] = "validation"
                rv["source"] = ref["source"]
                rv["provenance"] = resolved
                rv["note"] = resolved.note
                rv["mismatch"] = resolved.mismatch
            else:
                labels = ref.get("quick_points" if quick else "points") or []
                used = [by_label[lab] for lab in labels if lab in by_label]
                missing = [lab for lab in labels if lab not in by_label or by_label[lab].state != "ok"
                           or m["name"] not in by_label[lab].values]
                rv["label"] = ref.get("label") or "Richardson h → 0"
                rv["what"] = "verification (caplab against caplab)"
                rv["source"] = f"{ref['over']} → 0 over points {', '.join(labels) or '(none in this mode)'}"
                done = [r for r in used if r.state == "ok" and m["name"] in r.values and _num(spacing(r, ref["over"]))]
                ex = richardson([spacing(r, ref["over"]) for r in done], [r.values[m["name"]] for r in done],
                                ref["order"])
                rv["value"], rv["order"], rv["note"] = ex["value"], ex["order"], ex["note"]
                if missing:
                    rv["note"] += f"; without a finished value: {', '.join(missing)}"
            if _num(rv["value"]) and rv["value"] != 0:
                for r in rs:
                    if m["name"] in r.values:
                        r.errors[(m["name"], k)] = abs(r.values[m["name"]] - rv["value"]) / abs(rv["value"])
                cost_err = [(r.wall if r.state == "ok" else None, r.errors.get((m["name"], k))) for r in rs]
                front = pareto_front(cost_err)
                for i in front:
                    rs[i].front.add((m["name"], k))
                rv["front"] = [rs[i].label for i in front]
            else:
                rv["front"] = []
            mview["references"].append(rv)
        metrics.append(mview)
    counts = {s: sum(1 for r in rs if r.state == s) for s in ("ok", "failed", "stale", "running", "not run")}
    view = {"family": family, "points": rs, "metrics": metrics, "counts": counts,
            "levels": {r.level: r.label for r in rs if r.level}}
    view["figure"] = error_figure(view)
    return view


def error_figure(view: dict) -> str | None:
    """Per metric one panel: relative error (log) against wall time (log), one series per
    reference, the Pareto front of each as a step line, the catalogue levels labelled."""
    panels = [m for m in view["metrics"] if any(_num(rv["value"]) for rv in m["references"])]
    have = [(m, rv) for m in panels for rv in m["references"]
            if any(r.state == "ok" and _num(r.wall) and (m["name"], rv["index"]) in r.errors for r in view["points"])]
    if not have:
        return None
    panels = [m for m in panels if any(mm is m for mm, _ in have)]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 3.8), squeeze=False)
    styles = [("o", "#1f77b4", True), ("s", "#d62728", False), ("^", "#2ca02c", True), ("D", "#9467bd", False)]
    floor = 1e-6
    for ax, m in zip(axes[0], panels):
        for rv in m["references"]:
            marker, colour, filled = styles[rv["index"] % len(styles)]
            key = (m["name"], rv["index"])
            pts = [r for r in view["points"] if r.state == "ok" and _num(r.wall) and key in r.errors]
            if not pts:
                continue
            xs = [float(r.wall) for r in pts]
            ys = [100 * max(r.errors[key], floor) for r in pts]
            ax.plot(xs, ys, marker, color=colour, mfc=colour if filled else "none", ms=6, ls="none",
                    label=f"vs {rv['label']}")
            front = sorted((r for r in pts if key in r.front), key=lambda r: float(r.wall))
            if front:
                fx, fy = [], []
                for r in front:
                    if fx:
                        fx.append(float(r.wall))
                        fy.append(fy[-1])
                    fx.append(float(r.wall))
                    fy.append(100 * max(r.errors[key], floor))
                ax.plot(fx, fy, "--", color=colour, lw=1.0, alpha=0.8)
            for r, x, y in zip(pts, xs, ys):
                text = r.label + (f" [{r.level}]" if r.level else "")
                ax.annotate(text, (x, y), fontsize=6, xytext=(4, 3), textcoords="offset points",
                            fontweight="bold" if r.level else "normal")
                if r.level:
                    ax.plot([x], [y], "o", ms=13, mfc="none", mec="#333", lw=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
            axis.set_minor_formatter(ticker.NullFormatter())
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel(f"relative error of {m['symbol']} [%]")
        ax.grid(True, which="both", lw=0.3, alpha=0.6)
        ax.legend(fontsize=7, loc="best")
        ax.set_title(m["symbol"], fontsize=10)
    fig.suptitle(f"{view['family']['title']}: error against run time (dashed: Pareto front; ringed: catalogue levels)",
                 fontsize=9)
    fig.tight_layout()
    return png_data_uri(fig)


def any_run(family: dict, results: Path | None, quick: bool) -> bool:
    if results is None:
        return False
    base = Path(results) / family["id"]
    return any((base / (p["label"] + STAMP_SUFFIX)).exists() for p in points_of(family, quick))


def error_section(series_file: Path | None, results: Path | None, mode: str = "auto",
                  references: Path | None = None, repo: Path | None = None) -> dict:
    """The run-time-against-error section: {mode, families (views), problem}. ``mode`` full, quick
    or auto (full when a full point has run, else quick when a quick point has, else full)."""
    out = {"mode": mode, "families": [], "problem": "", "series_file": str(series_file), "results": str(results)}
    if series_file is None:
        out["problem"] = "no error series file given"
        return out
    try:
        series = load_series(series_file, repo)
    except SeriesError as err:
        out["problem"] = str(err)
        return out
    out["description"] = series.get("description", "")
    if mode == "auto":
        if any(any_run(f, results, False) for f in series["families"]):
            mode = "full"
        elif any(any_run(f, results, True) for f in series["families"]):
            mode = "quick"
        else:
            mode = "full"
    out["mode"] = mode
    refs = ReferenceLibrary(references if references is not None else
                            (Path(repo) if repo else Path(__file__).resolve().parents[2]) / "references")
    out["families"] = [family_view(f, results, mode == "quick", refs) for f in series["families"]]
    return out


# ---- the page -------------------------------------------------------------------------------------------

def fmt_pct(v, decimals: int = 1) -> str:
    """0.8123 -> "81.2 %" (fixed decimals, never an exponent)."""
    return f"{100 * float(v):.{decimals}f} %" if _num(v) else "–"


def fmt_error_pct(v) -> str:
    """A relative error in percent with three significant digits: 0.000123 -> "0.0123 %"."""
    return f"{100 * float(v):.3g} %" if _num(v) else "–"


def render(bench: dict | None, stages: list[dict], error: dict, meta: dict, bench_problem: str = "") -> str:
    from .build import environment

    env = environment()
    env.filters["pct"] = fmt_pct
    env.filters["errpct"] = fmt_error_pct
    b = bench or {}
    return env.get_template("bench.html.j2").render(
        title="caplab — performance (make bench)", bench=b, bench_problem=bench_problem,
        env_view=environment_view(b), bandwidth=bandwidth_rows(b), uniform=fluid_rows(b),
        two_level=fluid_rows(b, "two_level"), bytes_rows=bytes_per_update(b),
        roofline_figure=roofline_figure(b) if bench else None, stages=stages, stage_names=STAGES,
        stage_colours=STAGE_COLOURS, error=error, meta=meta, root="")


def build_page(bench_json: Path | None, out: Path, results: Path | None = None, fidelity: str = "standard",
               series_file: Path | None = None, error_results: Path | None = None, error_mode: str = "auto",
               catalogue: Path | None = None, references: Path | None = None, repo: Path | None = None,
               pdf: bool = True, chromium: str = "chromium") -> Page:
    """Writes ``out/index.html`` (and the PDF) from bench.json, the results tree and the error series."""
    import datetime as _dt

    from .build import git_sha, publish

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    bench, bench_problem = None, ""
    if bench_json is None or not Path(bench_json).is_file():
        bench_problem = f"{bench_json}: not found — run `caplab bench --out {out}` (make bench) first"
    else:
        bench = _read(Path(bench_json))
        if not isinstance(bench, dict):
            bench, bench_problem = None, f"{bench_json}: not readable as JSON"
        elif bench.get("schema") != "caplab.bench/1":
            bench_problem = f"{bench_json}: schema {bench.get('schema')!r}, expected 'caplab.bench/1'; shown as far as it goes"
    stages = stage_families(results, fidelity, catalogue)
    error = error_section(series_file, error_results, error_mode, references, repo)
    meta = {"generated": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "results": f"{bench_json}, {results}/{fidelity}, {error_results}", "report_git_sha": git_sha(),
            "fidelity": fidelity}
    return publish(out, render(bench, stages, error, meta, bench_problem), pdf, chromium,
                   [p for p in (bench_problem, error.get("problem")) if p])


def main(argv=None) -> int:
    """Command line: ``python3 -m caplab_report.bench`` (make bench)."""
    import argparse
    import sys

    repo = Path(__file__).resolve().parents[2]
    p = argparse.ArgumentParser(prog="caplab_report.bench", description="Build the benchmark page (make bench).")
    p.add_argument("--bench", type=Path, default=repo / "reports" / "out" / "bench" / "bench.json",
                   help="bench.json of caplab bench (default: reports/out/bench/bench.json)")
    p.add_argument("--out", type=Path, default=repo / "reports" / "out" / "bench", help="output folder")
    p.add_argument("--results", type=Path, default=repo / "results", help="results tree of make reproduce*")
    p.add_argument("--fidelity", default="standard", help="fidelity of the runs for the stage shares (default standard)")
    p.add_argument("--series", type=Path, default=repo / "solver" / "bench" / "error_series.json",
                   help="error series file (default: solver/bench/error_series.json)")
    p.add_argument("--error-results", type=Path, default=repo / "results" / "bench-error",
                   help="results folder of scripts/bench-error (default: results/bench-error)")
    p.add_argument("--error-mode", choices=("auto", "full", "quick"), default="auto",
                   help="which points of the series to show (default auto: full if any ran, else quick)")
    p.add_argument("--catalogue", type=Path, default=repo / "catalogue")
    p.add_argument("--no-pdf", action="store_true")
    p.add_argument("--chromium", default="chromium")
    a = p.parse_args(argv)
    page = build_page(a.bench, a.out, a.results, a.fidelity, a.series, a.error_results, a.error_mode, a.catalogue,
                      pdf=not a.no_pdf, chromium=a.chromium)
    for problem in page.problems:
        print(f"bench page: {problem}", file=sys.stderr)
    print(f"bench page: wrote {page.html}" + (f" and {page.pdf}" if page.pdf else ""))
    fatal = [q for q in page.problems if q.startswith("PDF not written")]
    return 1 if fatal or (a.bench is not None and not a.bench.is_file()) else 0


if __name__ == "__main__":
    raise SystemExit(main())
