"""Observed order of convergence and Richardson extrapolation, shared by the 3D grid study
(capsule3d.py) and the run-time-against-error series (bench.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class Order:
    order: float
    extrapolated: float


def observed_order(spacings, values) -> Order | None:
    """Observed order p and the Richardson-extrapolated f0 of f(h) = f0 + C h^p through three
    (spacing, value) points, any spacing ratios (Roache 1998; Celik et al. 2008, J. Fluids Eng.
    130:078001). None for oscillatory or stalled convergence or an order outside (0.05, 20)."""
    pts = sorted((float(h), float(f)) for h, f in zip(spacings, values))
    if len(pts) != 3 or not all(math.isfinite(x) for pt in pts for x in pt):
        return None
    (h1, f1), (h2, f2), (h3, f3) = pts
    if not 0 < h1 < h2 < h3:
        return None
    e21, e32 = f2 - f1, f3 - f2
    if e21 == 0 or e32 == 0 or (e32 / e21) <= 0:
        return None
    ratio = e32 / e21

    def g(p):
        return (h3 ** p - h2 ** p) / (h2 ** p - h1 ** p) - ratio

    lo, hi = 0.05, 20.0
    if g(lo) * g(hi) > 0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0:
            hi = mid
        else:
            lo = mid
    p = 0.5 * (lo + hi)
    c = e21 / (h2 ** p - h1 ** p)
    return Order(p, f1 - c * h1 ** p)
