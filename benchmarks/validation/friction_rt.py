"""The tangential parameter under mesh refinement: the sliding block at 10x5 ... 80x40.

The sliding block of ``benchmarks.cases.sliding_block``
(1 x 0.5 SVK block, E = 1000, nu = 0, mu = 0.3, top clamped, plane pressed up
0.01 then moved sideways 0.02 in 20 steps, vertex rule), GNRM and ``auto``
at r = 1e-2 ... 1e4 E/h, stopping test atol = 1e-10 E h raised to the
round-off floor at r (as the trade-off sweep), 200 Newton iterations a step,
no cut-backs. Records per run: status, steps completed, Newton iterations,
the largest count in one step, the final F_t / (mu N) and the decisions of
the strategy (r_t lowered, line search ...).

``--rule`` chooses the tangential cap: ``body`` (the default of the
library: r_t = min(r, tangential_r_max E/L)), or ``mesh X`` to reproduce
the former r_t = min(r, X E/h) (``--rule mesh --cap 0.1``).

Run: ``python benchmarks/validation/friction_rt.py [--meshes 1,2,4,8] [--methods gnrm,auto]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases, harness
from fenics_contact import Scene
from fenics_contact.model.scaling import scaled_atol
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

R_VALUES = (1e-2, 1e-1, 1.0, 1e2, 1e4)
MU = 0.3


def run(block: Scene, label: str, method: str, r: float, *,
        mesh_cap: float | None = None) -> dict:
    """One load path; ``mesh_cap`` sets the former cap r_t <= mesh_cap E/h instead."""
    problem = cases.build(block, r, relative=True)
    if mesh_cap is not None:
        problem.set_tangential_cap(mesh_cap * problem.stiffness_scale)
    settings = SolverSettings(atol=scaled_atol(problem), max_iterations=200)
    strategy = make_strategy(method, problem, settings)
    start = time.perf_counter()
    path = solve_load_path(strategy, block.solver.steps, max_cutbacks=0)
    wall = time.perf_counter() - start
    final = path.steps[-1]
    ratio = final.tangential_force / (MU * final.contact_force)
    return {
        "mesh": label, "method": method, "r_relative": r, "status": path.status,
        "steps": path.steps_completed, "iterations": path.iterations,
        "max_per_step": max(s.iterations for s in path.steps),
        "ratio": ratio, "r_t_over_E_h": problem.tangential_r / problem.stiffness_scale,
        "switches": sorted({s.split(":")[0] for s in path.switches}), "wall_s": wall,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="1,2,4,8", help="refinements k of 10k x 5k")
    parser.add_argument("--methods", default="gnrm,auto")
    parser.add_argument("--r", default=",".join(f"{r:g}" for r in R_VALUES))
    parser.add_argument("--rule", choices=("body", "mesh"), default="body")
    parser.add_argument("--cap", type=float, default=0.1, help="mesh rule: cap in E/h")
    parser.add_argument("--name", default="friction_rt")
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    records, rows = [], []
    for k in (int(v) for v in args.meshes.split(",")):
        block = cases.sliding_block(MU, nx=10 * k, ny=5 * k)
        for method in args.methods.split(","):
            for r in (float(v) for v in args.r.split(",")):
                rec = run(block, f"{10 * k}x{5 * k}", method, r,
                          mesh_cap=args.cap if args.rule == "mesh" else None)
                records.append(rec)
                rows.append([
                    rec["mesh"], method, f"{r:g}", rec["status"], f"{rec['steps']}/20",
                    rec["iterations"], rec["max_per_step"], f"{rec['ratio']:.12f}",
                    f"{rec['r_t_over_E_h']:.3g}", "; ".join(rec["switches"]),
                    f"{rec['wall_s']:.1f}",
                ])
                print(*rows[-1], flush=True)
    header = ["mesh", "method", "r (E/h)", "status", "steps", "Newton its", "max its/step",
              "F_t/(mu N)", "final r_t (E/h)", "switches", "wall s"]
    table = harness.md_table(header, rows)
    harness.write(args.name, {"machine": harness.machine(), "records": records}, table, args.out)
    print(table)


if __name__ == "__main__":
    main()
