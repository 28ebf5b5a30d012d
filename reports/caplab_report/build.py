"""Assembles the report: runs + references -> HTML pages (jinja2) -> PDF (headless Chromium).

Output (``out``):
    index.html, index.pdf            every chapter's verdicts, environment
    chapterN/index.html, index.pdf   one chapter: cases, figures, scorecards, tables 2.1/2.2 (ch2),
                                     capsule families, thesis statements, verification (capsule.py),
                                     3D capsules (capsule3d.py: chapter 5; capsule3d_modes.py: chapter 6),
                                     moving bodies: statements, twins, validation (moving.py)
    references.html                  provenance of every reference dataset, with anchors

Files are written to a temporary name and renamed, under an exclusive lock on ``out/.lock``, so
that two report builds started by parallel ``make`` targets do not interleave.
"""

from __future__ import annotations

import datetime as _dt
import fcntl
import os
import shutil
import subprocess
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import jinja2

from . import capsule, capsule3d, capsule3d_modes, cylinder, figures, moving
from .references import KIND_LABELS, ReferenceLibrary, claim_summary, parameters_text
from .runs import (Run, catalogue_cases, chapter_slug, chapter_sort_key, chapter_title, discover,
                   finite, with_missing)

TEMPLATES = Path(__file__).resolve().parent / "templates"
REPO = Path(__file__).resolve().parents[2]

VERDICT_LABELS = {"pass": "PASS", "fail": "FAIL", "none": "N/A", "missing": "MISSING",
                  "not scored": "NOT SCORED"}


@dataclass
class BuildResult:
    pages: list[Path] = field(default_factory=list)
    pdfs: list[Path] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    runs: list[Run] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not any(p.startswith("PDF") for p in self.problems)


# ---- formatting -------------------------------------------------------------------------------

def fmt_num(v, digits: int = 4) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(fmt_num(x, digits) for x in v) + "]"
    if v is None:
        return "–"
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, (int, float)):
        if not finite(v):
            return str(v)
        if isinstance(v, int):
            return str(v)
        return f"{v:.{digits}g}"
    return str(v)


def fmt_error(v, comparison: str) -> str:
    if comparison == "mode":
        return {0: "match", 1: "mismatch"}.get(v, "–") if finite(v) else "–"
    if not finite(v):
        return fmt_num(v)
    if comparison == "relative":
        return f"{100 * float(v):.2f} %"
    return fmt_num(v)


def fmt_modes(v) -> str:
    """A mode entry's reference: a regime, or the allowed regimes joined by "or"."""
    if isinstance(v, list):
        return " or ".join(str(x) for x in v) or "–"
    return "–" if v is None else str(v)


def fmt_seconds(v) -> str:
    if not finite(v):
        return "–"
    v = float(v)
    if v < 120:
        return f"{v:.1f} s"
    if v < 7200:
        return f"{v / 60:.1f} min"
    return f"{v / 3600:.2f} h"


def verdict_label(v: str) -> str:
    return VERDICT_LABELS.get(v, (v or "–").upper())


# ---- views ------------------------------------------------------------------------------------

def scorecard(run: Run, refs: ReferenceLibrary) -> list[dict]:
    """Rows of the scorecard: every acceptance entry of the case, scored or not, then any scored
    entry the case does not list (so nothing the scorer produced is hidden)."""
    scored = {e.get("metric"): e for e in run.entries}
    rows, seen = [], set()
    acceptance = [a for a in run.case.get("acceptance", []) if isinstance(a, dict)]
    for a in acceptance + [e for e in run.entries if e.get("metric") not in {x.get("metric") for x in acceptance}]:
        metric = a.get("metric", "?")
        if metric in seen:
            continue
        seen.add(metric)
        e = scored.get(metric, {})
        comparison = e.get("comparison") or a.get("comparison") or ""
        ref_value = e.get("reference_value", a.get("reference_value"))
        if comparison == "bracket" and ref_value is None:
            ref_value = a.get("bracket")
        if comparison == "mode" and ref_value is None:
            ref_value = a.get("reference_mode")
        tolerance = e.get("tolerance")
        if tolerance is None:
            tolerance = figures.tolerance_at(a, run.fidelity)
        reference = e.get("reference") or a.get("reference")
        resolved = refs.resolve(reference, ref_value)
        verdict = e.get("verdict") or ("not evaluated" if run.status != "missing" else "missing")
        unit = e.get("unit") or ""
        if not unit:
            m = run.summary.get("metrics", {}).get(metric) if isinstance(run.summary.get("metrics"), dict) else None
            unit = m.get("unit", "") if isinstance(m, dict) else ""
        rows.append({
            "metric": metric,
            "value": fmt_num(e.get("value"), 5) if e else "–",
            "unit": "" if unit in ("1", "-", "") or comparison == "mode" else unit,
            "reference_value": fmt_modes(ref_value) if comparison == "mode" else fmt_num(ref_value),
            "reference": resolved,
            "comparison": comparison,
            "error": fmt_error(e.get("error"), comparison) if e else "–",
            "tolerance": ("exact" if comparison == "mode" else fmt_error(tolerance, comparison)
                          if comparison in ("relative", "absolute") else fmt_num(tolerance)),
            "verdict": verdict,
            "justification": e.get("justification") or a.get("justification") or "",
            "message": e.get("message", ""),
        })
    return rows


def run_view(run: Run, refs: ReferenceLibrary) -> dict:
    figure, series, fig_problem = (None, [], "")
    if run.status != "missing":
        try:
            figure, series, fig_problem = figures.time_histories(run, refs)
        except Exception as err:  # a broken series must not stop the report
            figure, series, fig_problem = None, [], f"figure failed: {err}"
    shares = run.stage_share
    total = sum(shares.values()) or 1.0
    stage = [{"name": k, "share": v, "width": 100.0 * v / total} for k, v in shares.items()]
    threads = run.manifest.get("threads") or run.environment.get("threads")
    return {
        "run": run,
        "figure": figure,
        "series": [{"name": s.name, "unit": "-" if s.unit in ("", "1") else s.unit, "definition": s.definition}
                   for s in series],
        "figure_problem": fig_problem if run.status != "missing" else "",
        "scorecard": scorecard(run, refs),
        "checks": run.sanity_checks,
        "wall_time": fmt_seconds(run.perf("wall_time_s")),
        "mlups": fmt_num(run.perf("mlups"), 3),
        "steps": fmt_num(run.perf("steps")),
        "threads": fmt_num(threads),
        "stages": stage,
    }


def environment_rows(runs: list[Run]) -> tuple[list[dict], list[dict]]:
    """(builds: unique git sha/compiler/flags with the runs using them, per-run rows)."""
    builds: dict[tuple, dict] = {}
    rows = []
    for run in runs:
        if run.status == "missing" or not run.manifest:
            continue
        b, env = run.build, run.environment
        sha = str(b.get("git_sha", "–"))
        dirty = b.get("git_dirty")
        key = (sha, dirty, b.get("compiler"), b.get("flags"))
        entry = builds.setdefault(key, {"git_sha": sha, "git_dirty": dirty, "compiler": b.get("compiler", "–"),
                                        "flags": b.get("flags", "–"), "runs": []})
        entry["runs"].append(f"{run.case_id} ({run.fidelity})")
        rows.append({"case": run.case_id, "fidelity": run.fidelity, "status": run.status_label,
                     "git_sha": sha[:12] + ("+dirty" if dirty else ""),
                     "host": env.get("host", "–"), "cpu": env.get("cpu_model", "–"),
                     "threads": env.get("threads", run.manifest.get("threads", "–")),
                     "date": env.get("date_utc", run.manifest.get("finished_utc", "–"))})
    return list(builds.values()), rows


def counts(runs: list[Run]) -> dict:
    c = {"cases": len(runs), "pass": 0, "fail": 0, "missing": 0, "other": 0}
    for r in runs:
        v = r.verdict
        c[v if v in c else "other"] += 1
    return c


# ---- I/O --------------------------------------------------------------------------------------

def write_atomically(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def locked(out: Path):
    out.mkdir(parents=True, exist_ok=True)
    with open(out / ".lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def chromium_command(chromium: str, profile: str, extra: list[str], html: Path) -> list[str]:
    return [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run", f"--user-data-dir={profile}",
            *extra, html.resolve().as_uri()]


def print_pdf(html: Path, pdf: Path, chromium: str = "chromium", timeout: float = 240) -> str:
    """Prints ``html`` to ``pdf`` with headless Chromium; returns "" or a problem."""
    exe = shutil.which(chromium)
    if exe is None:
        return f"PDF not written: {chromium} not found"
    profile = tempfile.mkdtemp(prefix="caplab-chromium-")
    fd, tmp = tempfile.mkstemp(prefix=f".{pdf.name}.", suffix=".pdf", dir=pdf.parent)
    os.close(fd)
    try:
        cmd = chromium_command(exe, profile, ["--no-pdf-header-footer", f"--print-to-pdf={tmp}"], html)
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout, text=True)
        if proc.returncode != 0 or os.path.getsize(tmp) == 0:
            return f"PDF not written for {html}: chromium exited {proc.returncode}: {proc.stderr.strip()[-500:]}"
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, pdf)
        return ""
    except subprocess.TimeoutExpired:
        return f"PDF not written for {html}: chromium timed out after {timeout:.0f} s"
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
        shutil.rmtree(profile, ignore_errors=True)


@dataclass
class Page:
    """A standalone page (stress, bench): its HTML, its PDF when printed, what went wrong."""
    html: Path
    pdf: Path | None = None
    problems: list[str] = field(default_factory=list)


def publish(out: Path, text: str, pdf: bool, chromium: str, problems: list[str] | None = None) -> Page:
    """Writes OUT/index.html atomically under the folder's lock and, when ``pdf``, prints index.pdf."""
    page = Page(out / "index.html", problems=list(problems or []))
    with locked(out):
        write_atomically(page.html, text)
        if pdf:
            problem = print_pdf(page.html, out / "index.pdf", chromium)
            if problem:
                page.problems.append(problem)
            else:
                page.pdf = out / "index.pdf"
    return page


def git_sha() -> str:
    try:
        out = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short=12", "HEAD"], capture_output=True,
                             text=True, timeout=10)
        return out.stdout.strip() or "–"
    except (OSError, subprocess.SubprocessError):
        return "–"


def environment() -> jinja2.Environment:
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(TEMPLATES)),
                             autoescape=jinja2.select_autoescape(["html", "j2"]),
                             trim_blocks=True, lstrip_blocks=True)
    env.filters.update(num=fmt_num, verdict=verdict_label, seconds=fmt_seconds, claim_summary=claim_summary,
                       claim_parameters=parameters_text,
                       kind=lambda k: KIND_LABELS.get(k, {"caplab": "caplab run"}.get(k, k)))
    return env


# ---- the build --------------------------------------------------------------------------------

def build_report(results: Path, out: Path, references: Path | None = None, catalogue: Path | None = None,
                 fidelities: list[str] | None = None, chapters: list[str] | None = None, pdf: bool = True,
                 chromium: str = "chromium") -> BuildResult:
    result = BuildResult()
    references = references if references is not None else REPO / "references"
    catalogue = catalogue if catalogue is not None else REPO / "catalogue"
    refs = ReferenceLibrary(references)
    result.problems += refs.problems
    if not results.is_dir():
        result.problems.append(f"results folder {results} not found: no runs to report")

    runs = discover(results, fidelities)
    cases = catalogue_cases(catalogue)
    present = {r.chapter for r in runs}
    wanted = {c if not c.isdigit() else f"ch{c}" for c in (chapters or [])}
    all_runs = with_missing(runs, cases, present | wanted, fidelities)
    all_runs.sort(key=lambda r: (chapter_sort_key(r.chapter), r.case_id, r.fidelity))
    result.runs = all_runs
    by_chapter: dict[str, list[Run]] = {}
    for r in all_runs:
        by_chapter.setdefault(r.chapter, []).append(r)
    build_now = sorted(wanted or set(by_chapter), key=chapter_sort_key)

    env = environment()
    meta = {"generated": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
            "results": str(results), "report_git_sha": git_sha(),
            "fidelities": sorted({r.fidelity for r in all_runs}) or (fidelities or [])}

    with locked(out):
        for chapter in build_now:
            chapter_runs = by_chapter.get(chapter, [])
            views = [run_view(r, refs) for r in chapter_runs]
            used = {}
            for v in views:
                for row in v["scorecard"]:
                    ds = row["reference"].dataset
                    if ds is not None:
                        used[ds.anchor] = ds
            tables = cylinder.build(chapter_runs, refs) if chapter == "ch2" else None
            capsules = capsule.build(chapter_runs, moving.without_statements(refs), chapter)
            for ds in capsules.datasets:
                used[ds.anchor] = ds
            result.problems += [f"{chapter}: {p}" for p in capsules.problems]
            capsules3d = capsule3d.build(chapter_runs, refs, chapter)
            for ds in capsules3d.datasets:
                used[ds.anchor] = ds
            result.problems += [f"{chapter}: {p}" for p in capsules3d.problems]
            modes3d = capsule3d_modes.build(chapter_runs, refs, chapter, claims=capsules.claims)
            for ds in modes3d.datasets:
                used[ds.anchor] = ds
            result.problems += [f"{chapter}: {p}" for p in modes3d.problems]
            motions = moving.build(chapter_runs, refs, chapter)
            for ds in motions.datasets:
                used[ds.anchor] = ds
            result.problems += [f"{chapter}: {p}" for p in motions.problems]
            conventions = {}
            if tables is not None:
                for name in ("table_2_1.csv", "table_2_2.csv", "cylinder_extra_reference_values.csv"):
                    ds = refs.get("cylinder", name)
                    if ds is not None:
                        used[ds.anchor] = ds
                result.problems += tables.problems
            for ds in used.values():
                conv = refs.benchmarks.get(ds.benchmark, {}).get("conventions")
                if isinstance(conv, dict):
                    conventions[ds.benchmark] = conv
            builds, env_rows = environment_rows(chapter_runs)
            page = out / chapter_slug(chapter) / "index.html"
            html = env.get_template("chapter.html.j2").render(
                title=f"caplab report — {chapter_title(chapter)}", chapter=chapter,
                chapter_title=chapter_title(chapter), runs=chapter_runs, views=views, counts=counts(chapter_runs),
                tables=tables, capsules=capsules, moving=motions, datasets=sorted(used.values(), key=lambda d: d.rel),
                capsules3d=capsules3d, modes3d=modes3d,
                conventions=conventions,
                builds=builds,
                env_rows=env_rows, meta=meta, cost_figure=figures.cost_vs_error(chapter_runs),
                problems=[p for p in refs.problems], root="../")
            write_atomically(page, html)
            result.pages.append(page)

        chapter_links = []
        for chapter in sorted(by_chapter, key=chapter_sort_key):
            page = out / chapter_slug(chapter) / "index.html"
            chapter_links.append({"chapter": chapter, "title": chapter_title(chapter),
                                  "href": f"{chapter_slug(chapter)}/index.html" if page.exists() else "",
                                  "pdf": f"{chapter_slug(chapter)}/index.pdf",
                                  "counts": counts(by_chapter[chapter])})
        builds, env_rows = environment_rows(all_runs)
        index = out / "index.html"
        write_atomically(index, env.get_template("index.html.j2").render(
            title="caplab report — all chapters", runs=all_runs, chapters=chapter_links, counts=counts(all_runs),
            builds=builds, env_rows=env_rows, meta=meta, problems=result.problems, root="",
            bench_page=(out / "bench" / "index.html").exists(),
            page_of=lambda r: f"{chapter_slug(r.chapter)}/index.html"))
        result.pages.append(index)

        refs_page = out / "references.html"
        write_atomically(refs_page, env.get_template("references.html.j2").render(
            title="caplab report — reference data", refs=refs, meta=meta, root=""))
        result.pages.append(refs_page)

        if pdf:
            for page in result.pages:
                if page.name != "index.html":
                    continue
                target = page.with_suffix(".pdf")
                problem = print_pdf(page, target, chromium)
                if problem:
                    result.problems.append(problem)
                else:
                    result.pdfs.append(target)
    return result
