"""Newton iterations per load step with each load-step predictor (issue 21, item 1).

Cases, 10 load steps each, GNRM, nodal contact, MUMPS:
the 2D Hertz cylinder on the medium mesh (h = 0.008, 3814 displacement DOFs)
and the fine mesh (h = 0.004), at atol 1e-8; the two identical cylinders of
``scenes/two_cylinders_node_to_segment.toml`` (node-to-segment pair, graded non-matching
meshes) and the paper's Example 2 (``scenes/paper_ex2.toml``) with their
scenes' solver settings. Predictors: ``previous`` (the last converged
state), ``extrapolate`` (linear extrapolation of the last two) and
``active-set`` (extrapolation, and the first iteration's contact set chosen
from the gaps' history; :class:`~fenics_contact.solvers.predictor.ActiveSetPredicted`).
Each predictor runs with the sign rule for the contact set of every Newton
step (the paper's GNRM), and the active-set predictor also with the exact
set of each step's linear model (``contact_set = "exact"``,
:class:`~fenics_contact.solvers.complementarity.ExactContactSet`; its
back-substitutions are reported as columns); ``two-cylinders-mortar`` is the
shipped mortar scene ``scenes/two_cylinders.toml``.
Reported per case and variant: Newton iterations in total and per step,
and the load path's wall time (median of the repeats, the predictors of a
case run interleaved). The answer is checked to be the same: largest
displacement difference against ``extrapolate``, relative to the largest
displacement. Targets (issue 21): Hertz medium <= 12, fine <= 16, two
cylinders <= 22 with step 1 <= 4, Example 2 <= 40.

Run: ``python benchmarks/performance/active_set_prediction.py [--repeats 3]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import numpy as np

from benchmarks import cases, harness
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.stepping import solve_load_path

ROOT = Path(__file__).resolve().parents[2]
#: (load-step predictor, each Newton step's contact set) of the runs.
VARIANTS = (("previous", "sign"), ("extrapolate", "sign"), ("active-set", "sign"),
            ("active-set", "exact"))
REFERENCE = ("extrapolate", "sign")
TARGETS = {"hertz-medium": 12, "hertz-fine": 16, "two-cylinders": 22,
           "two-cylinders-mortar": 22, "paper-ex2": 40}


def hertz(h: float):
    def build():
        scene = cases.hertz_cylinder(h, push=0.02, fine_radius=0.22)
        problem = cases.build(scene, 1.0, relative=True, quadrature="nodal")
        return problem, SolverSettings(atol=1e-8), 10
    return build


def shipped(name: str):
    def build():
        scene = load_scene(ROOT / "scenes" / f"{name}.toml")
        return build_problem(scene), scene.solver, scene.solver.steps
    return build


CASES = {
    "hertz-medium": hertz(0.008),
    "hertz-fine": hertz(0.004),
    "two-cylinders": shipped("two_cylinders_node_to_segment"),
    "two-cylinders-mortar": shipped("two_cylinders"),
    "paper-ex2": shipped("paper_ex2"),
}


def run(case: str, variant: tuple[str, str]) -> tuple[dict, np.ndarray]:
    """One load path; its record and the final displacement array."""
    predictor, contact_set = variant
    problem, settings, steps = CASES[case]()
    strategy = make_strategy("gnrm", problem, settings, predictor=predictor,
                             contact_set=contact_set)
    start = time.perf_counter()
    path = solve_load_path(strategy, steps)
    wall = time.perf_counter() - start
    assert path.converged, (case, variant, path.status)
    exact = strategy.kernel.complementarity
    return {
        "case": case, "predictor": predictor, "contact_set": contact_set,
        "columns": exact.columns if exact is not None else 0, "newton": path.iterations,
        "per_step": [s.iterations for s in path.steps],
        "active": [s.active_count for s in path.steps], "path_s": wall,
    }, problem.u.x.array.copy()


def main() -> None:
    """Every case with every predictor, interleaved repeats; JSON and a markdown table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    records, rows = {}, []
    for case in CASES:
        runs: dict[tuple[str, str], list[dict]] = {v: [] for v in VARIANTS}
        answers = {}
        run(case, REFERENCE)  # warm-up: forms compiled
        for _ in range(args.repeats):
            for variant in VARIANTS:
                record, u = run(case, variant)
                runs[variant].append(record)
                answers[variant] = u
        scale = float(np.abs(answers[REFERENCE]).max())
        for variant in VARIANTS:
            first = runs[variant][0]
            assert all(r["per_step"] == first["per_step"] for r in runs[variant])
            diff = float(np.abs(answers[variant] - answers[REFERENCE]).max()) / scale
            record = {**first, "path_s": float(np.median([r["path_s"] for r in runs[variant]])),
                      "u_difference": diff, "target": TARGETS[case]}
            records[f"{case}/{'/'.join(variant)}"] = record
            rows.append((case, *variant, record["newton"],
                         " ".join(map(str, record["per_step"])), record["columns"],
                         record["path_s"], diff, TARGETS[case]))
    header = ("case", "predictor", "contact set", "Newton", "per step", "columns",
              "path s (median)", "u difference", "target")
    table = harness.md_table(header, rows)
    harness.write("active_set_prediction",
                  {"machine": harness.machine(), "repeats": args.repeats, "runs": records},
                  table, args.out)
    print(table)


if __name__ == "__main__":
    main()
