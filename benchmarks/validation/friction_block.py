"""Sliding-block benchmark: friction strategies over r and mu, and a load reversal.

The shipped scene ``scenes/block_slide_friction.toml`` (a 1 x 0.5 SVK block,
E = 1000, nu = 0, 20 x 10 quadrilaterals, 21 contact nodes, top clamped; the
rigid plane moves up by 0.01, then sideways by 0.02, in 20 steps). Nodal
(vertex rule) contact, atol 1e-8, no cut-backs unless said. Records per run:
status, Newton iterations (total and per step), multiplier updates, final
normal force N, tangential force F_t, F_t / (mu N) and the largest
displacement difference against the GNRM reference at r = 1 E/h. The
tangential parameter is r_t = min(r, cap E/L), cap 2 by default (L = 1 the
contact surface extent: 2000 = 0.1 E/h on this mesh); "r"
in the cap column means r_t = r.

Run: ``python benchmarks/validation/friction_block.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "block_slide_friction.toml"
#: Press, slide by +0.02, slide back to -0.01: the friction force reverses.
REVERSAL = ((0.0, 0.0, 0.0), (0.3, 0.0, 0.01), (0.65, 0.02, 0.01), (1.0, -0.01, 0.01))


def run(method: str, r: float, mu: float | None = 0.3, schedule=None, cutbacks: int = 0,
        max_iterations: int = 100, rt_max: float | None = 2.0) -> tuple[dict, np.ndarray]:
    """Solve the scene once; return the record and the final displacement.

    ``rt_max`` caps r_t relative to E/L, L = 1 the contact surface extent (None: r_t = r).
    """
    scene = load_scene(SCENE)
    obstacle = scene.obstacle if schedule is None else dataclasses.replace(
        scene.obstacle, schedule=schedule
    )
    scene = dataclasses.replace(
        scene, contact=dataclasses.replace(scene.contact, mu=mu), obstacle=obstacle
    )
    scene = dataclasses.replace(  # None: r_t = r
        scene, contact=dataclasses.replace(scene.contact, tangential_r_max=rt_max)
    )
    problem = build_problem(scene)
    problem.set_r(r, relative=True)
    strategy = make_strategy(
        method, problem, SolverSettings(atol=1e-8, rtol=1e-10, max_iterations=max_iterations),
        predictor="previous",
    )
    start = time.perf_counter()
    path = solve_load_path(strategy, 20, max_cutbacks=cutbacks)
    wall = time.perf_counter() - start
    final = path.steps[-1]
    vector = problem.tangential_force_vector() if mu is not None else np.zeros(2)
    record = {
        "method": method, "r_relative": r, "mu": mu, "rt_max": rt_max, "status": path.status,
        "iterations": path.iterations, "updates": path.updates, "cutbacks": path.cutbacks,
        "per_step": [s.iterations for s in path.steps],
        "slip_counts": [s.slip_count for s in path.steps],
        "tangential_forces": [s.tangential_force for s in path.steps],
        "normal_force": final.contact_force, "tangential_force": final.tangential_force,
        "tangential_force_x": float(vector[0]),
        "ratio": final.tangential_force / (mu * final.contact_force) if mu else float("nan"),
        "wall_s": wall,
    }
    return record, problem.u.x.array.copy()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    records = []
    reference, u_ref = run("gnrm", 1.0)
    cases = [("gnrm", r, 0.3, None, 0, 2.0) for r in (1e-3, 1e-2, 0.1, 1.0, 1e2, 1e4)]
    cases += [("gnrm", r, 0.3, None, 0, None) for r in (0.1, 0.3, 1.0, 100.0)]
    cases += [("auto", r, 0.3, None, 0, 2.0) for r in (1e-2, 1.0, 1e2, 1e4)]
    cases += [("nua", 0.1, 0.3, None, 0, 2.0), ("nua", 1.0, 0.3, None, 0, 2.0)]
    cases += [("sua", 0.01, 0.3, None, 0, 2.0)]
    cases += [("penalty", r, 0.3, None, 4, 2.0) for r in (0.1, 1.0, 10.0)]
    cases += [("gnrm", 1.0, mu, None, 0, 2.0) for mu in (None, 0.0, 0.1, 1.0, 10.0)]
    cases += [("gnrm", 1.0, 0.3, REVERSAL, 0, 2.0), ("auto", 1.0, 0.3, REVERSAL, 0, 2.0)]
    rows = []
    for method, r, mu, schedule, cutbacks, rt_max in cases:
        rec, u = run(method, r, mu, schedule, cutbacks, 500 if method in ("nua", "sua") else 100,
                     rt_max)
        same_path = schedule is None and mu == 0.3
        rec["max_du_vs_reference"] = (
            float(np.max(np.abs(u - u_ref))) if same_path and rec["status"] == "converged"
            else float("nan")
        )
        rec["load_path"] = "reversal" if schedule else "press, slide"
        records.append(rec)
        rows.append([
            method, r, "r" if rt_max is None else rt_max, "none" if mu is None else mu,
            rec["load_path"], rec["status"],
            rec["iterations"], max(rec["per_step"]), rec["updates"], rec["cutbacks"],
            rec["normal_force"], rec["tangential_force_x"], rec["ratio"],
            rec["max_du_vs_reference"], rec["wall_s"],
        ])
        print(*rows[-1], flush=True)
    header = ["method", "r (E/h)", "r_t cap (E/h)", "mu", "load path", "status", "Newton its",
              "max its/step",
              "updates", "cutbacks", "N", "F_t,x", "F_t/(mu N)", "max |u - u_ref|", "wall s"]
    table = harness.md_table(header, rows)
    harness.write(
        "friction_block",
        {"machine": harness.machine(), "reference": reference, "records": records}, table,
        args.out,
    )
    print(table)


if __name__ == "__main__":
    main()
