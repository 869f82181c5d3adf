"""Multiplier on the whole boundary against detected candidate facets: DOFs and time.

Usage: python benchmarks/candidate_facets.py [--out results/candidates] [--repeats 3]

For each scene the same problem is built three ways (whole boundary,
facets detected along the obstacle path with the push as margin, and the
scene's own tag) and solved with GNRM at the same absolute r and the same
absolute tolerance; build and solve times are medians of the repeats.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.output.io import write_json
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path
from fenics_contact.verification.bench_scenes import BarScene, HertzScene

SCENES = {
    "hertz h=0.004": (HertzScene(h_contact=0.004), 200.0 / 0.004, 1e-10),
    "bar 48x16 (neo-Hookean)": (BarScene(nx=48, ny=16, law="neo-hookean"), 210.0 / 0.125, 1e-9),
}


def measure(scene, r_abs: float, atol: float, repeats: int) -> dict:
    builds, solves = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        problem = scene.build(ContactSettings(r=r_abs, relative=False), MPI.COMM_WORLD)
        strategy = make_strategy("gnrm", problem, SolverSettings(atol=atol, max_iterations=60))
        builds.append(time.perf_counter() - start)
        start = time.perf_counter()
        path = solve_load_path(strategy, scene.steps, max_cutbacks=2)
        solves.append(time.perf_counter() - start)
    state = problem.contact_state()
    return {
        "candidates": scene.candidates,
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
    for name, (scene, r_abs, atol) in SCENES.items():
        for mode in ("boundary", "detected", "tag"):
            variant = type(scene)(**{**scene.__dict__, "candidates": mode})
            row = {"scene": name, **measure(variant, r_abs, atol, args.repeats)}
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
