"""The verdicts of the thesis statements (references/*/claims.json), from ``caplab claims``.

The statements are checked in one place, the C++ scorer (solver/score/claims.hpp, which documents
the checks and the layout of the result); the report only shows what it says. ``evaluate`` runs
``caplab claims CLAIMS RUN_DIR... --json FILE`` and returns the parsed result.

Which caplab: ``set_executable`` (scripts/report --caplab), else $CAPLAB, else the build of this
checkout (build/solver/app/caplab). A missing executable or a failed evaluation raises
``ClaimsUnavailable`` with what to do, which the sections turn into a problem of the report.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DEFAULT_EXECUTABLE = REPO / "build" / "solver" / "app" / "caplab"
TIMEOUT_S = 600

_executable: Path | None = None


class ClaimsUnavailable(RuntimeError):
    """caplab claims could not be run or gave no result."""


def set_executable(path: Path | None) -> None:
    global _executable
    _executable = Path(path) if path else None


def executable() -> Path:
    chosen = _executable or (Path(os.environ["CAPLAB"]) if os.environ.get("CAPLAB") else DEFAULT_EXECUTABLE)
    if not chosen.is_file() or not os.access(chosen, os.X_OK):
        raise ClaimsUnavailable(f"the caplab executable {chosen} is not there: run `make build`, or give "
                                "scripts/report --caplab BIN (or set CAPLAB)")
    return chosen


def evaluate(claims: Path | dict, run_dirs: list[Path], only: str | None = None,
             provenance: dict | None = None) -> dict:
    """``caplab claims`` on the claims file (or document) ``claims`` and the run directories. For a
    document, ``provenance`` is written beside it as the provenance.json caplab reads settings from
    (e.g. "consistency" of references/moving); a file has its own."""
    with tempfile.TemporaryDirectory(prefix="caplab-claims-") as tmp:
        if isinstance(claims, dict):
            path = Path(tmp) / "claims.json"
            path.write_text(json.dumps(claims), encoding="utf-8")
            if provenance is not None:
                (Path(tmp) / "provenance.json").write_text(json.dumps(provenance), encoding="utf-8")
        else:
            path = Path(claims)
        out = Path(tmp) / "result.json"
        cmd = [str(executable()), "claims", str(path), *map(str, run_dirs), "--json", str(out)]
        if only:
            cmd += ["--only", only]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S)
        except (OSError, subprocess.TimeoutExpired) as err:
            raise ClaimsUnavailable(f"`caplab claims {path.name}` could not run: {err}") from err
        if proc.returncode != 0 or not out.is_file():
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
            raise ClaimsUnavailable(f"`caplab claims {path.name}` exited with {proc.returncode}: " + " ".join(tail))
        return json.loads(out.read_text(encoding="utf-8"))
