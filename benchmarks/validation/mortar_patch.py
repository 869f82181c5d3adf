"""The contact patch test on non-matching meshes: node-to-segment against mortar, 2D and 3D.

A block pressed uniformly onto another (uniaxial stress: the exact contact
pressure is uniform). 2D: ``scenes/block_on_block.toml`` (8 and 11
divisions along the interface, plane strain, exact pressure
E delta / ((1 - nu^2) H) = 2.198); 3D: ``scenes/block_on_block_3d.toml``
(tetrahedra of h = 0.125 and 0.17 at the interface, exact pressure 2). Each
with a node-to-segment and a mortar pair (GNRM, 2 steps). Reported: the
spread (max - min) / exact of the nodal pressures and the force balance.
Writes ``<out>/mortar_patch.json`` and ``.md`` and, with ``--figure``, the
nodal pressures along x of all four runs.

Run: ``python benchmarks/validation/mortar_patch.py [--out results/bench]
[--figure docs/images/mortar_patch.png]``.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.harness import figure_parser, report, save_figure
from fenics_contact import build_problem, load_scene, make_strategy, solve_load_path
from fenics_contact.solvers.diagnostics import SolverSettings

ROOT = Path(__file__).resolve().parents[2]
SCENES = {"2D": ("block_on_block.toml", 200.0 / (1 - 0.3**2) * 0.01),
          "3D": ("block_on_block_3d.toml", 200.0 * 0.01)}
DISCRETISATIONS = ("node-to-segment", "mortar")


def solve(dimension: str, discretisation: str) -> dict:
    """One patch test: nodal pressures along x, their spread, the Newton count."""
    name, exact = SCENES[dimension]
    scene = load_scene(ROOT / "scenes" / name)
    pairs = tuple(dataclasses.replace(p, discretisation=discretisation) for p in scene.pairs)
    problem = build_problem(dataclasses.replace(scene, pairs=pairs))
    path = solve_load_path(make_strategy("gnrm", problem, SolverSettings(atol=1e-10)), 2)
    state = problem.contact_state()
    comm = problem.comm
    x = np.concatenate(comm.allgather(problem.nodal_coordinates()[:, 0]))
    p = -np.concatenate(comm.allgather(state.pressure))
    return {"dimension": dimension, "discretisation": discretisation, "status": path.status,
            "iterations": path.iterations, "exact": exact,
            "spread": float((p.max() - p.min()) / exact),
            "force_error": float(abs(state.contact_force / exact
                                     / (0.25 if dimension == "3D" else 1.0) - 1.0)),
            "x": x.tolist(), "p": p.tolist()}


def picture(runs: list[dict], path: Path) -> None:
    """Nodal pressure / exact along x, 2D and 3D, both pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
    for ax, dimension in zip(axes, SCENES, strict=True):
        for run, marker in zip([r for r in runs if r["dimension"] == dimension], ("s", "o"),
                               strict=True):
            ax.plot(run["x"], np.array(run["p"]) / run["exact"], marker, ms=4,
                    mfc="none" if marker == "s" else None,
                    label=f"{run['discretisation']}: spread {run['spread']:.1e}")
        ax.axhline(1.0, color="k", lw=0.6)
        ax.set_xlabel("x")
        ax.set_title(f"{dimension} patch test, non-matching meshes")
        ax.legend(fontsize=8)
    axes[0].set_ylabel("nodal pressure / exact")
    fig.tight_layout()
    save_figure(fig, path)


def main() -> None:
    """Command line."""
    args = figure_parser(__doc__).parse_args()
    runs = [solve(dim, d) for dim in SCENES for d in DISCRETISATIONS]
    table = report("mortar_patch", runs, ["", "pair", "status", "Newton",
                                          "pressure spread / exact", "force error"],
                   ["dimension", "discretisation", "status", "iterations", "spread",
                    "force_error"], args.out, drop=("x", "p"))
    print(table)
    if args.figure is not None:
        picture(runs, args.figure)


if __name__ == "__main__":
    main()
