"""Cattaneo-Mindlin interim check: stick half-width and traction profile of a cylinder.

Small-strain half-cylinder (R = 1, E = 200) clamped at its flat top; the
rigid plane moves up by 0.01 (pressing, 4 steps), then sideways by 0.003
(8 steps), mu = 0.3, GNRM at r = 0.01 E/h, vertex rule. Pressing is
frictionless unless ``frictional press`` (then mu acts from the start).
Per shear step: Q / (mu P), measured and analytic stick half-width c, the
relative error of c, the node spacing at the stick edge relative to c and
the relative L2 error of the nodal tangential traction against
Cattaneo-Mindlin's profile. See :mod:`fenics_contact.references.cattaneo`.

Run: ``python benchmarks/validation/cattaneo_cylinder.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from benchmarks.validation.cattaneo import CattaneoCylinder, solve_cattaneo
from benchmarks.validation.cattaneo_plot import traction_picture
from fenics_contact.references.cattaneo import contact_profile

CASES = [  # (nu, h_contact, degree, frictionless pressing)
    (0.3, 0.004, 1, True), (0.45, 0.004, 1, True), (0.49, 0.004, 1, True),
    (0.3, 0.002, 1, True), (0.45, 0.002, 1, True), (0.45, 0.004, 2, True),
    (0.45, 0.004, 1, False), (0.49, 0.004, 2, True),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=harness.OUT)
    parser.add_argument("--picture-only", action="store_true", help="only draw the profile")
    args = parser.parse_args()
    picture(args.out / "cattaneo_traction.png")
    if args.picture_only:
        return
    records, rows = [], []
    for nu, h, degree, frictionless in CASES:
        cylinder = CattaneoCylinder(nu=nu, h_contact=h, degree=degree, shift=0.003)
        start = time.perf_counter()
        _, zones, iterations = solve_cattaneo(cylinder, frictionless_press=frictionless)
        wall = time.perf_counter() - start
        for k, z in enumerate(zones):
            rec = {"nu": nu, "beta": cylinder.dundurs_beta, "h_contact": h, "degree": degree,
                   "frictionless_press": frictionless, "shear_step": k + 1,
                   **z.to_dict(),
                   "iterations": iterations, "wall_s": wall}
            records.append(rec)
            if k in (1, 3, 7):
                rows.append([nu, round(cylinder.dundurs_beta, 3), h, degree,
                             "no" if frictionless else "yes", z.load_ratio,
                             z.c_measured, z.c_analytic, z.c_error, z.c_resolution,
                             z.traction_error])
                print(*rows[-1], flush=True)
    header = ["nu", "beta", "h", "degree", "friction in pressing", "Q/(mu P)", "c measured",
              "c analytic", "c error", "node spacing / c", "traction L2 error"]
    table = harness.md_table(header, rows)
    harness.write("cattaneo_cylinder", {"machine": harness.machine(), "records": records},
                  table, args.out)
    print(table)


def picture(path: Path, nu: float = 0.45, h: float = 0.002) -> None:
    """Nodal tangential traction and Coulomb limit against Cattaneo-Mindlin (last shear step)."""
    cylinder = CattaneoCylinder(nu=nu, h_contact=h, shift=0.003)
    problem, zones, _ = solve_cattaneo(cylinder)
    traction_picture([(contact_profile(problem), zones[-1])], cylinder.mu, path,
                     title=f"cylinder on a rigid plane, nu = {nu}, h = {h}")


if __name__ == "__main__":
    main()
