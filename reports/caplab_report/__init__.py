"""caplab report builder (DESIGN.md section 7).

Reads run directories written by ``caplab run`` (DESIGN.md section 6) under a results tree
``RESULTS/<fidelity>/<case id with / replaced by __>/`` and the reference datasets with their
provenance under ``references/``, and writes self-contained HTML pages (figures embedded as
base64 PNG) plus a PDF of each page printed by headless Chromium:

- ``OUT/index.html`` (+ ``index.pdf``): every verdict of every chapter, environment;
- ``OUT/chapterN/index.html`` (+ ``index.pdf``): per case title, description, time histories
  with reference bands, scorecard, cost; for chapter 2 the thesis tables 2.1 and 2.2 reproduced
  (cylinder.py); for capsule cases (capsule.py) the families overlaid like the thesis figures,
  Jeffery's orbit, membrane contours, the thesis statements checked against the runs, and
  self-convergence;
- ``OUT/references.html``: the provenance of every reference dataset, with anchors;
- ``reports/out/stress/index.html`` (+ PDF): the stability maps of ``make stress``, built by
  stress.py (classification, references, boundaries) and stress_theory.py (the explicit-coupling
  limit) from the stress.json that scripts/stress writes.

Runs that failed, diverged, never finished or are missing are shown as such, never omitted.
Entry point: ``scripts/report`` (``python -m caplab_report`` with ``reports/`` on the path).
"""

__all__ = ["main"]


def main(argv=None):
    from .cli import main as _main

    return _main(argv)
