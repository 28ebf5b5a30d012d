#!/usr/bin/python3
"""Reference series and steady values of the thesis's chapter 5 spherical NH capsules.

Usage: /usr/bin/python3 convert_nh_sphere.py [SOURCE]

SOURCE defaults to ../../../shared/refdata/capsule3d_nh_sphere_D_vs_t.csv relative to this
script (the project's shared reference data). It is first copied, byte for byte, to
capsule3d_nh_sphere_D_vs_t.csv next to this script, so that the repository holds the raw file;
everything below is then read from that local copy. When SOURCE does not exist but the local
copy does, the local copy is converted as it is.

Writes, next to this script (see provenance.json for every convention):
  - <source>_G<Ca>.csv for each (source, Ca) of the raw file: pozrikidis1995_G0.0125.csv ...
    pozrikidis1995_G0.2.csv, ramanujan1998_G0.025.csv ... ramanujan1998_G0.2.csv. Columns t, D:
    t = k t (shear rate times time), D = D_xz = (L - B)/(L + B) in the shear plane. Rows sorted
    by t; points with t < 0 or D < 0 (digitization noise) dropped (the header says how many);
    the numbers are written exactly as digitized (the strings of the raw file). Their Ca is
    mu k a / E_s with the NH law written with E_s = 3 G_s: it equals the thesis G for NH.
  - steady_values.csv: the steady D of Ramanujan & Pozrikidis 1998 for Ca = 0.05, 0.1, 0.2 (the
    mean of the digitized curve over the last 40 % of its time span, the spread max - min there
    as its uncertainty) and the first-order small-deformation values D = 25/4 G (NH) and
    D = 25/6 G (Skalak, C = 1), inclination -> pi/4 (Barthes-Biesel 1980; Barthes-Biesel &
    Rallison 1981), in thesis units.
Standard library only.
"""
import csv
import math
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
RAW_NAME = "capsule3d_nh_sphere_D_vs_t.csv"
DEFAULT_SOURCE = HERE / ".." / ".." / ".." / "shared" / "refdata" / RAW_NAME
LOCAL = HERE / RAW_NAME

#: Fraction of the time span of a curve, at its end, averaged for the steady value.
LAST_FRACTION = 0.4
#: Ca of the Ramanujan & Pozrikidis 1998 curves that reach a steady state (the 0.025 curve
#: stops at k t = 1.4, still rising).
STEADY_CA = ("0.05", "0.1", "0.2")
#: G of the small-deformation rows (thesis fig. 5.7 draws the theory for 0.0125, 0.025, 0.05).
SMALL_DEFORMATION_G = ("0.0125", "0.025", "0.05")
DIGITIZATION = 0.005

SOURCES = {
    "Pozrikidis1995": {
        "prefix": "pozrikidis1995",
        "name": "Pozrikidis 1995",
        "citation": "Pozrikidis C. 1995, Finite deformation of liquid capsules enclosed by elastic membranes "
                    "in simple shear flow, J. Fluid Mech. 297:123-152 (boundary-element method)",
        "doi": "10.1017/S002211209500303X (unverified)",
        "raw_file": "pozrikidis1995_ca_{ca}.csv",
        "caveat": "transient only: the curves stop at k t <= 2",
        "law": "the thesis (section 5.3.1.1) says Pozrikidis 1995 used the zero-thickness (ZT) law",
    },
    "RamanujanPozrikidis1998": {
        "prefix": "ramanujan1998",
        "name": "Ramanujan & Pozrikidis 1998",
        "citation": "Ramanujan S. & Pozrikidis C. 1998, Deformation of liquid capsules enclosed by elastic "
                    "membranes in simple shear flow: large deformations and the effect of fluid viscosities, "
                    "J. Fluid Mech. 361:117-143 (boundary-element method)",
        "doi": "10.1017/S0022112098008714 (unverified)",
        "raw_file": "pozrikidis1998_ca_{ca}.csv",
        "caveat": "to k t = 8 (Ca = 0.05: to k t = 4.9; Ca = 0.025: stops at k t = 1.4, still rising)",
        "law": "the thesis (section 5.1.1) says Ramanujan & Pozrikidis 1998 used the zero-thickness (ZT) law",
    },
}
BASILISK = ("comphy-lab/basilisk-C @ c7be0ade3dcf94f0fdf50d9c69d14e12c1e1566f (data files last changed in "
            "96c53ce7610255a9a74006b7a8bb3b31a6134332), basilisk-wiki/sandbox/huet/tests/lagrangian_caps/"
            "data/nh_shear_3d/")


def copy_raw(source: Path) -> None:
    """Copies the raw file next to this script, unchanged (nothing to do when it is the local copy)."""
    if source.exists():
        if source.resolve() != LOCAL.resolve():
            shutil.copyfile(source, LOCAL)
            print(f"copied {source.resolve()} -> {LOCAL.name}")
    elif LOCAL.exists():
        print(f"{source.resolve()} not found: converting the local copy {LOCAL.name}")
    else:
        sys.exit(f"neither {source} nor {LOCAL} exists")


def read_raw(path: Path) -> dict:
    """{(source, Ca string): [(t string, D string), ...]} in file order."""
    lines = [line for line in path.read_text(encoding="utf-8").splitlines() if line and not line.startswith("#")]
    curves: dict = {}
    for row in csv.DictReader(lines):
        curves.setdefault((row["source"], row["Ca"]), []).append((row["t_gamma"], row["D"]))
    return curves


def write_series(source: str, ca: str, points: list) -> tuple:
    """Writes <prefix>_G<ca>.csv; returns (file name, kept points as floats, number dropped)."""
    info = SOURCES[source]
    ordered = sorted(points, key=lambda p: float(p[0]))  # stable: ties keep the digitized order
    kept = [p for p in ordered if float(p[0]) >= 0 and float(p[1]) >= 0]
    dropped = len(ordered) - len(kept)
    name = f"{info['prefix']}_G{ca}.csv"
    header = [
        f"Taylor deformation D_xz(k t) of an initially spherical capsule in unbounded simple shear, Stokes flow, "
        f"viscosity ratio 1: {info['name']}, Ca = {ca}",
        f"Source: {info['citation']}; DOI {info['doi']}",
        f"Numbers: third-party digitization of a published figure (figure number not given in the source "
        f"repository), {BASILISK}{info['raw_file'].format(ca=ca)}; via {RAW_NAME} (copy of shared/refdata)",
        f"Conversion (convert_nh_sphere.py): rows source = {source}, Ca = {ca} of {RAW_NAME}; sorted by t; "
        f"points with t < 0 or D < 0 (digitization noise) dropped: {dropped} of {len(ordered)}; "
        f"numbers written as digitized",
        "Columns: t = k t (shear rate times time); D = D_xz = (L - B)/(L + B) in the shear plane (x-z for "
        "u = (k z, 0, 0))",
        "Ca = mu k a / E_s, NH law written with E_s = 3 G_s: Ca equals the thesis G for NH "
        "(W = E/6 (I1 - 1 + 1/(I2 + 1)), E = 3 G_s) and eps_Lac / 3",
        f"Law: labelled neo-Hookean by the digitization source; {info['law']}, equivalent to NH at small "
        "strain; the difference at large G is not quantified here (provenance.json)",
        f"Uncertainty: +-{DIGITIZATION} in D (digitization, medium confidence); {info['caveat']}",
    ]
    with (HERE / name).open("w", encoding="utf-8", newline="") as f:
        for line in header:
            f.write(f"# {line}\n")
        f.write("t,D\n")
        for t, d in kept:
            f.write(f"{t},{d}\n")
    return name, [(float(t), float(d)) for t, d in kept], dropped


def steady(points: list) -> dict:
    """Mean and spread of D over the last LAST_FRACTION of the time span (and over k t >= 4)."""
    t0, t1 = points[0][0], points[-1][0]
    start = t0 + (1 - LAST_FRACTION) * (t1 - t0)
    tail = [d for t, d in points if t >= start]
    late = [d for t, d in points if t >= 4]
    return {"start": start, "end": t1, "n": len(tail), "mean": sum(tail) / len(tail),
            "spread": max(tail) - min(tail),
            "late": (len(late), sum(late) / len(late), max(late) - min(late)) if late else None}


def write_steady(rp98: dict) -> list:
    rows = []
    for ca in STEADY_CA:
        s = rp98[ca]
        late = s["late"]
        how = (f"mean of the digitized curve (ramanujan1998_G{ca}.csv) over the last 40 % of its time span, "
               f"k t = {s['start']:.3f} to {s['end']:.3f} ({s['n']} points); uncertainty = max - min there; "
               f"digitization +-{DIGITIZATION} in addition")
        if late:
            how += f"; over k t >= 4 instead: {late[1]:.6f}, spread {late[2]:.6f} ({late[0]} points)"
        rows.append([f"ramanujan1998_G{ca}", "neo_hookean", ca, "Ramanujan & Pozrikidis 1998 (BIM, digitized)",
                     f"{s['mean']:.6f}", f"{s['spread']:.6f}", "", how])
    # First-order theory per law: (id prefix, law, D / G, how), in thesis units.
    theories = [
        ("small_deformation_nh", "neo_hookean", 25.0 / 4.0,
         "D = (25/4) G = (25/12) eps_Lac with eps_Lac = 3 G (NH, E = 3 G_s); inclination -> pi/4; "
         "error O(G^2): valid for small G only (thesis 5.3.1.1: no longer good at G = 0.05)"),
        ("small_deformation_sk", "skalak", 25.0 / 6.0,
         "D = (25/6) G = (25/12) eps_Lac with eps_Lac = 2 G (Skalak C = 1, E = 2 G_s, surface Poisson "
         "ratio C/(1 + C) = 1/2 as NH); inclination -> pi/4; error O(G^2): valid for small G only"),
    ]
    for prefix, law, slope, how in theories:
        for g in SMALL_DEFORMATION_G:
            rows.append([f"{prefix}_G{g}", law, g,
                         "first-order small-deformation theory (Barthes-Biesel 1980; Barthes-Biesel & Rallison 1981)",
                         repr(slope * float(g)), "", repr(math.pi / 4), how])
    header = [
        "Steady Taylor deformation D_xz of an initially spherical capsule in unbounded simple shear (Stokes flow, "
        "viscosity ratio 1), thesis units (G = mu k a / E; NH E = 3 G_s, Skalak E = 2 G_s)",
        "Written by convert_nh_sphere.py; sources and validity in provenance.json (datasets.steady_values.csv, "
        "analytic.small_deformation_*)",
        "Columns: id (the key a case names: steady_values.csv#<id>:D); law; G; source; D; uncertainty (of D: the "
        "spread max - min over the averaging window; empty for the formulas, whose error is O(G^2)); "
        "inclination (rad, from x toward z; empty where the source gives none); how",
        "ramanujan1998 rows: validation (external, digitized); small_deformation rows: verification (analytic "
        "limit, first order - the thesis compares with the second-order theory, whose coefficients are not "
        "included here)",
    ]
    with (HERE / "steady_values.csv").open("w", encoding="utf-8", newline="") as f:
        for line in header:
            f.write(f"# {line}\n")
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["id", "law", "G", "source", "D", "uncertainty", "inclination", "how"])
        w.writerows(rows)
    return rows


def main(source: Path) -> None:
    copy_raw(source)
    curves = read_raw(LOCAL)
    rp98 = {}
    for (src, ca), points in curves.items():
        name, kept, dropped = write_series(src, ca, points)
        print(f"{name}: {len(kept)} points, {dropped} dropped")
        if src == "RamanujanPozrikidis1998" and ca in STEADY_CA:
            rp98[ca] = steady(kept)
    for row in write_steady(rp98):
        print("steady_values.csv:", ", ".join(row[:7]))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_SOURCE)
