"""Reference datasets and their provenance (DESIGN.md section 7).

``references/<benchmark>/provenance.json`` describes each dataset of the folder (source, table or
figure, how obtained, uncertainty, columns, and per row or per dataset a ``kind``), and may carry
``analytic`` reference solutions (formulas with their source) and ``not_available`` notes (data a
thesis figure is compared with that caplab does not have). A dataset is a CSV, or a JSON file of
thesis statements ``{"claims": [{"id", "section", "figure", "sentence", "kind", ...}]}`` (format in
references/capsule2d/provenance.json), or, with ``"format": "sweeps"`` in its provenance entry, the
parameter sweeps of ``make stress`` (references/stress/sweeps.json). A case names a reference as
``references/<benchmark>/<file>.csv#<key>`` where the key is ``<row>:<column>`` (row matched
against the first column, e.g. ``Present:cd_re100``) or ``<t column>:<value column>`` for a
reference series, as ``references/<benchmark>/claims.json#<claim id>``, as
``references/<benchmark>/provenance.json#<analytic entry>``, or the literal ``value`` for a value
stated in the case itself.

The kind separates validation (external data, thesis statements) from a thesis value being
reproduced and from verification (analytic, convergence, invariants); the report never mixes
them up.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from .runs import read_json

KIND_LABELS = {
    "validation": "validation (external data)",
    "thesis": "thesis value (reproduction)",
    "verification": "verification (analytic / convergence / invariant)",
    "statement": "thesis statement (validation against a stated mode, bracket, bound or trend)",
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
    claims: dict[str, dict] = field(default_factory=dict)  #: claim id -> claim (a claims JSON)
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
            files = sorted(bench_dir.glob("*.csv")) + sorted(
                p for p in bench_dir.glob("*.json") if p.name != "provenance.json")
            for path in files:
                ds = Dataset(bench_dir.name, path.name, path, described.get(path.name, {}))
                if not ds.provenance:
                    self.problems.append(f"{ds.rel}: no entry in provenance.json")
                if path.suffix == ".json" and ds.provenance.get("format") == "sweeps":
                    pass  # a sweep definition (references/stress/sweeps.json, scripts/stress), not claims
                elif path.suffix == ".json":
                    self._read_claims(ds)
                else:
                    try:
                        ds.header_comments, ds.columns, ds.rows = read_csv(path)
                    except (OSError, UnicodeDecodeError, csv.Error) as err2:
                        ds.error = str(err2)
                self.datasets[(bench_dir.name, path.name)] = ds
            for name in described:
                if (bench_dir.name, name) not in self.datasets:
                    self.problems.append(f"references/{bench_dir.name}/{name}: described in provenance.json but missing")

    def _read_claims(self, ds: Dataset) -> None:
        try:
            doc = json.loads(ds.path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, ValueError) as err:
            ds.error = str(err)
            self.problems.append(f"{ds.rel}: unreadable: {err}")
            return
        claims = doc.get("claims") if isinstance(doc, dict) else None
        if not isinstance(claims, list):
            ds.error = "no \"claims\" array"
            self.problems.append(f"{ds.rel}: no \"claims\" array")
            return
        for c in claims:
            cid = c.get("id") if isinstance(c, dict) else None
            if not isinstance(cid, str) or not cid:
                self.problems.append(f"{ds.rel}: a claim without an id")
            elif cid in ds.claims:
                self.problems.append(f"{ds.rel}: claim id {cid} appears twice")
            else:
                ds.claims[cid] = c

    def get(self, benchmark: str, filename: str) -> Dataset | None:
        return self.datasets.get((benchmark, filename))

    def claims(self, prefix: str = "") -> list[tuple[Dataset, dict]]:
        """Every claim (with its dataset) whose id starts with ``prefix``, in file order."""
        return [(ds, c) for ds in self.datasets.values() for cid, c in ds.claims.items() if cid.startswith(prefix)]

    def provenance_entries(self, key: str) -> list[tuple[str, object]]:
        """(benchmark, value) of provenance.json ``key`` (e.g. "not_available") of every benchmark."""
        return [(b, prov[key]) for b, prov in self.benchmarks.items() if prov.get(key)]

    def resolve(self, reference, reference_value=None) -> "ResolvedReference":
        """What a reference string of a case points to (never raises)."""
        if not isinstance(reference, str) or not reference:
            return ResolvedReference(text=str(reference or "-"), kind="unknown")
        if reference == "value":
            return ResolvedReference(text="value in the case file", kind="stated")
        path, _, key = reference.rpartition("#") if "#" in reference else (reference, "", "")
        parts = Path(path).parts
        if len(parts) == 3 and parts[0] == "references" and parts[2] == "provenance.json":
            return self._resolve_analytic(reference, parts[1], key, reference_value)
        if len(parts) >= 3 and parts[0] == "references":
            ds = self.get(parts[1], parts[-1])
        else:
            ds = None
        if ds is None:
            return ResolvedReference(text=reference, kind="unknown",
                                     note=f"{path} not found under references/ or not described")
        res = ResolvedReference(text=reference, dataset=ds, key=key, kind=ds.kind or "unknown")
        if ds.claims or path.endswith(".json"):
            return self._resolve_claim(res, reference_value)
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


    def _resolve_analytic(self, reference: str, benchmark: str, key: str, reference_value) -> "ResolvedReference":
        """An analytic entry of a provenance.json (``references/<b>/provenance.json#<entry>``)."""
        analytic = self.benchmarks.get(benchmark, {}).get("analytic")
        entry = analytic.get(key) if isinstance(analytic, dict) else None
        if not isinstance(entry, dict):
            return ResolvedReference(text=reference, kind="unknown", mismatch=True,
                                     note=f"no analytic entry {key or '(no #key)'} in references/{benchmark}/provenance.json")
        res = ResolvedReference(text=reference, kind=entry.get("kind", "verification"), key=key, analytic=entry,
                                note=" — ".join(str(entry[k]) for k in ("title", "formula") if entry.get(k)))
        value = entry.get("value")
        if finite_number(value) and finite_number(reference_value):
            res.table_value = f"{value:.10g}"
            if not math.isclose(float(value), float(reference_value), rel_tol=1e-9, abs_tol=1e-12):
                res.note += f" — reference_value {reference_value} differs from the analytic value {value:.10g}"
                res.mismatch = True
        return res

    @staticmethod
    def _resolve_claim(res: "ResolvedReference", reference_value) -> "ResolvedReference":
        claim = res.dataset.claims.get(res.key)
        if claim is None:
            res.note = f"claim {res.key or '(no #id)'} not in {res.dataset.filename}"
            res.mismatch = True
            return res
        res.claim = claim
        res.kind = "statement"
        where = f"thesis {claim.get('section', '?')}" + (f", fig. {claim['figure']}" if claim.get("figure") else "")
        res.note = f"{where}: \u201c{claim.get('sentence', '')}\u201d"
        wanted = claim_modes(claim)
        given = [reference_value] if isinstance(reference_value, str) else reference_value
        if wanted and isinstance(given, list) and all(isinstance(g, str) for g in given):
            extra = [g for g in given if g not in wanted]
            if extra:
                res.note += f" — reference_mode {', '.join(extra)} is not what the claim states ({', '.join(wanted)})"
                res.mismatch = True
        return res


# ---- thesis statements (claims JSON) ------------------------------------------------------------

MODE_NAMES = ("steady_tank_treading", "oscillating_tank_treading", "tumbling")


def finite_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
PARAMETER_SYMBOLS = {"shape": "", "aspect_ratio": "r", "alpha": "α", "reference_curvature": "κ0",
                     "capillary": "G", "bending_ratio": "E_b", "reynolds": "Re"}


def claim_modes(claim: dict) -> list[str]:
    """The regime(s) a mode claim allows ("mode" or "modes"); [] for other claims."""
    if claim.get("kind") != "mode":
        return []
    modes = claim.get("modes", claim.get("mode"))
    modes = [modes] if isinstance(modes, str) else modes
    return [m for m in modes if isinstance(m, str)] if isinstance(modes, list) else []


def parameter_text(value) -> str:
    if isinstance(value, dict):
        return f"{value.get('from', '?'):g} … {value.get('to', '?'):g}" if all(
            isinstance(value.get(k), (int, float)) for k in ("from", "to")) else str(value)
    if isinstance(value, list):
        return ", ".join(parameter_text(v) for v in value)
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def parameters_text(params) -> str:
    """"ellipse, r = 2, κ0 = initial, G = 0.04, E_b = 0.06" for a claim's parameters."""
    if not isinstance(params, dict):
        return ""
    parts = []
    for key, value in params.items():
        symbol = PARAMETER_SYMBOLS.get(key, key)
        parts.append(parameter_text(value) if not symbol else f"{symbol} = {parameter_text(value)}")
    return ", ".join(parts)


def claim_summary(claim: dict) -> str:
    """The structured content of a claim in one line."""
    kind = claim.get("kind")
    what = claim.get("metric") or claim.get("quantity") or "?"
    if kind == "mode":
        return " or ".join(claim_modes(claim))
    if kind == "bracket":
        lo, hi = (claim.get("between") or ["?", "?"])[:2]
        symbol = PARAMETER_SYMBOLS.get(claim.get("varying", ""), claim.get("varying", "?"))
        return f"transition at {lo} < {symbol} < {hi}: {claim.get('below', '?')} below, {claim.get('above', '?')} above"
    if kind == "trend":
        varying = claim.get("varying")
        varying = varying if isinstance(varying, list) else [varying]
        direction = claim.get("direction")
        direction = direction if isinstance(direction, list) else [direction] * len(varying)
        text = "; ".join(f"{what} {d} with {PARAMETER_SYMBOLS.get(v, v) or v}" for v, d in zip(varying, direction))
        if claim.get("limit") is not None:
            text += f" (limit {claim['limit']:g})"
        if claim.get("sequence"):
            text += ": " + " → ".join(claim["sequence"])
        return text
    if kind == "bound":
        parts = []
        if claim.get("lower") is not None:
            parts.append(f"{what} {'>' if claim.get('strict') else '≥'} {claim['lower']:g}")
        if claim.get("upper") is not None:
            parts.append(f"{what} {'<' if claim.get('strict') else '≤'} {claim['upper']:g}")
        return " and ".join(parts) or f"{what}: bounded (no number stated)"
    if kind == "value":
        value = claim.get("value")
        text = f"{what} = {parameter_text(value) if not isinstance(value, dict) else json.dumps(value)}"
        if value is None:
            text = what
        if claim.get("unit"):
            text += f" [{claim['unit']}]"
        if claim.get("agreement"):
            text += f"; agreement: {claim['agreement']}"
        return text
    return ""


@dataclass
class ResolvedReference:
    text: str
    kind: str = "unknown"
    dataset: Dataset | None = None
    key: str = ""
    table_value: str | None = None
    note: str = ""
    mismatch: bool = False
    claim: dict | None = None
    analytic: dict | None = None  #: an analytic entry of a provenance.json

    @property
    def kind_label(self) -> str:
        return KIND_LABELS.get(self.kind, self.kind)

    @property
    def anchor(self) -> str:
        return self.dataset.anchor if self.dataset else ""
