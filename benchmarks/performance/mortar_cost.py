"""Mortar against node-to-segment: the cost of a Newton iteration and of the first compilation.

``--case cylinders`` (2D, the default): two identical half-cylinders (linear
elastic, E = 200, nu = 0.3) pushed together by 0.02 in 10 steps;
``--case hemispheres`` (3D): the shipped two hemispheres (quarter model) in
4 steps at contact size ``--h``. GNRM and MUMPS, on one mesh, once with a
node-to-segment pair and once with a mortar pair; the runs alternate
(``--repeats`` of each, side by side in one process) and the median time per
Newton iteration of each is compared, with the kernel's accounts (residual
and Jacobian assembly, linear solve, search, transfer).

With ``--cold`` each discretisation is also built once in a child process
with an empty form cache (``XDG_CACHE_HOME`` set to a new folder): the time
from the start of the build to the end of the first Newton iteration, which
is what a user waits for the first time a scene runs. ``--opt`` chooses the
C optimisation level of the mortar forms (the library's default is the
``MortarContact.jit_options``).

Writes ``OUT/mortar_cost.json`` and ``.md`` (3D: ``mortar_cost_3d``).

Run: ``python benchmarks/performance/mortar_cost.py [--case cylinders|hemispheres]
[--h 0.004] [--repeats 3] [--cold] [--opt 0|1|2] [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import cases
from fenics_contact.model.mortar import MortarContact
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings

STEPS = {"cylinders": 10, "hemispheres": 4}
DISCRETISATIONS = ("node-to-segment", "mortar")
ACCOUNTS = ("residual_s", "jacobian_s", "setup_s", "solve_s", "search_s", "transfer_s")


CASE = "cylinders"


def scene(h: float, discretisation: str):
    """The case at contact size h, with the given pair (2D: the target's size is 1.37 h)."""
    if CASE == "hemispheres":
        from benchmarks.validation.mortar_hemispheres import scene_for

        return scene_for(h, discretisation)
    base = cases.two_cylinders(h, push=0.02, steps=STEPS[CASE], h_far=0.1)
    return replace(base, pairs=tuple(replace(p, discretisation=discretisation)
                                     for p in base.pairs))


def set_mortar_optimisation(level: int | None) -> None:
    """Compile the mortar forms at -O``level`` (None: the library's default)."""
    if level is not None:
        MortarContact.jit_options = {"cffi_extra_compile_args": [f"-O{level}", "-g0"]}


def run(h: float, discretisation: str, first_only: bool = False) -> dict:
    """Build and solve; seconds to build, to the first iteration, and per iteration."""
    start = time.perf_counter()
    problem = cases.build(scene(h, discretisation), 1.0)
    strategy = make_strategy("gnrm", problem, SolverSettings(max_iterations=1 if first_only
                                                              else 50))
    built = time.perf_counter()
    its = 0
    steps = STEPS[CASE]
    for i in range(1, (1 if first_only else steps) + 1):
        problem.set_load(i / steps)
        result = strategy.solve()
        if not first_only:
            assert result.converged, (discretisation, i, result.status)
        its += result.iterations
    end = time.perf_counter()
    timings = strategy.kernel.timings.to_dict()
    dofs = problem.V.dofmap.index_map.size_global * problem.V.dofmap.index_map_bs
    record = {"discretisation": discretisation, "dofs": dofs, "iterations": its,
              "build_s": built - start, "solve_s": end - built, "to_first_iteration_s":
              end - start if first_only else None,
              "compile_s": timings["compile_s"], "per_iteration_s": (end - built) / its,
              "contact_force": problem.contact_state().contact_force}
    record["accounts_per_iteration_s"] = {k: timings[k] / its for k in ACCOUNTS}
    return record


def cold(h: float, discretisation: str, opt: int | None) -> dict:
    """``run(first_only=True)`` in a child process with an empty form cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "XDG_CACHE_HOME": cache}
        argv = [sys.executable, __file__, "--child", discretisation, "--h", str(h),
                "--case", CASE]
        if opt is not None:
            argv += ["--opt", str(opt)]
        out = subprocess.run(argv, env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def table(record: dict) -> list[str]:
    """The markdown lines of the report."""
    nts, mortar = (record["warm"][d] for d in DISCRETISATIONS)
    lines = [
        f"# Mortar against node-to-segment: two {CASE}, h = {record['h']:g}, "
        f"GNRM, {STEPS[CASE]} steps", "",
        f"Mortar forms at {record['mortar_flags']}; {record['repeats']} alternating runs of "
        "each, medians.", "",
        "| pair | DOFs | Newton its | s / iteration | residual | Jacobian | LU + solve | search "
        "| transfer |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for d, r in ((d, record["warm"][d]) for d in DISCRETISATIONS):
        a = r["accounts_per_iteration_s"]
        lines.append(
            f"| {d} | {r['dofs']} | {r['iterations']} | {r['per_iteration_s']:.4f} | "
            f"{a['residual_s']:.4f} | {a['jacobian_s']:.4f} | "
            f"{a['setup_s'] + a['solve_s']:.4f} | {a['search_s']:.4f} | "
            f"{a['transfer_s']:.4f} |")
    lines += ["", f"Cost ratio per Newton iteration (mortar / node-to-segment, medians of "
              f"the same run): {mortar['per_iteration_s'] / nts['per_iteration_s']:.2f}"]
    if record.get("cold"):
        lines += ["", "Empty form cache, build to the end of the first Newton iteration:", "",
                  "| pair | seconds |", "|---|---|"]
        lines += [f"| {d} | {r['to_first_iteration_s']:.1f} |"
                  for d, r in record["cold"].items()]
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=tuple(STEPS), default="cylinders")
    parser.add_argument("--h", type=float, default=None,
                        help="contact size (default 0.004 cylinders, 0.01 hemispheres)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--opt", type=int, default=None, choices=(0, 1, 2, 3))
    parser.add_argument("--cold", action="store_true", help="also time an empty form cache")
    parser.add_argument("--child", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    args = parser.parse_args()
    global CASE
    CASE = args.case
    if args.h is None:
        args.h = 0.004 if CASE == "cylinders" else 0.01
    set_mortar_optimisation(args.opt)
    if args.child:
        print(json.dumps(run(args.h, args.child, first_only=True)))
        return
    runs: dict[str, list[dict]] = {d: [] for d in DISCRETISATIONS}
    for d in DISCRETISATIONS:  # compile (or load) both before timing anything
        run(args.h, d, first_only=True)
    for _ in range(args.repeats):
        for d in DISCRETISATIONS:
            runs[d].append(run(args.h, d))
    warm = {}
    for d, rs in runs.items():
        median = statistics.median(r["per_iteration_s"] for r in rs)
        warm[d] = min(rs, key=lambda r, m=median: abs(r["per_iteration_s"] - m))
        warm[d]["per_iteration_all_s"] = [r["per_iteration_s"] for r in rs]
    record = {"h": args.h, "repeats": args.repeats, "processes": MPI.COMM_WORLD.size,
              "mortar_flags": " ".join(MortarContact.jit_options["cffi_extra_compile_args"]),
              "warm": warm,
              "ratio_per_iteration": warm["mortar"]["per_iteration_s"]
              / warm["node-to-segment"]["per_iteration_s"]}
    if args.cold and MPI.COMM_WORLD.size == 1:
        record["cold"] = {d: cold(args.h, d, args.opt) for d in DISCRETISATIONS}
    if MPI.COMM_WORLD.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        name = "mortar_cost" if CASE == "cylinders" else "mortar_cost_3d"
        record["case"] = CASE
        (args.out / f"{name}.json").write_text(json.dumps(record, indent=2))
        lines = table(record)
        (args.out / f"{name}.md").write_text("\n".join(lines) + "\n")
        print("\n".join(lines))


if __name__ == "__main__":
    main()
