"""The layout shared by the generated 2D capsule catalogues (scripts/generate-ch2-capsule-cases,
scripts/generate-ch3-cases and scripts/generate-ch4-cases): one function builds a case file from
the physical parameters, with the fidelity levels of the 2D capsule cases. Imported by those
scripts only.

Conventions (thesis 3.1.2, references/capsule2d/provenance.json): a = equivalent radius
(area/pi)^0.5, velocity k a, time 1/k; Re = rho (2ka)(2a)/mu, G = mu k a / E (eq. 3.9),
E_b = E_B/(a^2 E) (eq. 3.10); shear u = (k y, 0). Every case: a square domain with the capsule
at its centre, a Hookean membrane of `nodes` equally spaced nodes, TRT in double precision, the
cosine 4-point kernel, series every 0.02/k, vorticity and velocity snapshots.

Fidelity levels: by default quick doubles the fine spacing and the lattice velocity and halves
the membrane nodes, and thesis runs the thesis's lattice velocity with BGK; a case can keep its
nodes at quick, run quick at the same lattice velocity, or replace the quick block (shorter_run,
or {} where quick is the same run).

Files: json.dumps(doc, indent=2) and a newline (ASCII). Python's number formatting is the
files', so the type of a value matters: integers stay integers (centre [8, 8], fine block
[5, 5]-[11, 11], times), E_b and the wall-time budgets are floats (0.0, 300.0).
"""
import json
import math

SERIES = ["taylor_deformation", "inclination", "area_change", "tank_treading_phase", "tank_treading_period"]
#: With the membrane's length change (total and largest local stretch), where a case scores it.
LENGTH_SERIES = SERIES[:3] + ["length_change", "max_length_change"] + SERIES[3:]

CLAIMS = "references/capsule2d/claims.json"
STEADY, SWINGING, TUMBLING = "steady_tank_treading", "oscillating_tank_treading", "tumbling"

#: Thesis 3.1.2: 2ka = 1e-4 in lattice units (BGK), kept by the thesis level.
THESIS_U = 1e-4 / 2
#: Standard: four times the thesis's lattice velocity (four times fewer steps), with TRT.
STANDARD_U = 4 * THESIS_U
THESIS_LEVEL = {"numerics.lattice_velocity": THESIS_U, "numerics.collision": {"operator": "bgk"}}


def tau(re, u, spacing):
    """caplab's relaxation time on a block of `spacing` (in a) at lattice velocity u = k a: nu = (2ka)(2a)/Re
    with a = 1/spacing lattice units, tau = 1/2 + 3 nu. The fine block of the two-level grid runs at half the
    coarse time step with the same lattice velocity (acoustic scaling), so its tau is this with the fine spacing."""
    return 0.5 + 12 * u / (spacing * re)


def thesis_magic(re, spacing):
    """The TRT magic parameter of the quick and standard levels: Lambda = (tau_f - 1/2)^2 of the thesis's BGK run
    on the fine block (spacing in a). BGK is TRT with Lambda = (tau - 1/2)^2, and at a fixed grid TRT's steady
    solutions depend on Lambda alone, not on tau: so the standard level, at four times the thesis's lattice
    velocity, keeps the thesis's steady-state discretization where the capsule is. It matters for the immersed
    boundary's area leak, which grows with Lambda and not with tau (references/capsule2d/provenance.json,
    ib_area_leak_and_magic)."""
    return round((tau(re, THESIS_U, spacing) - 0.5) ** 2, 6)


def mach(u, domain=16):
    """caplab's Mach number (`caplab check`): the shear velocity at the domain edge, (domain/2) k a, over the
    lattice sound speed 1/sqrt(3)."""
    return domain / 2 * u * 3 ** 0.5


#: The fine block's half width (in a) around the capsule: [5a, 11a]^2 in the thesis's 16a domain.
FINE_HALF_WIDTH = 3


def fine_region(domain, fine_spacing=0.05):
    """The fine block, centred on the capsule at the domain's centre: [5, 5]-[11, 11] for 16a (thesis 3.1.2).
    Its faces lie on coarse nodes (caplab's rule): where FINE_HALF_WIDTH is not a whole number of coarse spacings
    (the fig. 4.3 grids of 2a = 30 and 50 spacings) the block is the smallest one on coarse nodes around it."""
    c = domain // 2
    cells = math.ceil(FINE_HALF_WIDTH / (2 * fine_spacing) - 1e-9)
    half = FINE_HALF_WIDTH if abs(cells * 2 * fine_spacing - FINE_HALF_WIDTH) < 1e-9 else round(cells * 2 * fine_spacing, 10)
    return {"min": [c - half] * 2, "max": [c + half] * 2}


def setup(re, fine_spacing=0.05, domain=16):
    """The description's opening for the low-Reynolds capsules (thesis 2.2.4 and chapter 3), with the case's
    own grid, domain and relaxation times; the sentence on the quick level follows it (QUICK_HALF unless a case
    says otherwise)."""
    h = fine_spacing
    region = fine_region(domain, fine_spacing)
    lo, hi = region["min"][0], region["max"][0]

    def taus(u):
        return f"tau_c = {tau(re, u, 2 * h):.3g}, tau_f = {tau(re, u, h):.3g}"

    magic = thesis_magic(re, h)
    return ("Liquid-filled 2D capsule with a Hookean membrane (thesis eq. 3.6) and bending moment m = E_B (kappa - "
            "kappa_0) (eq. 3.8) in unbounded simple shear u = (k y, 0) imposed on all four faces (non-equilibrium "
            f"extrapolation), domain {domain}a x {domain}a, capsule at the centre, fine block [{lo}a, {hi}a]^2 with "
            f"spacing {h:.3g}a, "
            f"coarse {2 * h:.3g}a (thesis 3.1.2{'' if h == 0.05 else ': 0.05a and 0.1a'}"
            f"{'' if domain == 16 else ', in a domain of 16a'}). Units: a = equivalent "
            "radius (area/pi)^0.5, velocity k a, time 1/k; Re = rho (2ka)(2a)/mu, G = mu k a / E (eq. 3.9), "
            "E_b = E_B/(a^2 E) (eq. 3.10). "
            f"Lattice velocity: the thesis uses 2ka = 1e-4 (k a = 5e-5, BGK; {taus(THESIS_U)} at this Re = {re:g} "
            f"and grid), kept by level thesis; standard uses k a = 2e-4 with TRT ({taus(STANDARD_U)}: four times "
            f"fewer steps; the Mach number at the domain edge ({domain // 2} k a) is {mach(STANDARD_U, domain):.2g}) and "
            "the magic "
            f"parameter of the thesis's BGK on the fine block, (tau_f - 1/2)^2 = {magic:g} (TRT's steady solutions "
            "depend on it alone at a fixed grid; with 1/4 the immersed boundary's area leak was 1.6 times the "
            "thesis level's, references/capsule2d/provenance.json), ")


QUICK_HALF = "quick doubles the spacing and the lattice velocity and halves the membrane nodes."


def fmt(x):
    return f"{x:g}"


def tol(quick, standard):
    """A tolerance per fidelity level (thesis: as standard)."""
    return {"quick": quick, "standard": standard, "thesis": standard}


def mode(claim, expected, why):
    return {"metric": "mode", "comparison": "mode", "reference": f"{CLAIMS}#{claim}", "reference_mode": expected,
            "justification": why}


def area_change(quick="quick runs at half the resolution, where the IB leaks more: 0.2 %."):
    """The enclosed-area bound of every low-Reynolds capsule (chapters 2 and 3); `quick` says why quick allows
    0.2 %."""
    return {"metric": "area_change_max", "comparison": "absolute", "reference": f"{CLAIMS}#ch3.area_change",
            "reference_value": 0.0, "tolerance": tol(0.002, 0.001),
            "justification": "Thesis bound: area change below 0.1 % (thesis ch. 3.1.1: 'the volume change during "
                             f"capsule deformation is less than 0.1%'); {quick}"}


AREA_CHANGE = area_change()


def budget(end_time, resolution, larger=None):
    """The wall-time budget of a thesis-resolution case: 5 minutes per 10 shear times at standard. larger =
    (factor, why): a case with `factor` times the node updates of its thesis-sized original gets that much more."""
    factor, why = larger or (1, "")
    seconds = round(300.0 * end_time / 10 * factor)
    return {"wall_time_budget_s": {"standard": float(seconds)},
            "justification": "The cost target of the issue that added the 2D capsules: a thesis-resolution case "
                             f"({resolution}) runs 10 shear times in at most 5 minutes at standard fidelity on the "
                             f"2-core development machine; this run is k t = {end_time} long"
                             + (f", {why}, hence {seconds:g} s." if larger else f", hence {seconds:g} s.")}


def shorter_run(end_time, average_from):
    """A quick level on the standard grid, only shorter."""
    return {"numerics.end_time": end_time, "outputs.average_from": average_from, "outputs.snapshots.times": [end_time]}


def case(cid, title, description, *, shape, G, re, end_time, average_from, Eb=0.0, kappa0="initial", nodes=160,
         domain=16, fine_spacing=0.05, refinement="two_level", walls=False, u=STANDARD_U, snapshots=None,
         series=SERIES, quick=None, quick_speedup=2, quick_keeps_nodes=False, quick_end=None,
         quick_snapshots=None, quick_average_from=None, thesis=THESIS_LEVEL, magic=None, acceptance=(),
         performance=None):
    """One case file. `cid` is "chapter/name"; `shape` the shape's type and parameters (the centre and the
    equivalent diameter 2 are added); walls=True: moving walls at y = 0 and y = domain with x periodic instead
    of the far field on all faces; quick=None: the default half-resolution quick level (with the quick_*
    options), else the quick block itself; magic: the TRT magic parameter where a case sets its own (the
    thesis level's cases take the thesis's, thesis_magic)."""
    assert domain % 2 == 0  # the centre stays an integer
    snapshots = list(snapshots) if snapshots else [end_time]
    grid = {"refinement": refinement, "fine_spacing": fine_spacing}
    if refinement == "two_level":
        grid["fine_region"] = fine_region(domain, fine_spacing)
    if quick is None:
        quick = {"numerics.grid.fine_spacing": 2 * fine_spacing, "numerics.lattice_velocity": quick_speedup * u}
        if not quick_keeps_nodes:
            quick["physics.bodies.0.membrane.nodes"] = nodes // 2
        quick["numerics.end_time"] = quick_end or end_time
        quick["outputs.snapshots.times"] = snapshots if quick_snapshots is None else quick_snapshots
        if quick_average_from is not None:
            quick["outputs.average_from"] = quick_average_from
    if magic is None and thesis == THESIS_LEVEL:
        magic = thesis_magic(re, fine_spacing)
    collision = {"operator": "trt"} if magic is None else {"operator": "trt", "magic": magic}
    doc = {
        "id": cid,
        "title": title,
        "description": description,
        "physics": {
            "dimension": 2,
            "flow": {"type": "shear"},
            "reynolds": re,
            "domain": {"size": [domain, domain],
                       "boundaries": ["periodic", "wall"] if walls else ["far_field"] * 2},
            "bodies": [{"name": "capsule",
                        "shape": {"type": shape["type"], "center": [domain // 2] * 2, "diameter": 2,
                                  **{k: v for k, v in shape.items() if k != "type"}},
                        "membrane": {"law": "hooke", "capillary": G, "bending_ratio": float(Eb),
                                     "reference_curvature": kappa0, "nodes": nodes}}],
        },
        "numerics": {
            "grid": grid,
            "collision": collision,
            "precision": "double",
            "ib": {"kernel": "cosine4"},
            "lattice_velocity": u,
            "end_time": end_time,
        },
        "fidelity": {"quick": quick, "standard": {}, "thesis": thesis},
        "outputs": {
            "series": {"interval": 0.02, "quantities": series},
            "snapshots": {"times": snapshots, "fields": ["vorticity", "velocity"]},
            "average_from": average_from,
        },
        "acceptance": list(acceptance),
    }
    if performance:  # a wall-time budget per level: score.json's performance verdict
        doc["performance"] = performance
    return doc


def write(cases, out):
    """Writes each case to out/<name>.json in the catalogue's formatting."""
    out.mkdir(parents=True, exist_ok=True)
    for doc in cases:
        (out / (doc["id"].split("/", 1)[1] + ".json")).write_text(json.dumps(doc, indent=2) + "\n")
    print(f"wrote {len(cases)} cases to {out}")
