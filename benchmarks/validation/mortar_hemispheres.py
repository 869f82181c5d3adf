"""Two hemispheres against Hertz with mortar and node-to-segment pairs, on three meshes.

The shipped quarter model (``scenes/two_hemispheres_3d.toml``: R = 1, E = 200,
nu = 0.3, flat faces pushed 0.02 closer, non-matching tetrahedra) in 4 steps
(GNRM, r = 1 E/h) with the pair's contact size h = 0.03, 0.02, 0.015 and
0.01 and each discretisation. For each run: the contact radius and peak of the fit of
the nodal pressures (p^2 against r^2) and the largest nodal pressure against
Hertz for two identical spheres at the computed force (R_eff = R/2,
E* = E / (2 (1 - nu^2)), four quarters), the relative L2 error of the nodal
pressures inside r < a - 2h, the Newton iterations and the solve time.
Writes ``<out>/mortar_hemispheres.json`` and ``.md`` and, with ``--figure``,
both profiles on the finest mesh against Hertz.

Run: ``python benchmarks/validation/mortar_hemispheres.py [--out results/bench]
[--figure docs/images/mortar_hemispheres.png] [--sizes 0.03,0.02,0.015,0.01]``.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np

from mpi4py import MPI

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.harness import figure_parser, report, save_figure
from fenics_contact import build_problem, load_scene, make_strategy, solve_load_path
from fenics_contact.references.hertz import fit_contact_profile
from fenics_contact.references.hertz3d import hertz_point_contact
from fenics_contact.solvers.diagnostics import SolverSettings

ROOT = Path(__file__).resolve().parents[2]
SIZES = (0.03, 0.02, 0.015, 0.01)
DISCRETISATIONS = ("node-to-segment", "mortar")
STEPS = 4


def scene_for(h: float, discretisation: str):
    """The shipped hemispheres scene at contact size h with the pair's discretisation."""
    scene = load_scene(ROOT / "scenes" / "two_hemispheres_3d.toml")
    pairs = tuple(dataclasses.replace(p, discretisation=discretisation) for p in scene.pairs)
    mesh = dataclasses.replace(scene.mesh, parameters={**scene.mesh.parameters, "h_contact": h})
    return dataclasses.replace(scene, pairs=pairs, mesh=mesh)


def solve(h: float, discretisation: str) -> dict:
    """One run: the radial profile, the force and the errors against Hertz."""
    problem = build_problem(scene_for(h, discretisation))
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10))
    start = time.perf_counter()
    path = solve_load_path(strategy, STEPS)
    seconds = time.perf_counter() - start
    state = problem.contact_state()
    comm = problem.comm
    r = np.concatenate(comm.allgather(np.linalg.norm(problem.nodal_coordinates()[:, :2], axis=1)))
    p = -np.concatenate(comm.allgather(state.pressure))
    order = np.argsort(r)
    r, p = r[order], p[order]
    force = 4.0 * state.contact_force  # global already; four quarters
    hertz = hertz_point_contact(force, 0.5, 100.0, 0.3)
    fit = fit_contact_profile(r, p)
    exact = hertz.p0 * np.sqrt(np.clip(1.0 - (r / hertz.a) ** 2, 0.0, None))
    inside = r < hertz.a - 2 * h
    l2 = float(np.sqrt(np.sum((p - exact)[inside] ** 2) / np.sum(exact[inside] ** 2)))
    return {
        "h": h, "discretisation": discretisation, "status": path.status,
        "u_dofs": problem.V.dofmap.index_map.size_global * 3,
        "iterations": path.iterations, "per_step": [s.iterations for s in path.steps],
        "solve_s": seconds, "force": force, "a_hertz": hertz.a, "p0_hertz": hertz.p0,
        "a_error": fit.a / hertz.a - 1.0, "p0_fit_error": fit.p0 / hertz.p0 - 1.0,
        "peak_error": float(p.max() / hertz.p0 - 1.0), "l2_inside": l2,
        "max_penetration": comm.allreduce(state.max_penetration, op=MPI.MAX),
        "r": r.tolist(), "p": p.tolist(),
    }


def picture(runs: list[dict], h: float, path: Path) -> None:
    """Both discretisations' nodal pressures against Hertz at contact size h."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chosen = [run for run in runs if run["h"] == h]
    fig, axes = plt.subplots(1, len(chosen), figsize=(5.2 * len(chosen), 3.8), sharey=True)
    for ax, run in zip(np.atleast_1d(axes), chosen, strict=True):
        a, p0 = run["a_hertz"], run["p0_hertz"]
        rs = np.linspace(0, 1.3 * a, 300)
        ax.plot(rs / a, np.sqrt(np.clip(1 - (rs / a) ** 2, 0, None)), "k-", label="Hertz")
        ax.plot(np.array(run["r"]) / a, np.array(run["p"]) / p0, "o", ms=3,
                label=f"nodes: peak {run['peak_error']:+.1%}, fit a {run['a_error']:+.1%}, "
                      f"p0 {run['p0_fit_error']:+.1%}")
        ax.set_xlim(0, 1.35)
        ax.set_xlabel("r / a")
        ax.set_title(f"{run['discretisation']}, h = {h:g} R")
        ax.legend(fontsize=7, loc="lower left")
    np.atleast_1d(axes)[0].set_ylabel("p / p0 (Hertz)")
    fig.suptitle("Two hemispheres on non-matching tetrahedra", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path)


def main() -> None:
    """Command line."""
    args = figure_parser(__doc__, SIZES).parse_args()
    sizes = args.sizes
    runs = [solve(h, d) for h in sizes for d in DISCRETISATIONS]
    if MPI.COMM_WORLD.rank != 0:
        return
    for run in runs:
        run["solve_s"] = round(run["solve_s"], 1)
    table = report("mortar_hemispheres", runs,
                   ["h", "pair", "DOFs", "status", "Newton", "a (fit)", "p0 (fit)",
                    "nodal peak", "L2 r < a - 2h", "solve s"],
                   ["h", "discretisation", "u_dofs", "status", "iterations", "a_error",
                    "p0_fit_error", "peak_error", "l2_inside", "solve_s"], args.out,
                   drop=("r", "p"))
    print(table)
    if args.figure is not None:
        picture(runs, min(sizes), args.figure)


if __name__ == "__main__":
    main()
