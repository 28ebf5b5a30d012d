"""Discovery and loading of run directories (the contract of DESIGN.md section 6).

Layout read here (written by scripts/reproduce and ``caplab run``)::

    RESULTS/<fidelity>/<case id with "/" replaced by "__">/       the run directory
        case.json manifest.json series.h5 summary.json score.json
    RESULTS/<fidelity>/<same name>.reproduce.json                  scripts/reproduce's record
    RESULTS/<fidelity>/<same name>.log                             caplab's stdout + stderr

Every file is optional: a run that crashed before writing its manifest, a run still marked
"running" (killed), a case of the catalogue that has no run at all, each becomes a ``Run`` whose
``status`` says so, so that the report can show it instead of leaving it out.
"""

from __future__ import annotations

import fcntl
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: Final statuses written by caplab into manifest.json, plus the ones this module derives.
STATUS_LABELS = {
    "ok": "ok",
    "input_error": "INPUT ERROR",
    "diverged": "DIVERGED",
    "failed": "FAILED",
    "incomplete": "INCOMPLETE",
    "missing": "MISSING",
}

#: Exit codes of ``caplab run`` (DESIGN.md section 6) for runs without a manifest.
EXIT_STATUS = {0: "ok", 1: "ok", 2: "input_error", 3: "diverged", 4: "failed"}

SIDE_SUFFIX = ".reproduce.json"
LOG_SUFFIX = ".log"


def case_dir_name(case_id: str) -> str:
    """Directory name of a case id inside RESULTS/<fidelity>/ ("ch2/x" -> "ch2__x")."""
    return case_id.replace("/", "__")


def case_id_from_dir(name: str) -> str:
    return name.replace("__", "/")


def chapter_of(case_id: str) -> str:
    """Chapter key of a case id: "ch2/cylinder_re100" -> "ch2"; "extra/x" -> "extra"."""
    return case_id.split("/", 1)[0] if "/" in case_id else "other"


def chapter_slug(chapter: str) -> str:
    """Output folder of a chapter: "ch2" -> "chapter2", anything else unchanged."""
    if chapter.startswith("ch") and chapter[2:].isdigit():
        return "chapter" + chapter[2:]
    return chapter


def chapter_title(chapter: str) -> str:
    if chapter.startswith("ch") and chapter[2:].isdigit():
        return "Chapter " + chapter[2:]
    return {"extra": "Cases beyond the thesis", "other": "Other cases"}.get(chapter, chapter)


def chapter_sort_key(chapter: str):
    if chapter.startswith("ch") and chapter[2:].isdigit():
        return (0, int(chapter[2:]), "")
    return (1, 0, chapter)


def read_json(path: Path) -> tuple[Any, str | None]:
    """(content, None) or (None, error message); never raises."""
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh), None
    except FileNotFoundError:
        return None, f"{path.name} missing"
    except (OSError, ValueError) as err:
        return None, f"{path.name} unreadable: {err}"


def finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


@dataclass
class Run:
    """One (case, fidelity) pair: what was run, what came out, and how it was judged."""

    case_id: str
    fidelity: str
    directory: Path | None = None
    case: dict = field(default_factory=dict)
    manifest: dict = field(default_factory=dict)
    summary: dict = field(default_factory=dict)
    score: dict = field(default_factory=dict)
    reproduce: dict = field(default_factory=dict)
    status: str = "missing"
    problems: list[str] = field(default_factory=list)
    log_tail: str = ""

    # ---- identity -------------------------------------------------------------------------
    @property
    def chapter(self) -> str:
        return chapter_of(self.case_id)

    @property
    def anchor(self) -> str:
        return "case-" + case_dir_name(self.case_id).replace(".", "-") + "-" + self.fidelity

    @property
    def title(self) -> str:
        return self.case.get("title") or self.case_id

    @property
    def description(self) -> str:
        return self.case.get("description", "")

    @property
    def series_path(self) -> Path | None:
        return self._file("series.h5")

    @property
    def snapshots_path(self) -> Path | None:
        return self._file("snapshots.h5")

    def _file(self, name: str) -> Path | None:
        if self.directory is None:
            return None
        p = self.directory / name
        return p if p.is_file() else None

    # ---- the case (case.json, or the catalogue file of a missing run) ------------------------
    @property
    def physics(self) -> dict:
        phys = self.case.get("physics")
        return phys if isinstance(phys, dict) else {}

    @property
    def dimension(self) -> int | None:
        d = self.physics.get("dimension")
        return d if isinstance(d, int) else None

    @property
    def bodies(self) -> list[dict]:
        bodies = self.physics.get("bodies")
        return [b for b in bodies if isinstance(b, dict)] if isinstance(bodies, list) else []

    @property
    def reynolds(self) -> float | None:
        r = self.physics.get("reynolds")
        return float(r) if finite(r) else None

    @property
    def fine_spacing(self) -> float | None:
        """numerics.grid.fine_spacing (in L), or None."""
        numerics = self.case.get("numerics") if isinstance(self.case.get("numerics"), dict) else {}
        grid = numerics.get("grid") if isinstance(numerics.get("grid"), dict) else {}
        s = grid.get("fine_spacing")
        return float(s) if finite(s) and s > 0 else None

    def summary_value(self, name: str):
        """The value of summary metric ``name`` as written (number, string, ...), or None."""
        metrics = self.summary.get("metrics") if isinstance(self.summary, dict) else None
        m = metrics.get(name) if isinstance(metrics, dict) else None
        return m.get("value") if isinstance(m, dict) else m

    # ---- verdicts ---------------------------------------------------------------------------
    @property
    def status_label(self) -> str:
        return STATUS_LABELS.get(self.status, self.status.upper())

    def _part(self, name: str) -> str:
        part = self.score.get(name)
        if isinstance(part, dict) and isinstance(part.get("verdict"), str):
            return part["verdict"]
        return ""

    @property
    def sanity(self) -> str:
        """pass | fail | missing | not scored."""
        if self.status == "missing":
            return "missing"
        v = self._part("sanity")
        if v:
            return v
        return "fail" if self.status != "ok" else "not scored"

    @property
    def accuracy(self) -> str:
        """pass | fail | none | missing | not scored."""
        if self.status == "missing":
            return "missing"
        v = self._part("accuracy")
        if v:
            return v
        return "none" if self.status != "ok" else "not scored"

    @property
    def accuracy_reason(self) -> str:
        acc = self.score.get("accuracy")
        if isinstance(acc, dict) and acc.get("reason"):
            return str(acc["reason"])
        if self.status != "ok" and self.status != "missing":
            return f"run {self.status_label.lower()}"
        return ""

    @property
    def verdict(self) -> str:
        """Overall: pass | fail | missing | not scored. A run that is not "ok" always fails."""
        if self.status == "missing":
            return "missing"
        if self.status != "ok":
            return "fail"
        v = self.score.get("verdict")
        if isinstance(v, str) and v:
            return v
        if "fail" in (self.sanity, self.accuracy):
            return "fail"
        return "not scored"

    @property
    def entries(self) -> list[dict]:
        acc = self.score.get("accuracy")
        entries = acc.get("entries") if isinstance(acc, dict) else None
        return [e for e in entries if isinstance(e, dict)] if isinstance(entries, list) else []

    @property
    def sanity_checks(self) -> list[dict]:
        san = self.score.get("sanity")
        checks = san.get("checks") if isinstance(san, dict) else None
        return [c for c in checks if isinstance(c, dict)] if isinstance(checks, list) else []

    # ---- performance ------------------------------------------------------------------------
    def perf(self, key: str):
        perf = self.score.get("performance")
        if isinstance(perf, dict) and perf.get(key) is not None:
            return perf[key]
        return self.manifest.get(key)

    @property
    def stage_share(self) -> dict[str, float]:
        share = self.manifest.get("stage_share")
        if not isinstance(share, dict):
            return {}
        return {k: float(v) for k, v in share.items() if finite(v)}

    @property
    def environment(self) -> dict:
        env = self.manifest.get("environment")
        return env if isinstance(env, dict) else {}

    @property
    def build(self) -> dict:
        b = self.environment.get("build")
        if not isinstance(b, dict):
            b = self.manifest.get("build") if isinstance(self.manifest.get("build"), dict) else {}
        return b

    def metric(self, *names: str):
        """First finite summary value among ``names`` (also matched as "<body>.<name>")."""
        metrics = self.summary.get("metrics") if isinstance(self.summary, dict) else None
        if not isinstance(metrics, dict):
            return None
        for name in names:
            for key, m in metrics.items():
                if key == name or key.endswith("." + name):
                    value = m.get("value") if isinstance(m, dict) else m
                    if finite(value):
                        return float(value)
        return None

    @property
    def average_from(self):
        out = self.case.get("outputs")
        v = out.get("average_from") if isinstance(out, dict) else None
        return float(v) if finite(v) else None


def held_by_a_live_run(directory: Path) -> bool:
    """Whether a caplab process is writing ``directory`` now: a live run holds an exclusive
    ``flock`` on the directory (solver/io/run_directory.cpp), so a shared one is refused here; a
    killed run's lock went with its process."""
    try:
        fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    except OSError:
        return False
    finally:
        os.close(fd)  # also releases the shared lock taken here
    return False


def load_run(directory: Path | None, case_id: str, fidelity: str, side: Path | None = None,
             log: Path | None = None) -> Run:
    run = Run(case_id=case_id, fidelity=fidelity, directory=directory)
    if side is not None and side.is_file():
        data, err = read_json(side)
        if isinstance(data, dict):
            run.reproduce = data
        elif err:
            run.problems.append(err)
    if log is not None and log.is_file():
        try:
            lines = log.read_text(encoding="utf-8", errors="replace").splitlines()
            run.log_tail = "\n".join(lines[-15:])
        except OSError:
            pass

    has_dir = directory is not None and directory.is_dir()
    if has_dir:
        for name in ("case", "manifest", "summary", "score"):
            data, err = read_json(directory / f"{name}.json")
            if isinstance(data, dict):
                setattr(run, name, data)
            elif err and name in ("manifest", "case") or (err and "unreadable" in err):
                run.problems.append(err)

    if run.manifest:
        status = run.manifest.get("status")
        stopped = run.manifest.get("interrupted") if status == "failed" else None
        run.status = "incomplete" if status in (None, "running") or stopped else str(status)
        if status == "running":
            run.problems.append("manifest.json still says \"running\": " + (
                "a caplab process is writing it now (it holds the directory's lock)" if held_by_a_live_run(directory)
                else "its process was killed (nobody holds the directory's lock); a checkpoint, if any, resumes it"))
        if isinstance(stopped, dict):
            run.problems.append(f"stopped by {stopped.get('signal')} after step {stopped.get('step')}, checkpoint "
                                "kept: `caplab run --resume` (or the next reproduce) continues it")
    elif run.reproduce:
        code = run.reproduce.get("exit_code")
        run.status = EXIT_STATUS.get(code, "failed") if isinstance(code, int) else "failed"
        if run.status == "ok":
            run.status = "failed"  # exited 0/1 but left no manifest: not a finished run
        run.problems.append(f"caplab exited with code {code} and left no manifest.json")
    elif has_dir:
        run.status = "incomplete"
    if run.reproduce.get("error"):
        run.problems.append(str(run.reproduce["error"]))
    if run.status == "ok" and not run.score:
        run.problems.append("score.json missing: the run was not scored")
    return run


def discover(results: Path, fidelities: list[str] | None = None) -> list[Run]:
    """All runs under ``results`` (optionally only the given fidelities)."""
    runs: list[Run] = []
    if not results.is_dir():
        return runs
    for fdir in sorted(p for p in results.iterdir() if p.is_dir() and not p.name.startswith(".")):
        fidelity = fdir.name
        if fidelities and fidelity not in fidelities:
            continue
        names: set[str] = set()
        for p in fdir.iterdir():
            if p.name.startswith("."):
                continue
            if p.is_dir():
                names.add(p.name)
            elif p.name.endswith(SIDE_SUFFIX):
                names.add(p.name[: -len(SIDE_SUFFIX)])
        for name in sorted(names):
            side = fdir / (name + SIDE_SUFFIX)
            directory = fdir / name
            case_id = case_id_from_dir(name)
            run = load_run(directory if directory.is_dir() else None, case_id, fidelity, side,
                           fdir / (name + LOG_SUFFIX))
            for source in (run.case.get("id"), run.manifest.get("case_id"), run.reproduce.get("case_id")):
                if isinstance(source, str) and source:
                    run.case_id = source
                    break
            runs.append(run)
    return runs


def catalogue_cases(catalogue: Path | None) -> dict[str, tuple[Path, dict]]:
    """case id -> (file, content) for every case file under ``catalogue`` (schema.json skipped)."""
    cases: dict[str, tuple[Path, dict]] = {}
    if catalogue is None or not catalogue.is_dir():
        return cases
    for path in sorted(catalogue.rglob("*.json")):
        if path.name == "schema.json":
            continue
        data, _ = read_json(path)
        if isinstance(data, dict) and isinstance(data.get("id"), str):
            cases[data["id"]] = (path, data)
    return cases


def with_missing(runs: list[Run], catalogue: dict[str, tuple[Path, dict]], chapters: set[str],
                 fidelities: list[str] | None = None) -> list[Run]:
    """Adds a "missing" run for each catalogue case of ``chapters`` that has no run at one of
    ``fidelities`` (default: the fidelities run for that chapter), and fills in the title and
    description of runs that lack their case.json from the catalogue."""
    out = list(runs)
    for run in out:
        if not run.case and run.case_id in catalogue:
            run.case = dict(catalogue[run.case_id][1])
    fidelities_of: dict[str, set[str]] = {}
    for run in runs:
        fidelities_of.setdefault(run.chapter, set()).add(run.fidelity)
    have = {(r.case_id, r.fidelity) for r in runs}
    for case_id, (path, case) in catalogue.items():
        chapter = chapter_of(case_id)
        if chapter not in chapters:
            continue
        for fidelity in sorted(set(fidelities) if fidelities else fidelities_of.get(chapter, set())):
            if (case_id, fidelity) not in have:
                missing = Run(case_id=case_id, fidelity=fidelity, case=dict(case), status="missing")
                missing.problems.append(f"no run directory for {path.name} at fidelity {fidelity}")
                out.append(missing)
    return out
