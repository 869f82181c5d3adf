"""Multiplier on the whole boundary against detected candidate facets: DOFs and time.

Usage: python benchmarks/performance/candidate_facets.py [--out results/candidates] [--repeats 3]

For each scene the same problem is built three ways (whole boundary,
facets detected along the obstacle path with the push as margin, and the
scene's own tag) and solved with GNRM at the same absolute r and the same
absolute tolerance; build and solve times are medians of the repeats.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
from mpi4py import MPI

from benchmarks import cases
from fenics_contact.output.io import write_json
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

#: Each case as a family of candidate modes, with its absolute r and tolerance.
SCENES = {
    "hertz h=0.004": (lambda mode: cases.hertz_cylinder(0.004, candidates=mode),
                      200.0 / 0.004, 1e-10),
    "bar 48x16 (neo-Hookean)": (
        lambda mode: cases.bar_on_cradle(48, 16, law="neo-hookean", candidates=mode),
        210.0 / 0.125, 1e-9),
}


def measure(scene, mode: str, r_abs: float, atol: float, repeats: int) -> dict:
    builds, solves = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        problem = cases.build(scene, r_abs, relative=False, comm=MPI.COMM_WORLD)
        strategy = make_strategy("gnrm", problem, SolverSettings(atol=atol, max_iterations=60))
        builds.append(time.perf_counter() - start)
        start = time.perf_counter()
        path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=2)
        solves.append(time.perf_counter() - start)
    state = problem.contact_state()
    return {
        "candidates": mode,
        "multiplier_dofs": problem.surface.num_dofs,
        "displacement_dofs": problem.V.dofmap.index_map.size_global * 2,
        "status": path.status,
        "iterations": path.iterations,
        "build_s": statistics.median(builds),
        "solve_s": statistics.median(solves),
        "active_nodes": state.active_count,
        "contact_force": state.contact_force,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/candidates"))
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    rows = []
    for name, (family, r_abs, atol) in SCENES.items():
        for mode in ("boundary", "detected", "tag"):
            row = {"scene": name, **measure(family(mode), mode, r_abs, atol, args.repeats)}
            rows.append(row)
            print(row, flush=True)
    lines = ["| scene | candidates | multiplier DOFs | total unknowns | iterations | build s | "
             "solve s | contact force |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['candidates']} | {r['multiplier_dofs']} | "
            f"{r['multiplier_dofs'] + r['displacement_dofs']} | {r['iterations']} | "
            f"{r['build_s']:.3f} | {r['solve_s']:.3f} | {r['contact_force']:.6g} |"
        )
    if MPI.COMM_WORLD.rank == 0:
        write_json(args.out / "candidates.json", rows)
        (args.out / "candidates.md").write_text("\n".join(lines) + "\n")
        print("\n".join(lines))


if __name__ == "__main__":
    main()
