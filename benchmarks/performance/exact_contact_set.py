"""Every shipped scene with each Newton step's contact set: the sign rule and the exact one.

``contact_set = "sign"`` takes the set of a Newton step from the sign of
lam + r g at the iterate (the paper's GNRM); ``"exact"`` solves the step's
linear complementarity problem with the step's own factorisation
(:class:`~fenics_contact.solvers.complementarity.ExactContactSet`). Each
scene runs with its own [solver] settings, once with each (one run each,
interleaved). Reported: Newton iterations in total and per step, the
back-substitutions the exact set took, the load path's wall time, and the
largest difference of the final displacements relative to the largest
displacement (the answer must be the same).

Run: ``python benchmarks/performance/exact_contact_set.py [--scenes a,b] [--out DIR]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import numpy as np

from benchmarks import harness
from fenics_contact.runner import scene_strategy
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers.stepping import solve_load_path

ROOT = Path(__file__).resolve().parents[2]
SETS = ("sign", "exact")


def run(path: Path, contact_set: str) -> tuple[dict, np.ndarray]:
    """One load path of the scene with that contact set; its record and final u."""
    scene = load_scene(path)
    scene = replace(scene, solver=replace(scene.solver, contact_set=contact_set))
    problem = build_problem(scene)
    strategy = scene_strategy(scene, problem)
    start = time.perf_counter()
    result = solve_load_path(strategy, scene.solver.steps)
    wall = time.perf_counter() - start
    exact = strategy.kernel.complementarity
    return {
        "scene": path.stem, "contact_set": contact_set, "converged": result.converged,
        "newton": result.iterations, "per_step": [s.iterations for s in result.steps],
        "columns": exact.columns if exact is not None else 0, "path_s": wall,
        "exact_used": exact is not None,
    }, problem.u.x.array.copy()


def main() -> None:
    """Both contact sets on every scene; JSON and a markdown table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="", help="comma-separated scene names (default all)")
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    names = [n for n in args.scenes.split(",") if n]
    paths = ([ROOT / "scenes" / f"{n}.toml" for n in names]
             or sorted((ROOT / "scenes").glob("*.toml")))
    records, rows = [], []
    totals = dict.fromkeys(SETS, 0)
    for path in paths:
        pair = {}
        for contact_set in SETS:
            record, u = run(path, contact_set)
            pair[contact_set] = (record, u)
            records.append(record)
            totals[contact_set] += record["newton"]
        (sign, u_sign), (exact, u_exact) = pair["sign"], pair["exact"]
        scale = max(float(np.abs(u_sign).max()), 1e-300)
        diff = float(np.abs(u_sign - u_exact).max()) / scale
        exact["u_difference"] = diff
        rows.append((path.stem, sign["newton"], exact["newton"],
                     " ".join(map(str, exact["per_step"])), exact["columns"],
                     sign["path_s"], exact["path_s"], f"{diff:.1e}",
                     "yes" if exact["exact_used"] else "no (sign rule)",
                     "yes" if sign["converged"] and exact["converged"] else "NO"))
    rows.append(("all scenes", totals["sign"], totals["exact"], "", "", "", "", "", "", ""))
    header = ("scene", "Newton, sign", "Newton, exact", "per step (exact)", "columns",
              "path s, sign", "path s, exact", "u difference", "exact set used", "converged")
    table = harness.md_table(header, rows)
    harness.write("exact_contact_set", {"machine": harness.machine(), "runs": records},
                  table, args.out)
    print(table)


if __name__ == "__main__":
    main()
