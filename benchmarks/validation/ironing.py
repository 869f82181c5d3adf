"""Ironing: reactions against the slide, convergence order and penetration per step.

Runs scenes/ironing.toml (stiff neo-Hookean half-disk indenter pressed into a
softer neo-Hookean block, then slid 2.4 radii in 40 steps, GNRM). After each
converged step: the indenter's horizontal and vertical support reactions, the
max penetration and the estimated order of convergence

    q = log(r_n / r_{n-1}) / log(r_{n-1} / r_{n-2})

on the last three residuals above ``FLOOR`` (the residuals near 1e-13 are at
round-off). Writes results/bench/ironing.json, ironing.md and
ironing_reactions.png.

Run: ``python benchmarks/validation/ironing.py [--scene scenes/ironing.toml]
[--out results/bench]``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from fenics_contact.runner import scene_strategy
from fenics_contact.scene.build import build_mesh, build_two_body_problem, tagged_facets
from fenics_contact.scene.schema import Scene, load_scene
from fenics_contact.solvers.stepping import solve_load_path

#: Residuals below this are at round-off and left out of the order estimate.
FLOOR = 1e-11


def order(residuals: list[float]) -> float:
    """Estimated order from the last three residuals above FLOOR (nan if fewer)."""
    r = [v for v in residuals if v > FLOOR]
    if len(r) < 3:
        return float("nan")
    a, b, c = r[-3:]
    return float(np.log(c / b) / np.log(b / a))


def setup(scene: Scene):
    """Problem, indenter top facets, the top's path knots and the scene's strategy."""
    body = build_mesh(scene, MPI.COMM_WORLD)
    problem = build_two_body_problem(scene, body)
    top = tagged_facets(body, scene, "top", "top")
    knots = np.asarray(next(d for d in scene.dirichlet if d.path).path)
    return problem, top, knots, scene_strategy(scene, problem)  # the scene's [solver]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=Path("scenes/ironing.toml"))
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    args = parser.parse_args()
    scene = load_scene(args.scene)
    problem, top, knots, strategy = setup(scene)
    radius = 0.5
    rows: list[dict] = []

    def on_step(step) -> None:
        force = problem.reaction(top)
        rows.append({
            "step": step.step, "load_factor": step.load_factor,
            "slide": float(np.interp(step.load_factor, knots[:, 0], knots[:, 1])),
            "reaction_x": float(force[0]), "reaction_y": float(force[1]),
            "iterations": step.iterations, "order": order(step.residuals[-1]),
            "max_penetration": step.max_penetration, "contact_force": step.contact_force,
            "residuals": step.residuals[-1],
        })

    path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=0, on_step=on_step)
    orders = np.array([r["order"] for r in rows])
    record = {
        "status": path.status, "steps": len(rows),
        "iterations": int(sum(r["iterations"] for r in rows)),
        "min_order": float(np.nanmin(orders)), "median_order": float(np.nanmedian(orders)),
        "steps_order_ge_1_8": int(np.sum(orders >= 1.8)),
        "max_penetration_over_R": max(r["max_penetration"] for r in rows) / radius,
        "rows": rows,
    }
    if MPI.COMM_WORLD.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "ironing.json").write_text(json.dumps(record, indent=2))
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        slide = [r["slide"] / radius for r in rows]
        ax.plot(slide, [-r["reaction_y"] for r in rows], "o-", ms=3, label="vertical (down)")
        ax.plot(slide, [-r["reaction_x"] for r in rows], "s-", ms=3, label="horizontal")
        ax.set_xlabel("slide / R (press phase at 0)")
        ax.set_ylabel("indenter reaction (force per thickness)")
        ax.set_title("Ironing: reactions on the indenter's top face")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.out / "ironing_reactions.png", dpi=120)
        md = [
            "# Ironing (GNRM, neo-Hookean, 50 steps)", "",
            f"- status {record['status']}, {record['iterations']} Newton iterations",
            f"- estimated order (last three residuals above {FLOOR:g}): min "
            f"{record['min_order']:.2f}, median {record['median_order']:.2f}, "
            f"{record['steps_order_ge_1_8']}/{len(rows)} steps >= 1.8",
            f"- max penetration / R: {record['max_penetration_over_R']:.2e}", "",
        ]
        (args.out / "ironing.md").write_text("\n".join(md))
        print("\n".join(md))


if __name__ == "__main__":
    main()
