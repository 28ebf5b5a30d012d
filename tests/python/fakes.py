"""Hand-built run directories following the contract of DESIGN.md section 6, for the report tests
and for the fake ``caplab`` of the reproduce tests (the solver is not needed to test either).

``make_run_dir(out, case, fidelity, outcome)`` writes what ``caplab run`` would write:
case.json, manifest.json, series.h5, summary.json, score.json. Outcomes:
  pass      finished, Cd mean close to the reference: accuracy pass
  fail      finished, Cd mean 15 % off: accuracy fail (caplab exit code 1)
  diverged  stopped at t = 40 with a NaN: manifest "diverged", sanity fail (exit code 3)
  running   manifest still "running" (a killed run)
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import h5py
import numpy as np

EXIT_CODES = {"pass": 0, "fail": 1, "diverged": 3, "running": 4}

CYLINDER_CASE = {
    "id": "ch2/cylinder_re100",
    "title": "Flow past a circular cylinder, Re = 100 (two-block IB-LBM)",
    "description": "Thesis section 2.2.1, table 2.1. Uniform flow past a fixed circular cylinder, "
                   "Cd = F_x / (0.5 rho U^2 D). Time in D/U.",
    "physics": {"dimension": 2, "flow": {"type": "uniform", "direction": [1, 0]}, "reynolds": 100,
                "domain": {"size": [30, 20], "boundaries": ["far_field", "far_field"]},
                "bodies": [{"name": "cylinder", "shape": {"type": "circle", "center": [10, 10], "diameter": 1},
                            "motion": {"type": "fixed"}}]},
    "numerics": {"grid": {"refinement": "two_level", "fine_spacing": 0.04}, "end_time": 150},
    "outputs": {"series": {"interval": 0.1, "quantities": ["drag_coefficient", "lift_coefficient"]},
                "average_from": 100},
    "acceptance": [{"metric": "drag_coefficient_mean", "reference": "references/cylinder/table_2_1.csv#Present:cd_re100",
                    "reference_value": 1.438, "comparison": "relative",
                    "tolerance": {"quick": 0.06, "standard": 0.02, "thesis": 0.02},
                    "justification": "Thesis table 2.1 spread about 3 %."}],
}


def cylinder_case(case_id: str = "ch2/cylinder_re100", title: str | None = None, reynolds: int = 100) -> dict:
    case = copy.deepcopy(CYLINDER_CASE)
    case["id"] = case_id
    case["physics"]["reynolds"] = reynolds
    if title:
        case["title"] = title
    return case


def write_json(path: Path, data) -> None:
    path.write_text(json.dumps(data, indent=2), encoding="utf-8")


def make_run_dir(out: Path, case: dict, fidelity: str = "quick", outcome: str = "pass") -> Path:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(out / "case.json", case)
    end = 40.0 if outcome == "diverged" else float(case["numerics"]["end_time"])
    avg_from = float(case["outputs"]["average_from"])
    t = np.arange(0.0, end + 1e-9, 0.1)
    f = 0.166
    cd_mean = {"pass": 1.45, "fail": 1.65}.get(outcome, 1.45)
    ramp = 1.0 - np.exp(-t / 15.0)
    cd = cd_mean + 2.5 * np.exp(-t / 3.0) + 0.01 * ramp * np.sin(4 * math.pi * f * t)
    cl = 0.34 * ramp * np.sin(2 * math.pi * f * t)
    if outcome == "diverged":
        cd[-5:] = np.nan
        cl[-5:] = np.nan
    with h5py.File(out / "series.h5", "w") as h5:
        for name, values, unit, definition in (
                ("t", t, "D/U", "time t U / D"),
                ("drag_coefficient", cd, "1", "Cd = F_x / (0.5 rho U^2 D)"),
                ("lift_coefficient", cl, "1", "Cl = F_y / (0.5 rho U^2 D)")):
            ds = h5.create_dataset(name, data=values)
            ds.attrs["unit"] = unit
            ds.attrs["definition"] = definition
    status = {"pass": "ok", "fail": "ok", "diverged": "diverged", "running": "running"}[outcome]
    manifest = {
        "status": status, "case_id": case["id"], "fidelity": fidelity, "wall_time_s": 42.5, "mlups": 31.7,
        "steps": 37500, "threads": 8,
        "stage_share": {"fluid": 0.8, "coupling": 0.05, "ib": 0.1, "diagnostics": 0.03, "output": 0.02},
        "environment": {"build": {"git_sha": "0123456789abcdef0123456789abcdef01234567", "git_dirty": False,
                                  "compiler": "GNU 12.2.0", "flags": "-O3 -march=native"},
                        "host": "testhost", "cpu_model": "Test CPU @ 3.0GHz", "date_utc": "2024-01-01T00:00:00Z",
                        "threads": 8},
    }
    write_json(out / "manifest.json", manifest)
    if outcome == "running":
        return out
    window = t >= avg_from
    if outcome == "diverged":
        metrics = {}
    else:
        metrics = {
            "drag_coefficient_mean": {"value": float(np.mean(cd[window])), "unit": "1", "definition": "time average"},
            "lift_coefficient_amplitude": {"value": float((cl[window].max() - cl[window].min()) / 2), "unit": "1",
                                           "definition": "(max - min)/2"},
            "strouhal_number": {"value": f, "unit": "1", "definition": "St = f D / U"},
        }
    write_json(out / "summary.json", {"case_id": case["id"], "fidelity": fidelity, "metrics": metrics})
    entries = []
    if outcome != "diverged":
        for a in case.get("acceptance", []):
            value = metrics[a["metric"]]["value"]
            tol = a["tolerance"][fidelity]
            err = abs(value - a["reference_value"]) / abs(a["reference_value"])
            entries.append({"metric": a["metric"], "value": value, "unit": "1", "reference_value": a["reference_value"],
                            "reference": a["reference"], "comparison": a["comparison"], "error": err,
                            "tolerance": tol, "justification": a["justification"],
                            "verdict": "pass" if err <= tol else "fail"})
    sane = outcome != "diverged"
    accuracy = ("none" if not sane else ("pass" if all(e["verdict"] == "pass" for e in entries) else "fail"))
    score = {
        "case_id": case["id"], "fidelity": fidelity,
        "sanity": {"verdict": "pass" if sane else "fail",
                   "checks": [{"name": "status", "value": status, "limit": "ok", "verdict": "pass" if sane else "fail",
                               "message": "" if sane else "run diverged at t = 39.6 (NaN in the density)"}]},
        "accuracy": {"verdict": accuracy, "entries": entries, **({"reason": "run did not finish"} if not sane else {})},
        "performance": {"wall_time_s": 42.5, "mlups": 31.7, "steps": 37500},
        "verdict": "pass" if sane and accuracy == "pass" else "fail",
    }
    write_json(out / "score.json", score)
    return out
