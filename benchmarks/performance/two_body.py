"""Two-body cost: search + transfer share of a Newton iteration, and two bodies vs one.

Two identical bodies (node-to-segment pair, condensing kernel) against one
body on a rigid plane with about the same number of displacement DOFs
(standard kernel), both GNRM, linear elastic. 2D: two half-cylinders and one
half-cylinder. 3D: two hemispheres (``scenes/two_hemispheres_3d_node_to_segment.toml``) and
one sphere octant (``benchmarks.cases.hertz_sphere``). Per Newton iteration:
search (closest point + target coefficients), transfer (selection matrix,
P^T R, P^T J P, Dirichlet elimination), and the whole kernel time.

The two cases alternate in one process (two, one, two, one, ...; the
machine is shared) and each figure is the median over ``--repeats`` runs;
the per-case peak memory is the resident high-water mark of each rank
during the case's build and solve (reset before each case; it includes the
interpreter and libraries, and whatever earlier cases left allocated). Under
``mpiexec -n 2`` every time is the maximum over ranks. Writes
``<out>/two_body[_3d][_<solver>][_np<ranks>].json`` and ``.md``.

Run: ``python benchmarks/performance/two_body.py [--dim 3] [--h 0.013]
[--solver iterative] [--steps 4] [--repeats 3] [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import gc
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
from mpi4py import MPI

from benchmarks import cases, harness
from fenics_contact import load_scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.linear import LinearSolverSettings

#: Two hemispheres (quarter model) pressed 0.02 together.
HEMISPHERES = (Path(__file__).resolve().parents[2] / "scenes"
               / "two_hemispheres_3d_node_to_segment.toml")
#: Newton stopping test of the 3D runs with the iterative solver (as the DOF ladder).
NEWTON_ITERATIVE = SolverSettings(atol=1e-12, rtol=1e-10, max_iterations=30)
#: The kernel accounts whose sum is the kernel time (seconds).
KERNEL = ("residual_s", "jacobian_s", "setup_s", "solve_s", "search_s", "transfer_s")


def _reset_peak_memory() -> None:
    """Start a new resident-memory high-water mark (Linux; no-op elsewhere)."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass


def _peak_memory_gb() -> float:
    """This process's resident high-water mark since the last reset (GB; nan if unknown)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024**2
    except OSError:
        pass
    return float("nan")


def _solve(build, steps: int, solver: str) -> dict:
    """Build a problem, solve ``steps`` GNRM load steps; counts, times and memory."""
    comm = MPI.COMM_WORLD
    gc.collect()  # the previous case's objects, before the high-water mark restarts
    _reset_peak_memory()
    comm.Barrier()
    start = time.perf_counter()
    problem = build()
    if solver == "direct":
        strategy = make_strategy("gnrm", problem, SolverSettings())
    else:
        strategy = make_strategy("gnrm", problem, NEWTON_ITERATIVE,
                                 linear=LinearSolverSettings(kind="iterative"))
    build_s = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    comm.Barrier()
    start = time.perf_counter()
    its = 0
    for i in range(1, steps + 1):
        problem.set_load(i / steps)
        result = strategy.solve()
        assert result.converged, result.status
        its += result.iterations
    wall = comm.allreduce(time.perf_counter() - start, op=MPI.MAX)
    t = {k: comm.allreduce(v, op=MPI.MAX) for k, v in strategy.kernel.timings.to_dict().items()}
    kernel = sum(t[k] for k in KERNEL)
    dofs = problem.V.dofmap.index_map.size_global * problem.V.dofmap.index_map_bs
    state = problem.contact_state()
    peak = _peak_memory_gb()
    out = {"dofs": dofs, "iterations": its, "krylov": t["krylov_iterations"],
           "wall_s": wall, "build_s": build_s, "kernel_s": kernel,
           "per_iteration_s": wall / its,
           "search_share": t["search_s"] / kernel, "transfer_share": t["transfer_s"] / kernel,
           "contact_force": state.contact_force, "active": state.active_count,
           "peak_rss_gb_max": comm.allreduce(peak, op=MPI.MAX),
           "peak_rss_gb_sum": comm.allreduce(peak, op=MPI.SUM)}
    out.update({f"t_{k}": v for k, v in t.items()})
    strategy.kernel.destroy()
    return out


def two_bodies(h: float) -> object:
    return cases.build(cases.two_cylinders(h, push=0.02, h_far=0.1), 1.0)


def one_body(h: float) -> object:
    cylinder = cases.hertz_cylinder(h, push=0.02, fine_radius=0.15, coarse_radius=0.6,
                                    h_far=0.1 / 2**0.5)
    return cases.build(cylinder, 1.0)


def two_bodies_3d(h: float) -> object:
    scene = load_scene(HEMISPHERES)
    scene = dataclasses.replace(scene, mesh=dataclasses.replace(
        scene.mesh, parameters={**scene.mesh.parameters, "h_contact": h, "h_far": 2.5 * h}))
    return cases.build(scene, 1.0)


def one_body_3d(h: float) -> object:
    return cases.build(cases.hertz_sphere(h, push=0.01, h_far=2.5 * h), 1.0)


def _table(args: argparse.Namespace, two: dict, one: dict, ratio: float,
           per_dof: float) -> str:
    """The markdown summary of one run of the script."""
    header = ("case", "DOFs", "Newton its", "Krylov its", "s / iteration", "search share",
              "transfer share", "peak RSS / rank GB")
    rows = [
        ("two bodies", two["dofs"], two["iterations"], two["krylov"], two["per_iteration_s"],
         f"{two['search_share']:.1%}", f"{two['transfer_share']:.1%}", two["peak_rss_gb_max"]),
        ("one body on a rigid plane", one["dofs"], one["iterations"], one["krylov"],
         one["per_iteration_s"], "-", "-", one["peak_rss_gb_max"]),
    ]
    ranks = MPI.COMM_WORLD.size
    return "\n".join([
        f"# Two-body cost ({args.dim}D, GNRM, {args.steps} steps, {args.solver} solver, "
        f"{ranks} rank{'s' if ranks > 1 else ''}, median of {args.repeats})", "",
        harness.md_table(header, rows), "",
        f"Cost ratio per Newton iteration (two / one): {ratio:.2f}; "
        f"per iteration and displacement DOF: {per_dof:.2f}", "",
    ])


def main() -> None:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=None,
                        help="two-body mesh size (default 0.005 in 2D, 0.02 in 3D)")
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    parser.add_argument("--repeats", type=int, default=3, help="median over this many runs")
    parser.add_argument("--dim", type=int, default=2, choices=(2, 3))
    parser.add_argument("--solver", choices=("direct", "iterative"), default="direct")
    parser.add_argument("--steps", type=int, default=10)
    args = parser.parse_args()
    if args.dim == 2:
        pair, single, scale = two_bodies, one_body, 2**0.5
    else:
        pair, single, scale = two_bodies_3d, one_body_3d, 2 ** (1 / 3)
    h = args.h if args.h is not None else (0.005 if args.dim == 2 else 0.02)
    twos, ones = [], []
    for _ in range(args.repeats):  # alternated: the machine is shared
        twos.append(_solve(lambda: pair(h), args.steps, args.solver))
        ones.append(_solve(lambda: single(h / scale), args.steps, args.solver))
    two, one = harness.median_dict(twos), harness.median_dict(ones)
    ratios = [a["per_iteration_s"] / b["per_iteration_s"] for a, b in zip(twos, ones, strict=True)]
    ratio = two["per_iteration_s"] / one["per_iteration_s"]
    per_dof = ratio * one["dofs"] / two["dofs"]  # the two cases' sizes differ by a few per cent
    ranks = MPI.COMM_WORLD.size
    record = {"h": h, "dim": args.dim, "solver": args.solver, "steps": args.steps,
              "processes": ranks, "two_bodies": two, "one_body_rigid": one,
              "cost_ratio_per_iteration": ratio, "cost_ratio_per_round": ratios,
              "cost_ratio_per_iteration_and_dof": per_dof,
              "runs": {"two_bodies": twos, "one_body_rigid": ones},
              "machine": harness.machine()}
    if MPI.COMM_WORLD.rank == 0:
        stem = "two_body" if args.dim == 2 else "two_body_3d"
        if args.solver != "direct":
            stem += f"_{args.solver}"
        if ranks > 1:
            stem += f"_np{ranks}"
        table = _table(args, two, one, ratio, per_dof)
        harness.write(stem, record, table, args.out)
        print(table, flush=True)


if __name__ == "__main__":
    main()
