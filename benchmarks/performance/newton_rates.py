"""Why a two-cylinder load step takes a third Newton iteration: rates, tangent check, apex.

Cases: the shipped two-cylinder scenes (``two_cylinders_node_to_segment``,
``two_cylinders``: h = 0.005 at the contact) and the same at h = 0.01 (the
mesh of issue 21's first counts), each with its scene's solver (GNRM, the
exact contact set, the active-set predictor, atol 1e-8), 10 load steps.

Reported per case: the residual history of every step and the Newton
constants e_{k+1} / e_k^2; and, at the iterate before the second Newton
step of every step that takes three:

* the Taylor remainder |F(x - s d) - F(x) + s J d| along that step d for
  s = 1, 1/2, 1/4 (s = 1 is the next residual when J d = F(x)); it falls by
  4 per halving when the condensed Jacobian is consistent (2 when a term
  is missing);
* the part of d that answers the tangential rows of the residual at the
  apex nodes (reference point (0, 0) of either body) and the remainder
  along d without it. A node-to-segment striker node sitting on a target
  vertex takes the normal of one of the vertex's two facets: as that facet
  turns within the step its force turns, and the equal and opposite
  tangential forces on the apices shear the two bodies along the
  frictionless interface.

Run: ``python benchmarks/performance/newton_rates.py``.
"""

from __future__ import annotations

import argparse
import itertools
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel's MPI libraries: first)

# isort: split
import numpy as np
from dolfinx.fem import petsc as fem_petsc

from benchmarks import harness
from fenics_contact.runner import scene_strategy
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers.stepping import solve_load_path

ROOT = Path(__file__).resolve().parents[2]
SCENES = {"node-to-segment": "two_cylinders_node_to_segment", "mortar": "two_cylinders"}


def scene_at(name: str, h: float, folder: Path) -> Path:
    """The shipped scene file with the contact mesh size h (length)."""
    text = (ROOT / "scenes" / f"{name}.toml").read_text()
    text = text.replace('"../meshes/', f'"{ROOT / "meshes"}/')
    text = text.replace("h_contact = 0.005", f"h_contact = {h}")
    path = folder / f"{name}_{h}.toml"
    path.write_text(text)
    return path


class Probe:
    """Hooks a strategy's kernel: at the second Newton step of a step, the checks above."""

    def __init__(self, strategy, problem) -> None:
        self.kernel = kernel = strategy.kernel
        self.solve_count, self.iteration = 0, 0
        self.found: dict[int, dict] = {}
        V = problem.contacts[0].solid.V
        self.n_u = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
        X = V.tabulate_dof_coordinates()[: V.dofmap.index_map.size_local, :2]
        self.apex_rows = 2 * np.flatnonzero(np.linalg.norm(X, axis=1) < 1e-12)
        self._solve, self._step = strategy.solve, kernel.newton_step
        strategy.solve, kernel.newton_step = self.solve, self.step

    def solve(self):
        self.solve_count += 1
        self.iteration = 0
        return self._solve()

    def residual(self, x) -> np.ndarray:
        fem_petsc.assign(x, self.kernel.unknowns)
        for f in self.kernel.unknowns:
            f.x.scatter_forward()
        self.kernel._assemble_b()
        return self.kernel.b.getArray().copy()

    def step(self, *args, **kwargs) -> bool:
        self.iteration += 1
        if self.iteration != 2:
            return self._step(*args, **kwargs)
        k = self.kernel
        k._pull()
        x1 = k.x.copy()
        ok = self._step(*args, **kwargs)
        k._pull()
        x2 = k.x.copy()
        self.found[self.solve_count] = self.check(x1, x1.getArray() - x2.getArray())
        self.residual(x2)  # the state and residual the loop goes on from
        k._pull()
        for v in (x1, x2):
            v.destroy()
        return ok

    def check(self, x1, d: np.ndarray) -> dict:
        k = self.kernel
        F1 = self.residual(x1)
        k._assemble_A()

        def vec(a):
            v = x1.duplicate()
            v.setArray(a)
            return v

        def remainder(v: np.ndarray, s: float) -> float:
            xs = x1.copy()
            xs.axpy(-s, vec(v))
            Jv = x1.duplicate()
            k.A.mult(vec(v), Jv)
            return float(np.linalg.norm(self.residual(xs) - F1 + s * Jv.getArray()))

        taylor = [remainder(d, s) for s in (1.0, 0.5, 0.25)]
        f = np.zeros_like(F1)
        f[self.apex_rows] = F1[self.apex_rows]
        k.ksp.setOperators(k.A)
        m = x1.duplicate()
        k.ksp.solve(vec(f), m)
        rest = d - m.getArray()
        out = {"taylor": taylor, "apex_force": float(np.linalg.norm(f)),
               "d_u": float(np.linalg.norm(d[: self.n_u])),
               "apex_response_u": float(np.linalg.norm(m.getArray()[: self.n_u])),
               "without_apex": remainder(rest, 1.0)}
        self.residual(x1)
        return out


def run(name: str, path: Path) -> dict:
    scene = load_scene(path)
    problem = build_problem(scene)
    strategy = scene_strategy(scene, problem)
    probe = Probe(strategy, problem)
    record = solve_load_path(strategy, scene.solver.steps)
    assert record.converged, name
    histories = [[float(r) for solve in step.residuals for r in solve] for step in record.steps]
    return {"per_step": [s.iterations for s in record.steps], "newton": record.iterations,
            "residuals": histories, "force": record.steps[-1].contact_force,
            "third": {s: v for s, v in probe.found.items()
                      if record.steps[s - 1].iterations >= 3}}


def main() -> None:
    """Both pairs at both mesh sizes; the histories and the checks, JSON and markdown."""
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    records, rows = {}, []
    with tempfile.TemporaryDirectory() as tmp:
        for h in (0.005, 0.01):
            for pair, name in SCENES.items():
                rec = run(pair, scene_at(name, h, Path(tmp)))
                records[f"{pair}/h={h}"] = rec
                for step, res in enumerate(rec["residuals"], start=1):
                    const = " ".join(f"{b / a**2:.3g}" for a, b in itertools.pairwise(res))
                    third = rec["third"].get(step)
                    rows.append((pair, h, step, " ".join(f"{r:.2e}" for r in res), const,
                                 _describe(third)))
    header = ("pair", "h", "step", "residuals", "e_k+1 / e_k^2", "third iteration: checks")
    table = harness.md_table(header, rows)
    harness.write("newton_rates", {"machine": harness.machine(), "runs": records}, table)
    print(table)
    for key, rec in records.items():
        print(f"{key}: {rec['newton']} ({' '.join(map(str, rec['per_step']))}), "
              f"force {rec['force']:.12g}")


def _describe(third: dict | None) -> str:
    if third is None:
        return ""
    t = third["taylor"]
    return (f"Taylor {t[0]:.2e} {t[1]:.2e} {t[2]:.2e}; |d_u| {third['d_u']:.2e}, "
            f"apex response {third['apex_response_u']:.2e}; "
            f"remainder without it {third['without_apex']:.2e}")


if __name__ == "__main__":
    main()
