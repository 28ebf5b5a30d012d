"""Chapter 2 extras: thesis tables 2.1 and 2.2 reproduced next to the caplab runs.

Table 2.1 lists Cd (mean), Cl (amplitude) and St at Re = 100 and 200 for four external studies
(validation: external data) and the thesis itself ("Present": the value being reproduced).
caplab rows are added per fidelity from the runs of the fixed-cylinder cases (2D, uniform flow,
one fixed circle), read from summary.json: drag_coefficient_mean, lift_coefficient_amplitude,
strouhal_number. Table 2.2 is the thesis's grid series (self-convergence, a verification-type
statement); caplab's Cd is added at the fine spacing each run used.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .references import ReferenceLibrary
from .runs import Run

COLUMNS = ["cd_re100", "cl_re100", "st_re100", "cd_re200", "cl_re200", "st_re200"]
METRICS = {
    "cd": ("drag_coefficient_mean",),
    "cl": ("lift_coefficient_amplitude",),
    "st": ("strouhal_number",),
}


def is_fixed_cylinder(run: Run) -> bool:
    phys = run.physics
    if phys.get("dimension") != 2:
        return False
    flow = phys.get("flow") if isinstance(phys.get("flow"), dict) else {}
    bodies = run.bodies
    if flow.get("type") != "uniform" or len(bodies) != 1 or "membrane" in bodies[0]:
        return False
    shape = bodies[0].get("shape") or {}
    motion = bodies[0].get("motion") or {"type": "fixed"}
    return shape.get("type") == "circle" and motion.get("type") == "fixed"


def _preference(run: Run):
    spacing = run.fine_spacing
    return (run.status == "ok", -(spacing if spacing is not None else 1e9), run.case_id)


@dataclass
class Cell:
    text: str
    css: str = ""
    title: str = ""


@dataclass
class Row:
    label: str
    kind: str
    cells: list[Cell]
    note: str = ""
    css: str = ""


@dataclass
class Tables:
    table_2_1: list[Row] = field(default_factory=list)
    table_2_2: list[Row] = field(default_factory=list)
    extra: list[dict] = field(default_factory=list)
    anchors: dict[str, str] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)

    @property
    def present(self) -> bool:
        return bool(self.table_2_1 or self.table_2_2)


def _fmt(v) -> str:
    return "" if v is None else f"{v:.4g}"


def _run_note(re_value: int, run: Run | None) -> str:
    if run is None:
        return f"Re {re_value}: no run"
    if run.status != "ok":
        return f"Re {re_value}: run {run.status_label}"
    return f"Re {re_value}: {run.case_id}"


def build(runs: list[Run], refs: ReferenceLibrary) -> Tables:
    tables = Tables()
    t21 = refs.get("cylinder", "table_2_1.csv")
    t22 = refs.get("cylinder", "table_2_2.csv")
    extra = refs.get("cylinder", "cylinder_extra_reference_values.csv")
    # Several runs of one Re and fidelity (e.g. a resolution sweep): the finished run on the finest
    # grid stands for it in table 2.1 (sorted so that it comes last and wins).
    cyl = sorted((r for r in runs if is_fixed_cylinder(r) and r.reynolds in (100.0, 200.0)), key=_preference)

    if t21 is None:
        tables.problems.append("references/cylinder/table_2_1.csv not found")
    else:
        tables.anchors["table_2_1"] = t21.anchor
        literature: dict[str, list[float]] = {c: [] for c in COLUMNS}
        for r in t21.rows:
            kind = t21.row_kind(r[0])
            cells = []
            for c in COLUMNS:
                text = t21.cell(r[0], c) or ""
                cells.append(Cell(text if text else "–"))
                if kind == "validation" and text:
                    try:
                        literature[c].append(float(text))
                    except ValueError:
                        pass
            tables.table_2_1.append(Row(r[0], kind, cells, css="thesis" if kind == "thesis" else ""))
        ranges = {c: (min(v), max(v)) for c, v in literature.items() if v}
        tables.table_2_1.append(Row(
            "range of the external studies", "validation",
            [Cell(f"{ranges[c][0]:g} – {ranges[c][1]:g}" if c in ranges else "–") for c in COLUMNS], css="range"))
        present = t21.row("Present")
        for fidelity in sorted({r.fidelity for r in cyl}):
            by_re = {int(r.reynolds): r for r in cyl if r.fidelity == fidelity}
            cells = []
            for c in COLUMNS:
                quantity, re_value = c[:2], int(c[-3:])
                run = by_re.get(re_value)
                value = run.metric(*METRICS[quantity]) if run is not None and run.status == "ok" else None
                if value is None:
                    label = "no run" if run is None else ("–" if run.status == "ok" else run.status_label)
                    cells.append(Cell(label, "na" if run is None or run.status == "ok" else "bad"))
                    continue
                css, title = "", ""
                if c in ranges:
                    lo, hi = ranges[c]
                    inside = lo <= value <= hi
                    css = "in" if inside else "out"
                    title = f"external range {lo:g}–{hi:g}: {'inside' if inside else 'outside'}"
                if present is not None:
                    ptxt = t21.cell("Present", c)
                    if ptxt:
                        pv = float(ptxt)
                        title += f"; thesis {ptxt}: {100 * (value - pv) / pv:+.1f} %"
                cells.append(Cell(_fmt(value), css, title.strip("; ")))
            note = "; ".join(_run_note(rv, by_re.get(rv)) for rv in (100, 200))
            tables.table_2_1.append(Row(f"caplab ({fidelity})", "caplab", cells, note, css="caplab"))
            deviations = []
            for c, cell in zip(COLUMNS, cells):
                ptxt = t21.cell("Present", c) if present is not None else None
                try:
                    value, pv = float(cell.text), float(ptxt)
                except (TypeError, ValueError):
                    deviations.append(Cell("–", "na"))
                    continue
                deviations.append(Cell(f"{100 * (value - pv) / pv:+.1f} %"))
            tables.table_2_1.append(Row(f"caplab ({fidelity}) vs Present", "caplab", deviations,
                                        "relative deviation from the thesis value", css="dev"))

    if t22 is None:
        tables.problems.append("references/cylinder/table_2_2.csv not found")
    else:
        tables.anchors["table_2_2"] = t22.anchor
        for r in t22.rows:
            tables.table_2_2.append(Row(r[0], "thesis", [Cell(r[1] if len(r) > 1 else ""),
                                                         Cell(t22.cell(r[0], "cd_re100") or "–"),
                                                         Cell(t22.cell(r[0], "cd_re200") or "–")]))
        points: dict[tuple[str, int], dict[int, Run]] = {}
        for run in cyl:
            spacing = run.fine_spacing
            if spacing is None:
                continue
            n = int(round(1.0 / spacing))
            points.setdefault((run.fidelity, n), {})[int(run.reynolds)] = run
        for (fidelity, n), by_re in sorted(points.items(), key=lambda kv: (kv[0][1], kv[0][0])):
            cells = [Cell(str(n))]
            for re_value in (100, 200):
                run = by_re.get(re_value)
                value = run.metric("drag_coefficient_mean") if run is not None and run.status == "ok" else None
                if value is None:
                    cells.append(Cell("no run" if run is None else run.status_label, "na" if run is None else "bad"))
                else:
                    cells.append(Cell(_fmt(value)))
            tables.table_2_2.append(Row(f"caplab 1/{n} ({fidelity})", "caplab", cells, css="caplab"))

    if extra is not None:
        tables.anchors["extra"] = extra.anchor
        cols = extra.columns
        for r in extra.rows:
            tables.extra.append({c: (r[i] if i < len(r) else "") for i, c in enumerate(cols)})
    return tables

