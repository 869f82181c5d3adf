"""3D DOF ladder: a rigid ball indenting a neo-Hookean block, 1e4 ... 1e6 displacement DOFs.

One case (size, linear solver) per process, so that peak memory is the
case's own: ``python benchmarks/performance/ladder3d.py --dofs 1e5 --solver iterative``
(or under ``mpiexec -n 2``). GNRM with the extrapolating predictor, 2 load
steps, Newton tolerance 1e-10 relative to the first residual of each step.
Solvers (:data:`SOLVERS`): ``direct`` (MUMPS), ``iterative`` (GMRES, Schur
field split with full factorisation, GAMG; Krylov rtol 1e-10 at every Newton
step), ``upper`` (the same with the upper Schur factorisation), and the
inexact Newton variants of the iterative solver: ``ew`` (Eisenstat-Walker
forcing terms, upper factorisation), ``inexact`` (and the multigrid
hierarchy kept within a load step), ``inexact-full`` (``inexact`` with the
full factorisation), ``inexact-path`` (the hierarchy kept along the path).
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
from mpi4py import MPI

from benchmarks import cases, harness
from benchmarks.cases import cells_for_dofs
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import solve_load_path

STEPS = 2
NEWTON = SolverSettings(atol=1e-12, rtol=1e-10, max_iterations=30)
_EW = {"kind": "iterative", "forcing": "eisenstat-walker"}
#: The linear solver of each ``--solver`` choice.
SOLVERS = {
    "direct": LinearSolverSettings(kind="direct"),
    "iterative": LinearSolverSettings(kind="iterative"),
    "upper": LinearSolverSettings(kind="iterative", schur_fact="upper"),
    "ew": LinearSolverSettings(**_EW),
    "inexact": LinearSolverSettings(**_EW, reuse_preconditioner="step"),
    "inexact-full": LinearSolverSettings(**_EW, reuse_preconditioner="step", schur_fact="full"),
    "inexact-path": LinearSolverSettings(**_EW, reuse_preconditioner="path"),
}


def run(n: int, solver: str, comm: MPI.Comm, answer: list | None = None) -> dict:
    """Build and solve the ladder problem once; the time split and counts.

    When ``answer`` is a list, the problem (its final state) is appended to it.
    """
    comm.Barrier()
    start = time.perf_counter()
    problem = cases.build(cases.block_indentation(n), 1.0, comm=comm)
    strategy = Extrapolated(make_strategy("gnrm", problem, NEWTON))
    strategy.kernel.set_linear_solver(SOLVERS[solver])
    build_s = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    comm.Barrier()
    start = time.perf_counter()
    path = solve_load_path(strategy, STEPS, max_cutbacks=0)
    total = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    t = strategy.kernel.timings.to_dict()
    t = {k: comm.allreduce(v, op=MPI.MAX) for k, v in t.items()}
    state = problem.contact_state()
    u = problem.u.x.petsc_vec if hasattr(problem.u.x, "petsc_vec") else None
    if answer is not None:
        answer.append(problem)
    return {
        "n": n,
        "u_dofs": problem.V.dofmap.index_map.size_global * 3,
        "lam_dofs": problem.surface.num_dofs,
        "solver": solver,
        "ranks": comm.size,
        "status": path.status,
        "newton_total": path.iterations,
        "newton_per_step": [s.iterations for s in path.steps],
        "krylov_total": t["krylov_iterations"],
        "multigrid_builds": comm.allreduce(
            strategy.kernel.lag.builds if strategy.kernel.lag is not None else path.iterations,
            op=MPI.MAX,
        ) if solver != "direct" else 0,
        "active_final": state.active_count,
        "contact_force": state.contact_force,
        "u_norm": u.norm() if u is not None else float("nan"),
        "build_s": build_s,
        **harness.split(total, t),
    }


def one(args: argparse.Namespace) -> None:
    """Run one case ``repeats`` times in this process and write its JSON."""
    comm = MPI.COMM_WORLD
    n = cells_for_dofs(args.dofs)
    runs = [run(n, args.solver, comm) for _ in range(args.repeats)]
    med = harness.median_dict(runs)
    med["build_s_first"] = runs[0]["build_s"]
    rss_gb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    med["peak_rss_gb_sum"] = comm.allreduce(rss_gb, op=MPI.SUM)
    med["peak_rss_gb_max"] = comm.allreduce(rss_gb, op=MPI.MAX)
    med["repeats"] = args.repeats
    med["machine"] = harness.machine()
    if comm.rank == 0:
        out = args.out / "ladder3d"
        out.mkdir(parents=True, exist_ok=True)
        name = f"{args.solver}_{med['u_dofs']}_np{comm.size}.json"
        (out / name).write_text(json.dumps({"median": med, "runs": runs}, indent=2) + "\n")
        print(json.dumps(med), flush=True)


def table(out: Path) -> None:
    """Gather the per-case JSON files into ladder3d.md."""
    found = [json.loads(p.read_text())["median"] for p in sorted((out / "ladder3d").glob("*.json"))]
    if not found:
        print(f"No ladder cases in {out / 'ladder3d'}; run ladder3d.py --dofs N first.")
        return
    found.sort(key=lambda m: (m["solver"], m["ranks"], m["u_dofs"]))
    rows = [
        (m["u_dofs"], m["lam_dofs"], m["solver"], m["ranks"], m["repeats"], m["newton_total"],
         m["krylov_total"], m.get("multigrid_builds", "-"), m["total_s"], m["assembly_s"],
         m["linear_s"], m["rest_s"], m["build_s"], m["peak_rss_gb_sum"],
         m.get("peak_rss_gb_max", m["peak_rss_gb_sum"] if m["ranks"] == 1 else "-"), m["status"])
        for m in found
    ]
    header = ("u DOFs", "lam DOFs", "solver", "ranks", "repeats", "Newton", "Krylov", "AMG set-ups",
              "solve s", "assembly s", "linear s", "rest s", "build s", "peak RSS GB",
              "RSS/rank GB", "status")
    (out / "ladder3d.md").write_text(harness.md_table(header, rows) + "\n")
    print(harness.md_table(header, rows))


def main() -> None:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--dofs", type=float, default=1e4)
    parser.add_argument("--solver", choices=tuple(SOLVERS), default="iterative")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    parser.add_argument("--table", action="store_true", help="only gather the table")
    args = parser.parse_args()
    if args.table:
        table(args.out)
    else:
        one(args)


if __name__ == "__main__":
    main()
