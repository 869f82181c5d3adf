"""2D Hertz benchmark: GNRM Newton counts over r, accuracy against Hertz, time split.

Half-cylinder R = 1 on a rigid plane, E = 200, nu = 0.3, small strain, plane
strain; the flat top is moved down 0.02 in 10 equal steps; P1 triangles
graded to h = 0.008 near contact (3814 displacement DOFs). Nodal (vertex
rule) contact. Targets: <= 23 Newton iterations in total, the same for
every r in 1e-2 ... 1e6 (relative to E/h).

Run: ``python benchmarks/validation/hertz2d.py [--repeats 3] [--out results/bench]``.
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
from fenics_contact.references.hertz import load_for_half_width, relative_error
from fenics_contact.references.measure import measure_hertz
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import solve_load_path

#: The issue-6 case: h = 0.008 at contact, fine zone 0.22 R -> 3814 displacement DOFs.
RADIUS = 1.0
CYLINDER = cases.hertz_cylinder(0.008, radius=RADIUS, push=0.02, fine_radius=0.22)
STEPS = 10
R_VALUES = (1e-2, 1e-1, 1.0, 1e1, 1e2, 1e4, 1e6)


def run(r: float, predictor: str) -> dict:
    """Build and solve once; return counts, accuracy and the time split."""
    start = time.perf_counter()
    problem = cases.build(CYLINDER, r, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-8))
    if predictor == "extrapolate":
        strategy = Extrapolated(strategy)
    build_s = time.perf_counter() - start
    kernel = strategy.kernel
    before = kernel.timings.snapshot()
    start = time.perf_counter()
    path = solve_load_path(strategy, STEPS)
    total = time.perf_counter() - start
    timings = kernel.timings.since(before).to_dict()
    c = measure_hertz(problem, RADIUS, CYLINDER.E, CYLINDER.nu)
    p_from_a = load_for_half_width(c.fit.a, RADIUS, CYLINDER.E, CYLINDER.nu)
    return {
        "r_relative": r,
        "predictor": predictor,
        "status": path.status,
        "newton_total": path.iterations,
        "newton_per_step": [s.iterations for s in path.steps],
        "active_per_step": [s.active_count for s in path.steps],
        "u_dofs": problem.V.dofmap.index_map.size_global * problem.V.dofmap.index_map_bs,
        "lam_dofs": problem.surface.num_dofs,
        "force_P": c.P,
        "force_hertz_from_a": p_from_a,
        "force_error": relative_error(c.P, p_from_a),
        "a_fit": c.fit.a,
        "a_hertz": c.hertz.a,
        "a_error": c.a_error,
        "p0_nodal": c.fit.nodal_peak,
        "p0_fit": c.fit.p0,
        "p0_hertz": c.hertz.p0,
        "p0_nodal_error": c.nodal_peak_error,
        "p0_fit_error": c.p0_error,
        "max_penetration": c.max_penetration,
        "build_s": build_s,
        **harness.split(total, timings),
        "residual_assemblies": timings["residuals"],
        "linear_solves": timings["linear_solves"],
    }


def main() -> None:
    """Sweep r with the extrapolating predictor, and r = 1 without it."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    runs_of = [(r, "extrapolate") for r in R_VALUES] + [(1.0, "previous")]
    records = []
    for r, predictor in runs_of:
        med, runs = harness.repeat(lambda r=r, p=predictor: run(r, p), args.repeats)
        med["build_s_first"] = runs[0]["build_s"]
        records.append(med)
        print(
            f"r={r:g} {predictor}: {med['newton_total']} its {med['newton_per_step']} "
            f"total {med['total_s']:.3f}s", flush=True,
        )
    rows = [
        (
            f"{m['r_relative']:g}", m["predictor"], m["newton_total"],
            " ".join(map(str, m["newton_per_step"])), m["force_P"], m["force_error"],
            m["p0_nodal"], m["p0_nodal_error"], m["a_error"], m["total_s"], m["assembly_s"],
            m["linear_s"], m["rest_s"], m["build_s"],
        )
        for m in records
    ]
    header = (
        "r / (E/h)", "predictor", "Newton", "per step", "P", "P vs Hertz(a)", "p0 nodal",
        "p0 vs Hertz(P)", "a vs Hertz(P)", "solve s", "assembly s", "linear s", "rest s",
        "build s",
    )
    table = harness.md_table(header, rows)
    harness.write(
        "hertz2d", {"machine": harness.machine(), "repeats": args.repeats, "records": records},
        table, args.out,
    )
    print(table)


if __name__ == "__main__":
    main()
