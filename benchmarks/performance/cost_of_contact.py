"""The cost of contact: the 2D Hertz case with contact (GNRM) against the same body with
the contact replaced by the equivalent Dirichlet condition on the final contact set.

Both run side by side in one process on the same mesh, 10 load steps, the
same Newton kernel, MUMPS and stopping test. The equivalent problem
prescribes, on the nodes in contact at the end, the vertical displacement
that puts them on the plane (u_y = -t y at load factor t), and the top
face as in the contact case. Each run builds its own kernel (matrix,
symbolic factorisation). The Dirichlet problem is run twice: with the
checks the load-path driver makes of every problem's steps, contact or not
(prescribed displacements, the supports' hold, det F), which the contact
runs make too, and as the bare Newton loop. Reported: time per load step
of each, the ratios (target <= 1.3, against the first), and the split into
assembly, linear solver and the rest, median of the repeats.

Run: ``python benchmarks/performance/cost_of_contact.py [--repeats 5]``.
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
import ufl
from dolfinx import fem

from benchmarks import cases, harness
from benchmarks.validation.hertz2d import CYLINDER, STEPS
from fenics_contact.model.problem import ContactProblem, VariationalSystem
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.base import newton_loop
from fenics_contact.solvers.diagnostics import (
    ConvergenceMonitor,
    SolverSettings,
    all_of,
    hold_admissibility,
    prescribed_admissibility,
)
from fenics_contact.solvers.newton import NewtonKernel
from fenics_contact.solvers.stepping import solve_load_path

SETTINGS = SolverSettings(atol=1e-8)
#: The contact runs: (load-step predictor, each Newton step's contact set).
CONTACT = (("active-set", "exact"), ("active-set", "sign"), ("extrapolate", "sign"),
           ("previous", "sign"))


def contact_run(variant: tuple[str, str]) -> tuple[dict, ContactProblem]:
    """Solve with contact; return the record and the solved problem."""
    predictor, contact_set = variant
    problem = cases.build(CYLINDER, 1.0, relative=True, quadrature="nodal")
    strategy = make_strategy("gnrm", problem, SETTINGS, predictor=predictor,
                             contact_set=contact_set)
    kernel = strategy.kernel
    before = kernel.timings.snapshot()
    start = time.perf_counter()
    path = solve_load_path(strategy, STEPS)
    total = time.perf_counter() - start
    assert path.converged, path.status
    t = kernel.timings.since(before).to_dict()
    return {
        "case": f"contact GNRM ({predictor}, {contact_set} set)",
        "newton": path.iterations,
        "jacobians": t["jacobians"],
        "residuals": t["residuals"],
        "per_step_s": total / STEPS,
        **harness.split(total, t),
    }, problem


class DirichletEquivalent:
    """The contact body with the final contact set held on the plane by Dirichlet conditions."""

    def __init__(self, solved: ContactProblem) -> None:
        self.problem = solved
        V = solved.V
        active = solved.contact_state().active
        points = solved.nodal_coordinates()[active]
        Vy, _ = V.sub(1).collapse()

        def on_contact_set(x: np.ndarray) -> np.ndarray:
            d = np.min(np.linalg.norm(x.T[:, None, :2] - points[None, :, :2], axis=2), axis=1)
            return d < 1e-10

        dofs = fem.locate_dofs_geometrical((V.sub(1), Vy), on_contact_set)
        self.g = fem.Function(Vy)
        self.g_final = -Vy.tabulate_dof_coordinates()[:, 1]
        bc = fem.dirichletbc(self.g, dofs, V.sub(1))
        self.u = solved.u  # the solid's own: its step checks below read it
        v = ufl.TestFunction(V)
        energy = solved.material.strain_energy(self.u) * ufl.dx
        self.system = VariationalSystem("dirichlet", [ufl.derivative(energy, self.u, v)],
                                        [self.u], [*solved.bcs, bc])
        self.n_contact = int(np.sum(active))

    def run(self, checks: bool = True) -> dict:
        """Ten load steps with the same Newton loop and stopping test.

        A new kernel each run, as each contact run has (its matrix, its
        solver's symbolic factorisation); its forms come from the cache.
        ``checks``: each step also makes the checks the load-path driver
        makes of every problem, contact or not: the prescribed displacements
        and the supports' hold of a converged iterate, det F of each
        converged step (False: the bare Newton loop).
        """
        self.u.x.array[:] = 0.0
        problem = self.problem
        kernel = NewtonKernel(self.system)
        admissible = (all_of(prescribed_admissibility(problem, SETTINGS),
                             hold_admissibility(problem, SETTINGS)) if checks else None)
        before = kernel.timings.snapshot()
        newton = 0
        start = time.perf_counter()
        for k in range(1, STEPS + 1):
            t = k / STEPS
            self.problem.set_load(t)
            self.g.x.array[:] = t * self.g_final
            status, steps = newton_loop(
                kernel, ConvergenceMonitor(SETTINGS, admissible=admissible),
                kernel.assemble_residual, lambda: None,
            )
            assert status == "converged", status
            if checks:
                assert problem.min_det_F().value > 0.0
            newton += steps
        total = time.perf_counter() - start
        t = kernel.timings.since(before).to_dict()
        kernel.destroy()
        return {
            "case": "Dirichlet on final contact set" + ("" if checks else ", bare Newton loop"),
            "newton": newton,
            "jacobians": t["jacobians"],
            "residuals": t["residuals"],
            "per_step_s": total / STEPS,
            **harness.split(total, t),
        }


def main() -> None:
    """Contact (with and without the predictor) and Dirichlet, interleaved repeats."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args()
    _, solved = contact_run(CONTACT[0])  # warm-up, and the final contact set
    equivalent = DirichletEquivalent(solved)
    equivalent.run()
    runs: dict[str, list[dict]] = {"/".join(v): [] for v in CONTACT}
    runs["dirichlet"], runs["dirichlet-bare"] = [], []
    for _ in range(args.repeats):  # interleaved: the same machine load for all of them
        for variant in CONTACT:
            runs["/".join(variant)].append(contact_run(variant)[0])
        runs["dirichlet"].append(equivalent.run())
        runs["dirichlet-bare"].append(equivalent.run(checks=False))
    med = {k: harness.median_dict(v) for k, v in runs.items()}

    def ratio(k: str, to: str) -> float:
        """Median over the repeats of the per-step time ratio, each repeat's runs side by side."""
        return float(np.median([c["per_step_s"] / d["per_step_s"]
                                for c, d in zip(runs[k], runs[to], strict=True)]))

    ratios = {k: ratio(k, "dirichlet") for k in runs}
    bare = {k: ratio(k, "dirichlet-bare") for k in runs}
    rows = [
        (m["case"], m["newton"], m["jacobians"], m["residuals"], m["per_step_s"] * 1e3,
         m["assembly_s"] / STEPS * 1e3, m["linear_s"] / STEPS * 1e3, m["rest_s"] / STEPS * 1e3,
         ratios[k], bare[k])
        for k, m in med.items()
    ]
    header = ("case", "Newton", "Jacobians", "residuals", "ms / step", "assembly ms / step",
              "linear ms / step", "rest ms / step", "ratio to Dirichlet",
              "ratio to the bare loop")
    table = harness.md_table(header, rows)
    harness.write(
        "cost_of_contact",
        {"machine": harness.machine(), "repeats": args.repeats, "median": med, "ratio": ratios,
         "ratio_to_bare_loop": bare, "contact_nodes": equivalent.n_contact, "runs": runs},
        table, args.out,
    )
    print(table)


if __name__ == "__main__":
    main()
