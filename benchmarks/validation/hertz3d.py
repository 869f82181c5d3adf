"""3D Hertz benchmark: a sphere octant on a rigid plane, small strain and neo-Hookean.

Contact radius and peak pressure against Hertz theory at the measured force
(fit of p^2 against r^2 over the nodes in contact; largest nodal pressure
reported too) on three meshes; GNRM with the extrapolating predictor, MUMPS,
2 load steps, push 0.01 R (a / R ~ 0.1). Target: within 2 % on the refined mesh.

Run: ``python benchmarks/validation/hertz3d.py [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
from benchmarks import cases, harness
from fenics_contact.references.measure import measure_hertz_sphere
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import solve_load_path

MESHES = (0.02, 0.01, 0.007)
LAWS = ("linear", "neo-hookean")
STEPS = 2
RADIUS = 1.0


def run(h: float, law: str) -> dict:
    """Build and solve once."""
    sphere = cases.hertz_sphere(h, radius=RADIUS, law=law)
    start = time.perf_counter()
    problem = cases.build(sphere, 1.0)
    strategy = Extrapolated(make_strategy("gnrm", problem, SolverSettings(atol=1e-10)))
    build_s = time.perf_counter() - start
    start = time.perf_counter()
    path = solve_load_path(strategy, STEPS)
    total = time.perf_counter() - start
    c = measure_hertz_sphere(problem, RADIUS, sphere.E, sphere.nu)
    return {
        "h_contact": h, "law": law, "status": path.status,
        "u_dofs": problem.V.dofmap.index_map.size_global * 3,
        "lam_dofs": problem.surface.num_dofs,
        "newton_per_step": [s.iterations for s in path.steps], "newton_total": path.iterations,
        "P": c.P, "a_fit": c.fit.a, "a_hertz": c.hertz.a, "a_error": c.a_error,
        "p0_fit": c.fit.p0, "p0_nodal": c.fit.nodal_peak, "p0_hertz": c.hertz.p0,
        "p0_fit_error": c.p0_error, "p0_nodal_error": c.nodal_peak_error,
        "n_contact": c.fit.n_contact, "max_penetration": c.max_penetration,
        "build_s": build_s, **harness.split(total, strategy.kernel.timings.to_dict()),
    }


def main() -> None:
    """Both laws on three meshes."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    records = []
    for law in LAWS:
        for h in MESHES:
            med, _ = harness.repeat(lambda h=h, law=law: run(h, law), args.repeats)
            records.append(med)
            print(law, h, med["a_error"], med["p0_fit_error"], med["total_s"], flush=True)
    rows = [
        (m["law"], m["h_contact"], m["u_dofs"], m["n_contact"], m["newton_total"], m["P"],
         m["a_error"], m["p0_fit_error"], m["p0_nodal_error"], m["total_s"], m["assembly_s"],
         m["linear_s"], m["rest_s"])
        for m in records
    ]
    header = ("law", "h contact", "u DOFs", "nodes in contact", "Newton", "P (whole sphere)",
              "a vs Hertz", "p0 (fit) vs Hertz", "p0 (nodal max) vs Hertz", "solve s",
              "assembly s", "linear s", "rest s")
    table = harness.md_table(header, rows)
    harness.write("hertz3d", {"machine": harness.machine(), "records": records}, table, args.out)
    print(table)


if __name__ == "__main__":
    main()
