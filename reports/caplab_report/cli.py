"""Command line of the report builder (called by scripts/report and scripts/reproduce)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import claims
from .build import REPO, build_report


def parse_args(argv=None) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="scripts/report", description=(
        "Build the caplab HTML + PDF report from a results tree RESULTS/<fidelity>/<case>/ "
        "(DESIGN.md sections 6-7)."))
    p.add_argument("--results", type=Path, default=Path("results"), help="results tree (default: results)")
    p.add_argument("--out", type=Path, default=REPO / "reports" / "out", help="output folder (default: reports/out)")
    p.add_argument("--references", type=Path, default=REPO / "references", help="reference datasets (default: references/)")
    p.add_argument("--catalogue", type=Path, default=REPO / "catalogue",
                   help="case catalogue, to list cases without a run as missing (default: catalogue/)")
    p.add_argument("--fidelity", action="append", default=[],
                   help="only runs at this fidelity (repeatable; default: every fidelity found)")
    p.add_argument("--chapter", action="append", default=[],
                   help="build only these chapter pages, e.g. 2 or ch2 (repeatable; default: every chapter found); "
                        "the overall index always covers every chapter")
    p.add_argument("--no-pdf", action="store_true", help="skip printing the PDFs")
    p.add_argument("--chromium", default="chromium", help="Chromium executable for the PDFs (default: chromium)")
    p.add_argument("--caplab", type=Path, default=None,
                   help="caplab executable that checks the thesis statements (`caplab claims`; default: $CAPLAB, "
                        "else build/solver/app/caplab)")
    return p.parse_args(argv)


def main(argv=None) -> int:
    args = parse_args(argv)
    claims.set_executable(args.caplab)
    result = build_report(args.results, args.out, args.references, args.catalogue, args.fidelity or None,
                          args.chapter or None, pdf=not args.no_pdf, chromium=args.chromium)
    for problem in result.problems:
        print(f"report: {problem}", file=sys.stderr)
    for page in result.pages:
        print(f"report: wrote {page}")
    for pdf in result.pdfs:
        print(f"report: wrote {pdf}")
    verdicts = {}
    for run in result.runs:
        verdicts[run.verdict] = verdicts.get(run.verdict, 0) + 1
    print("report: " + ", ".join(f"{n} {v}" for v, n in sorted(verdicts.items())) if verdicts else "report: no runs")
    return 0 if result.ok else 1
