"""The layout shared by the generated 3D capsule catalogues (scripts/generate-ch5-cases and
scripts/generate-ch6-cases): one function builds a case file from the physical parameters,
with the fidelity levels every 3D capsule case has. Imported by those scripts only.

Conventions (references/capsule3d/provenance.json): L = a (equivalent radius), velocity k a,
time 1/k, Re = rho k a^2 / mu (thesis section 5.3), G = mu k a / E with the E of eq. 5.1-5.3,
shear u = (k z, 0, 0): x-z is the shear plane.
"""
import math
from fractions import Fraction

SERIES = ["taylor_deformation", "inclination", "length", "width", "thickness", "volume_change",
          "surface_area_change", "max_area_change", "tank_treading_phase"]


def fmt(x):
    return f"{x:g}"


def exact_lattice_velocity(re, fine_per_a, tau_f):
    """k a in lattice units that puts the fine block at relaxation time tau_f:
    nu_f = (tau_f - 1/2)/3 = U a_f / Re with a_f = a / dx_f."""
    return (tau_f - 0.5) / 3 * re / fine_per_a


def lattice_velocity(re, fine_per_a, tau_f):
    """exact_lattice_velocity as the case files write it (6 decimals)."""
    return round(exact_lattice_velocity(re, fine_per_a, tau_f), 6)


# The explicit membrane-fluid coupling is stable while the membrane's stiffest modulus in lattice units,
# E_lu = nu_lu U_lu / G x stiffness_factor = U_lu^2 a_lu / (Re G) x stiffness_factor, stays small (C++:
# sim::membrane_lattice_modulus; the limit make stress measured on the NH sphere is E_lu about 2-4). The
# chapter 5 spheres run at 0.17 (standard) and 0.33 (quick). Measured failures: the biconcave cell at
# G = 0.0005 with the default tau_f = 3.5 (E_lu = 25 at quick) blew up within a few hundred steps; before the
# Skalak factor entered the rule, the chapter 6 biconcave cells at quick blew up at 6.5 (C = 23, 83 steps) and
# 3.2 (C = 120, 3500 steps) and ran through at 2.5. E_MAX = 0.5 keeps a factor 4-8 below the limit: above it
# the lattice velocity is lowered (smaller time steps, tau_f closer to 1/2) until E_lu = E_MAX.
E_MAX = 0.5


def stiffness_factor(law, C=None):
    """How much stiffer than NH of the same E the law is at small strain in its stiffest in-plane mode (C++:
    sim::membrane_stiffness_factor): 1 for NH and ZT; Skalak max(3/2, (1 + 2C)/2) (area modulus (2 + 4C) E
    against NH's 4E; shear modulus E/2 against E/3)."""
    return max(1.5, 0.5 * (1.0 + 2.0 * C)) if law == "skalak" else 1.0


def stable_tau_f(re, a_lu, G, law, C=None, tau_f=3.5):
    """tau_f of the fine grid (a_lu nodes per a): the given one, or lower where E_lu would pass E_MAX."""
    u = min(exact_lattice_velocity(re, a_lu, tau_f), math.sqrt(E_MAX * re * G / (a_lu * stiffness_factor(law, C))))
    return round(0.5 + 3 * u * a_lu / re, 4)


def stable_time_step(re, a_lu, G, law, C=None, tau_f=3.5):
    """case() keywords tau_f and quick_speedup from the rule: tau_f as given or lower where E_lu would pass
    E_MAX; quick (half the resolution, where E_lu doubles at the same tau_f) multiplies the lattice velocity by 2,
    or less, until E_lu = E_MAX."""
    tau_f = stable_tau_f(re, a_lu, G, law, C, tau_f)
    u = exact_lattice_velocity(re, a_lu, tau_f)
    speedup = round(min(2.0, math.sqrt(E_MAX * re * G / (a_lu / 2 * stiffness_factor(law, C))) / u), 4)
    return {"tau_f": tau_f, "quick_speedup": speedup}


OBLATE_SMALL_SWING = dict(oscillation_threshold=0.25, note=(
    "Swinging counts from a 0.5-degree reversal (outputs.oscillation_threshold 0.25, against the default 1): the nearly "
    "spherical capsule at this G swings by 1.27 degrees peak to peak (ch5, theta 20.07-21.34 degrees, D 0.499-0.523, "
    "period about 10/k; ch6 to k t = 40, theta 20.04-21.35 degrees, period about 12/k; standard, 2026-12-05), below "
    "the default's 2 degrees, while the NH sphere's wobble at G = 0.2 (the discrete membrane turning) is 0.23 degrees "
    "peak to peak (ch5/sphere_nh_G0.2, standard)."))


def oblate_small_swing(label, G):
    """Arguments of case() for an oblate spheroid (label "10to9", "3to2", "2to1") at capillary G: the 10:9 capsule at
    G = 0.2 swings by less than the default oscillation_threshold's 2 degrees peak to peak, in chapters 5 and 6 alike."""
    return dict(OBLATE_SMALL_SWING) if (label, G) == ("10to9", 0.2) else {}


def case(cid, title, description, *, chapter="ch5", shape, law, G, re, domain, fine, fine_per_a, subdivisions,
         end_time, average_from, walls=False, C=None, refinement="two_level", tau_f=3.5,
         acceptance=(), quick_end=None, snapshots=(), quick_speedup=2, performance=None, quick_margin=0,
         series=SERIES, magic=None, quick_at_standard=None, note="", oscillation_threshold=None):
    """One case file. magic: the TRT magic parameter where the default 1/4 does not do (as a fraction string
    "1/12"); quick_at_standard: why quick keeps the standard grid (then quick is the standard run); note: a last
    sentence of the description (why magic or oscillation_threshold is set); oscillation_threshold: degrees,
    outputs.oscillation_threshold where a smaller swing than the default's must count."""
    u = lattice_velocity(re, fine_per_a, tau_f)
    membrane = {"law": law, "capillary": G, "subdivisions": subdivisions}
    if C is not None:
        membrane["area_dilation"] = C
    grid = {"refinement": refinement, "fine_spacing": round(1.0 / fine_per_a, 10)}
    if refinement == "two_level":
        grid["fine_region"] = {"min": [fine[0]] * 3, "max": [fine[1]] * 3}
    size = list(domain) if isinstance(domain, (list, tuple)) else [domain] * 3
    doc = {
        "id": f"{chapter}/{cid}",
        "title": title,
        "description": description + (
            f" Lattice: fine spacing a/{fine_per_a}, k a = {u:g} in lattice units (tau_f = {tau_f}, TRT"
            + (f" with magic {magic}" if magic else "") + "), "
            f"{4 ** subdivisions * 8} triangles, single-precision populations (measured on the NH sphere at G = 0.05: "
            "the same steady D as double precision to 1e-6, 13 % less run time at quick; level thesis: double). "
            + (f"Quick: the standard resolution. {quick_at_standard}" if quick_at_standard else
               f"Quick: half the resolution (a/{fine_per_a // 2}, {4 ** (subdivisions - 1) * 8} triangles) and "
               + ("twice the lattice velocity (same tau_f)." if quick_speedup == 2 else
                  "the same lattice velocity (the walls' Mach number stays below 0.25; tau_f closer to 1/2)."
                  if quick_speedup == 1 else
                  f"{quick_speedup:g} times the lattice velocity (the membrane's lattice modulus bounds the time step)."))
            + (f" {note}" if note else "")),
        "physics": {
            "dimension": 3,
            "flow": {"type": "shear"},
            "reynolds": re,
            "domain": {"size": size,
                       "boundaries": ["periodic", "periodic", "wall"] if walls else ["far_field"] * 3},
            "bodies": [{"name": "capsule",
                        "shape": dict(shape, center=[x / 2 for x in size], diameter=2),
                        "membrane": membrane}],
        },
        "numerics": {
            "grid": grid,
            "collision": {"operator": "trt", **({"magic": float(Fraction(magic))} if magic else {})},
            "precision": "single",
            "ib": {"kernel": "cosine4"},
            "lattice_velocity": u,
            "end_time": end_time,
        },
        "fidelity": {
            "quick": {"numerics.grid.fine_spacing": round(2.0 / fine_per_a, 10),
                      "numerics.lattice_velocity": round(quick_speedup * u, 8),
                      "physics.bodies.0.membrane.subdivisions": subdivisions - 1,
                      **({"numerics.end_time": quick_end} if quick_end else {})},
            "standard": {},
            "thesis": {"numerics.precision": "double"},
        },
        "outputs": {
            "series": {"interval": 0.05, "quantities": list(series)},
            # t = 0: the rest mesh (XDMF, with the fluid's initial state).
            "snapshots": {"times": [0] + (list(snapshots) or [end_time]), "fields": ["velocity", "vorticity"]},
            "average_from": average_from,
            **({"oscillation_threshold": oscillation_threshold} if oscillation_threshold else {}),
        },
        "acceptance": list(acceptance),
    }
    if performance:  # a wall-time budget per level: score.json's performance verdict
        doc["performance"] = performance
    if quick_at_standard:
        doc["fidelity"]["quick"] = {}
        return doc
    if quick_end:
        doc["fidelity"]["quick"]["outputs.snapshots.times"] = [0, quick_end]
    # The fine block's faces lie on coarse nodes: at the quick level's coarser grid, widen the
    # block to the nearest ones outside (only grid20, at a/5, needs it), and by quick_margin more
    # coarse spacings on every side where the capsule needs the room (the IB stencil must stay 2
    # fine nodes inside the block: at quick that is twice as far from the edge as at standard).
    coarse_quick = 4.0 / fine_per_a
    snapped = fine and ((math.floor(fine[0] / coarse_quick + 1e-9) - quick_margin) * coarse_quick,
                        (math.ceil(fine[1] / coarse_quick - 1e-9) + quick_margin) * coarse_quick)
    if refinement == "two_level" and any(abs(a - b) > 1e-9 for a, b in zip(snapped, fine)):
        doc["fidelity"]["quick"]["numerics.grid.fine_region.min"] = [round(snapped[0], 10)] * 3
        doc["fidelity"]["quick"]["numerics.grid.fine_region.max"] = [round(snapped[1], 10)] * 3
    return doc


def tol(quick, standard):
    """A tolerance per fidelity level (thesis: as standard)."""
    return {"quick": quick, "standard": standard, "thesis": standard}
