"""Reference datasets and their provenance (DESIGN.md section 7).

``references/<benchmark>/provenance.json`` describes each CSV of the folder (source, table or
figure, how obtained, uncertainty, columns, and per row or per dataset a ``kind``). A case names a
reference as ``references/<benchmark>/<file>.csv#<key>`` where the key is ``<row>:<column>``
(row matched against the first column, e.g. ``Present:cd_re100``) or ``<t column>:<value
column>`` for a reference series, or the literal ``value`` for a value stated in the case itself.

The kind separates validation (external data) from a thesis value being reproduced and from
verification (analytic, convergence, invariants); the report never mixes them up.
"""

from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from .runs import read_json

KIND_LABELS = {
    "validation": "validation (external data)",
    "thesis": "thesis value (reproduction)",
    "verification": "verification (analytic / convergence / invariant)",
    "stated": "value stated in the case file",
    "unknown": "no provenance found",
}


def anchor_for(benchmark: str, filename: str) -> str:
    return "ref-" + re.sub(r"[^A-Za-z0-9_-]+", "-", f"{benchmark}-{filename}").strip("-")


@dataclass
class Dataset:
    benchmark: str
    filename: str
    path: Path
    provenance: dict
    header_comments: list[str] = field(default_factory=list)
    columns: list[str] = field(default_factory=list)
    rows: list[list[str]] = field(default_factory=list)
    error: str = ""

    @property
    def anchor(self) -> str:
        return anchor_for(self.benchmark, self.filename)

    @property
    def rel(self) -> str:
        return f"references/{self.benchmark}/{self.filename}"

    @property
    def kind(self) -> str:
        return self.provenance.get("kind", "") if self.provenance else ""

    def row(self, name: str) -> list[str] | None:
        for r in self.rows:
            if r and r[0] == name:
                return r
        return None

    def cell(self, row: str, column: str) -> str | None:
        r = self.row(row)
        if r is None or column not in self.columns:
            return None
        i = self.columns.index(column)
        return r[i] if i < len(r) else None

    def column_values(self, column: str) -> list[float]:
        if column not in self.columns:
            return []
        i = self.columns.index(column)
        out = []
        for r in self.rows:
            try:
                out.append(float(r[i]))
            except (IndexError, ValueError):
                out.append(math.nan)
        return out

    def row_kind(self, row: str) -> str:
        rows = self.provenance.get("rows") if self.provenance else None
        if isinstance(rows, dict) and isinstance(rows.get(row), dict):
            return rows[row].get("kind", "") or self.kind
        return self.kind


def read_csv(path: Path) -> tuple[list[str], list[str], list[list[str]]]:
    """(comment lines without '#', header, rows) of a CSV whose provenance lines start with '#'."""
    comments, body = [], []
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            comments.append(line[1:].strip())
        elif line.strip():
            body.append(line)
    table = list(csv.reader(io.StringIO("\n".join(body))))
    if not table:
        return comments, [], []
    return comments, [c.strip() for c in table[0]], [[c.strip() for c in r] for r in table[1:]]


class ReferenceLibrary:
    """Every dataset under a references/ folder, with its provenance."""

    def __init__(self, root: Path | None):
        self.root = root
        self.datasets: dict[tuple[str, str], Dataset] = {}
        self.benchmarks: dict[str, dict] = {}
        self.problems: list[str] = []
        if root is None or not root.is_dir():
            if root is not None:
                self.problems.append(f"reference folder {root} not found")
            return
        for bench_dir in sorted(p for p in root.iterdir() if p.is_dir()):
            prov, err = read_json(bench_dir / "provenance.json")
            if not isinstance(prov, dict):
                prov = {}
                self.problems.append(f"references/{bench_dir.name}: {err or 'provenance.json is not an object'}")
            self.benchmarks[bench_dir.name] = prov
            described = prov.get("datasets") if isinstance(prov.get("datasets"), dict) else {}
            for csv_path in sorted(bench_dir.glob("*.csv")):
                ds = Dataset(bench_dir.name, csv_path.name, csv_path, described.get(csv_path.name, {}))
                if not ds.provenance:
                    self.problems.append(f"{ds.rel}: no entry in provenance.json")
                try:
                    ds.header_comments, ds.columns, ds.rows = read_csv(csv_path)
                except (OSError, UnicodeDecodeError, csv.Error) as err2:
                    ds.error = str(err2)
                self.datasets[(bench_dir.name, csv_path.name)] = ds
            for name in described:
                if (bench_dir.name, name) not in self.datasets:
                    self.problems.append(f"references/{bench_dir.name}/{name}: described in provenance.json but missing")

    def get(self, benchmark: str, filename: str) -> Dataset | None:
        return self.datasets.get((benchmark, filename))

    def resolve(self, reference, reference_value=None) -> "ResolvedReference":
        """What a reference string of a case points to (never raises)."""
        if not isinstance(reference, str) or not reference:
            return ResolvedReference(text=str(reference or "-"), kind="unknown")
        if reference == "value":
            return ResolvedReference(text="value in the case file", kind="stated")
        path, _, key = reference.rpartition("#") if "#" in reference else (reference, "", "")
        parts = Path(path).parts
        if len(parts) >= 3 and parts[0] == "references":
            ds = self.get(parts[1], parts[-1])
        else:
            ds = None
        if ds is None:
            return ResolvedReference(text=reference, kind="unknown",
                                     note=f"{path} not found under references/ or not described")
        res = ResolvedReference(text=reference, dataset=ds, key=key, kind=ds.kind or "unknown")
        if ":" in key:
            row, column = key.split(":", 1)
            cell = ds.cell(row, column)
            if cell is not None:
                res.kind = ds.row_kind(row) or res.kind
                res.table_value = cell
                try:
                    tv = float(cell)
                except ValueError:
                    res.note = f"{key}: not a number in {ds.filename}"
                else:
                    if isinstance(reference_value, (int, float)) and not isinstance(reference_value, bool):
                        if not math.isclose(tv, float(reference_value), rel_tol=1e-9, abs_tol=1e-12):
                            res.note = f"reference_value {reference_value} differs from {ds.filename} ({cell})"
                            res.mismatch = True
            elif row in ds.columns and column in ds.columns:
                res.note = f"series {row} -> {column} of {ds.filename}"
            else:
                res.note = f"key {key} not found in {ds.filename}"
                res.mismatch = True
        if not res.kind:
            res.kind = "unknown"
        return res


@dataclass
class ResolvedReference:
    text: str
    kind: str = "unknown"
    dataset: Dataset | None = None
    key: str = ""
    table_value: str | None = None
    note: str = ""
    mismatch: bool = False

    @property
    def kind_label(self) -> str:
        return KIND_LABELS.get(self.kind, self.kind)

    @property
    def anchor(self) -> str:
        return self.dataset.anchor if self.dataset else ""
