#!/usr/bin/python3
"""Converts ../../../shared/refdata/hovering_wing_wang2004_related.csv (or the path given) into
the four reference series of catalogue/extra/hovering_wing_wang2004.json.

Source normalisation (Wang, Birch & Dickinson 2004, as digitized in mesnardo/petibm-flapping):
C_D^n = (drag opposing the translational velocity) / F_qs,max, C_L^n = (vertical force) / F_qs,max,
with the quasi-steady coefficients C_D,qs = 1.4 - cos(2 alpha), C_L,qs = 1.2 sin(2 alpha). Read
literally, "normalised by the maximum quasi-steady force" is a constant: over the stroke
u(t) = U sin(2 pi t/T), alpha(t) = pi/2 + pi/4 sin(2 pi t/T), the products u^2 C_qs peak at
mid-stroke, at 1.4 U^2 (drag) and 1.2 U^2 (lift). (PetIBM's own post-processing divides by an
instantaneous quasi-steady force instead; that differs near stroke reversal only.)

caplab's coefficients are C_x = F_x / (0.5 rho U^2 c), C_y = F_y / (0.5 rho U^2 c), U = pi f A0
the maximum translational speed. The wing centre moves as x = (A0/2) cos(2 pi t/T), so
u_x = -U sin(2 pi t/T) and the drag opposing it is s(t) F_x with s = sign(sin(2 pi t/T)):
    C_x = s(t) * 1.4 * C_D^n,    C_y = 1.2 * C_L^n.
The digitized C_D^n jumps sign at each stroke reversal, but a few thousandths of a period away
from t/T = k/2 (digitization and phase); s flips where the data jump (the largest sign-changing
step within 0.03 T of k/2), so that C_x, a force component, is continuous there.
Time: t = (t/T) * T with T = pi A0 = 8.796 c/U (A0 = 2.8 c).
"""
import csv
import math
import sys
from pathlib import Path

A0 = 2.8
PERIOD = math.pi * A0
SOURCES = {"Wang2004_experiment": "experiment", "Eldredge2007_VVPM": "vvpm"}


def main(source: Path, out: Path) -> None:
    rows = [r for r in csv.DictReader(l for l in source.open() if not l.startswith("#"))]
    for name, short in SOURCES.items():
        for coefficient, axis in (("CD", "cx"), ("CL", "cy")):
            picked = sorted((float(r["t_over_T"]), float(r["value"])) for r in rows
                            if r["source"] == name and r["coefficient"] == coefficient)
            path = out / f"wang2004_{short}_{axis}.csv"
            with path.open("w") as f:
                f.write(f"# {name} {coefficient} from {source.name}, converted by convert_wang2004.py "
                        f"(see provenance.json)\n")
                f.write("t,t_over_T,normalised,c\n")
                unique = []
                for tt, v in picked:
                    if not unique or tt > unique[-1][0]:  # digitized duplicates: keep the first
                        unique.append((tt, v))
                flips = reversal_flips(unique) if coefficient == "CD" else []
                for tt, v in unique:
                    if coefficient == "CD":
                        # s = +1 on the first half-stroke (u_x < 0), flipping at each data jump.
                        c = (-1.0) ** sum(tt > f_ for f_ in flips) * 1.4 * v
                    else:
                        c = 1.2 * v
                    f.write(f"{tt * PERIOD:.6f},{tt:.6f},{v:.6g},{c:.6g}\n")


def reversal_flips(points):
    """t/T where the digitized normalised drag changes sign at each stroke reversal k/2."""
    flips = []
    for k in range(1, int(2 * points[-1][0]) + 1):
        near = [(a, b) for a, b in zip(points, points[1:]) if abs(0.5 * (a[0] + b[0]) - 0.5 * k) < 0.03
                and a[1] * b[1] < 0]
        if near:
            a, b = max(near, key=lambda ab: abs(ab[1][1] - ab[0][1]))
            flips.append(0.5 * (a[0] + b[0]))
        else:
            flips.append(0.5 * k)
    return flips


if __name__ == "__main__":
    here = Path(__file__).resolve().parent
    src = Path(sys.argv[1]) if len(sys.argv) > 1 else here.parents[2] / "shared/refdata/hovering_wing_wang2004_related.csv"
    main(src, here)
