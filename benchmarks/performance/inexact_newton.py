"""Inexact Newton on the 3D DOF ladder (issue 21, item 3): what each change buys.

The ladder problem (``ladder3d.py``: a rigid ball indenting a neo-Hookean
block, GNRM, extrapolating predictor, 2 load steps, Newton tolerance 1e-10
relative) with the iterative linear solver, four ways, run interleaved in
one process (round after round, so that a shared machine's load falls on
all alike):

- ``iterative``: Krylov rtol 1e-10 at every Newton step, GAMG set up at
  every step (prolongators reused), full Schur factorisation, as before;
- ``upper``: the same with the upper Schur factorisation (one multigrid
  cycle per Krylov iteration instead of two);
- ``ew``: Eisenstat-Walker forcing terms instead of the fixed rtol (upper);
- ``inexact``: and the multigrid hierarchy kept within each load step;
- ``inexact-full``: ``inexact`` with the full factorisation;
- ``inexact-path``: the hierarchy kept along the load path.

Reported per solver (medians over the rounds): the 2-step solve time and
its ratio to ``iterative``, Newton iterations per step, Krylov iterations,
multigrid set-ups, the linear-solver and assembly times, and the answer's
difference from ``iterative`` (largest displacement difference over the
largest displacement, and the contact force). Targets (issue 21): at 1e5
DOFs solve time <= 0.5x, Newton count +1 at most, same answer to 1e-8.
Peak memory per rank is the single-case run's (``ladder3d.py --solver inexact``).

Run: ``python benchmarks/performance/inexact_newton.py --dofs 1e5 [--rounds 3]``
(or under ``mpiexec -n 2``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import numpy as np

from mpi4py import MPI

from benchmarks import harness
from benchmarks.cases import cells_for_dofs
from benchmarks.performance.ladder3d import run

SOLVERS = ("iterative", "upper", "ew", "inexact", "inexact-full", "inexact-path")
TARGET_RATIO = 0.5


def difference(problem, reference, comm: MPI.Comm) -> tuple[float, float]:
    """Largest displacement difference (relative to the largest displacement) and
    the relative contact force difference of two solved problems."""
    n = problem.V.dofmap.index_map.size_local * problem.V.dofmap.index_map_bs
    u, ref = problem.u.x.array[:n], reference.u.x.array[:n]
    diff = comm.allreduce(float(np.abs(u - ref).max(initial=0.0)), op=MPI.MAX)
    scale = comm.allreduce(float(np.abs(ref).max(initial=0.0)), op=MPI.MAX)
    f, f_ref = problem.contact_state().contact_force, reference.contact_state().contact_force
    return diff / scale, abs(f / f_ref - 1.0)


def main() -> None:
    """Every solver, interleaved rounds; JSON and a markdown table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dofs", type=float, default=1e5)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    comm = MPI.COMM_WORLD
    n = cells_for_dofs(args.dofs)
    run(cells_for_dofs(1e3), "inexact", comm)  # warm-up: forms compiled
    runs: dict[str, list[dict]] = {s: [] for s in SOLVERS}
    for _ in range(args.rounds):
        problems: list = []
        for solver in SOLVERS:
            record = run(n, solver, comm, answer=problems)
            runs[solver].append(record)
        for solver, problem in zip(SOLVERS, problems, strict=True):
            runs[solver][-1]["u_difference"], runs[solver][-1]["force_difference"] = (
                difference(problem, problems[0], comm))
        del problems
    medians = {s: harness.median_dict(r) for s, r in runs.items()}
    base = medians["iterative"]
    rows = []
    for solver, m in medians.items():
        m["ratio"] = m["total_s"] / base["total_s"]
        m["newton_extra"] = m["newton_total"] - base["newton_total"]
        m["u_difference"] = max(r["u_difference"] for r in runs[solver])
        m["force_difference"] = max(r["force_difference"] for r in runs[solver])
        rows.append((solver, m["newton_total"], " ".join(map(str, m["newton_per_step"])),
                     m["krylov_total"], m["multigrid_builds"], m["total_s"], m["ratio"],
                     m["linear_s"], m["assembly_s"], m["u_difference"], m["force_difference"]))
    header = ("solver", "Newton", "per step", "Krylov", "AMG set-ups", "solve s", "vs fixed",
              "linear s", "assembly s", "u difference", "force difference")
    table = harness.md_table(header, rows)
    u_dofs = base["u_dofs"]
    if comm.rank == 0:
        harness.write(
            f"inexact_newton_{u_dofs}_np{comm.size}",
            {"machine": harness.machine(), "rounds": args.rounds, "u_dofs": u_dofs,
             "ranks": comm.size, "target_ratio": TARGET_RATIO, "median": medians, "runs": runs},
            table, args.out,
        )
        print(table, flush=True)


if __name__ == "__main__":
    main()
