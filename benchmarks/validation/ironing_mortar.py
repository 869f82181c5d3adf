"""Frictionless ironing, mortar against node-to-segment: the horizontal reaction while sliding.

Runs the ironing scene (``scenes/ironing.toml``: stiff neo-Hookean half-disk
indenter pressed 0.1 into a softer block, then slid 2.4 radii, GNRM with the
extrapolating predictor; 250 load steps instead of the scene's 50, see
:data:`STEPS`) twice on the same meshes: with the mortar pair and
with the node-to-segment pair. Elastic, frictionless, quasi-static ironing
dissipates nothing, so the indenter's horizontal reaction R_x should vanish
in the steady part of the slide; what remains is the discretisation's
oscillation as striker nodes cross target vertices. Reported over the
steady window (slide/R from 0.6 to 2.4): the amplitude (max - min) / 2 and
the RMS of R_x, their ratio mortar / node-to-segment, Newton iterations and
the estimated order of each step.

The scene's block face strikes the indenter (the soft body conforms to the
stiff convex one). ``--swap`` makes the indenter strike the block instead:
then node-to-segment, at a concave vertex of the dented block, holds a node
on the extension of the facet it has passed, slightly inside the next
facet, and the surface check (``surface_tol`` = 1e-3 h) refuses the step;
``--nts-surface-tol`` loosens that check for the comparison, and the
largest such depth is reported.

Writes OUT/ironing_mortar.json, ironing_mortar.md and ironing_mortar.png.

``--h-indenter 0.02 --h-block 0.06`` meshes the indenter's tip three times
as finely as the block's face: each striker support of the block then
overlaps up to 8 target facets, more than the 4 slots the shipped meshes
need, and the mortar pair takes its slots from the facet sizes.

Run: ``python benchmarks/validation/ironing_mortar.py [--coarse] [--out results/bench]
[--swap] [--nts-surface-tol 1e-2] [--steps 250] [--h-indenter H] [--h-block H]
[--figure docs/images/ironing_mortar.png]``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from benchmarks.validation.ironing import order
from fenics_contact.scene.build import build_mesh, build_two_body_problem, tagged_facets
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.solvers.predictor import Extrapolated
from fenics_contact.solvers.stepping import solve_load_path

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "ironing.toml"
RADIUS = 0.5
#: The steady window of the slide, in radii.
WINDOW = (0.6, 2.4)
DISCRETISATIONS = ("node-to-segment", "mortar")


#: Load steps of the whole path: the slide sampled every 0.006, a fifth of the
#: block's facets (the scene's own 50 steps sample it every 0.03, in step with them,
#: and so see every node at the same place on its facet).
STEPS = 250


def run(discretisation: str, coarse: bool, surface_tol: float, swap: bool = False,
        steps: int | None = STEPS, sizes: dict[str, float] | None = None,
        slide: float | None = None, window: tuple[float, float] = WINDOW) -> dict:
    """One ironing run; per-step reactions, iterations, orders and surface depths.

    ``steps``: load steps of the whole path (None: the scene's 50). ``slide``:
    the slide's length (None: the scene's 1.2), over the same share of the
    path. ``window``: the steady part of the slide, in radii.
    """
    scene = load_scene(SCENE)
    if slide is not None:
        scene = replace(scene, dirichlet=tuple(
            replace(d, path=(*d.path[:-1], (d.path[-1][0], slide, d.path[-1][2])))
            if d.path else d for d in scene.dirichlet))
    if steps is not None:
        scene = replace(scene, solver=replace(scene.solver, steps=steps))
    scene = replace(scene, pairs=tuple(
        replace(p, discretisation=discretisation,
                **({"striker": p.target, "target": p.striker} if swap else {}))
        for p in scene.pairs))
    if coarse:
        sizes = {"h_indenter": 0.08, "h_block": 0.12}
    if sizes:
        scene = replace(scene, mesh=replace(scene.mesh, parameters={
            **scene.mesh.parameters, **sizes}))
    body = build_mesh(scene, MPI.COMM_WORLD)
    problem = build_two_body_problem(scene, body)
    top = tagged_facets(body, scene, "top", "top")
    knots = np.asarray(next(d for d in scene.dirichlet if d.path).path)
    settings = SolverSettings(atol=scene.solver.atol, surface_tol=surface_tol)
    strategy = Extrapolated(make_strategy("gnrm", problem, settings))
    rows: list[dict] = []

    def on_step(step) -> None:
        force = problem.reaction(top)
        rows.append({
            "step": step.step, "load_factor": step.load_factor,
            "slide_over_R": float(np.interp(step.load_factor, knots[:, 0], knots[:, 1])) / RADIUS,
            "reaction_x": float(force[0]), "reaction_y": float(force[1]),
            "iterations": step.iterations, "cutbacks": step.cutbacks,
            "order": order(step.residuals[-1]),
            "surface_depth": step.max_penetration,
        })

    path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=4, on_step=on_step)
    return _summary(discretisation, path, rows, surface_tol, window)


def _rigid_scene(quadrature: str, sizes: dict[str, float] | None, folder: Path) -> Path:
    """The shipped scene with the indenter replaced by a rigid circle on the same path."""
    text = SCENE.read_text().replace('"../meshes/', f'"{ROOT / "meshes"}/')
    knots = next(d for d in load_scene(SCENE).dirichlet if d.path).path
    ball = (f'[[obstacle]]\nname = "rigid_circle"\ntype = "ball"\ncentre = [0.0, {RADIUS}]\n'
            f"radius = {RADIUS}\nschedule = {[list(k) for k in knots]}\n"
            f'tag = "target_face"\nr = 1.0\nrelative = true\nquadrature = "{quadrature}"\n\n')
    text = re.sub(r'^\[\[body\]\]\nname = "indenter".*?\n\n', "", text, flags=re.S | re.M)
    text = re.sub(r"^\[\[pair\]\]\n.*?\n\n", ball, text, flags=re.S | re.M)
    text = re.sub(r'^\[\[dirichlet\]\]\ntag = "top".*?\n\n', "", text, flags=re.S | re.M)
    params = {"h_indenter": 0.04, "h_block": 0.06, **(sizes or {}), "indenter": 0}
    text = re.sub(r"^parameters = .*$", "parameters = { " + ", ".join(
        f"{k} = {v:g}" for k, v in params.items()) + " }", text, flags=re.M)
    path = folder / f"ironing_rigid_{quadrature}.toml"
    path.write_text(text)
    return path


def run_rigid(quadrature: str, sizes: dict[str, float] | None, steps: int | None,
              folder: Path) -> dict:
    """The floor of the block's own discretisation: an exact rigid circle on the same path.

    Nodal contact on the block's face (``quadrature = "nodal"``) or at its Gauss
    points; R_x of the circle = minus the block's support reaction.
    """
    scene = load_scene(_rigid_scene(quadrature, sizes, folder))
    if steps is not None:
        scene = replace(scene, solver=replace(scene.solver, steps=steps))
    body = build_mesh(scene, MPI.COMM_WORLD)
    problem = build_two_body_problem(scene, body)
    bottom = tagged_facets(body, scene, "bottom", "bottom")
    knots = np.asarray(scene.obstacles[0].obstacle.schedule)
    strategy = Extrapolated(make_strategy("gnrm", problem, SolverSettings(atol=scene.solver.atol)))
    rows: list[dict] = []

    def on_step(step) -> None:
        force = -problem.reaction(bottom)
        rows.append({"step": step.step, "load_factor": step.load_factor,
                     "slide_over_R": float(np.interp(step.load_factor, knots[:, 0],
                                                     knots[:, 1])) / RADIUS,
                     "reaction_x": float(force[0]), "reaction_y": float(force[1]),
                     "iterations": step.iterations, "cutbacks": step.cutbacks,
                     "order": order(step.residuals[-1]),
                     "surface_depth": step.max_penetration})

    path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=4, on_step=on_step)
    return _summary(f"rigid circle, {quadrature}", path, rows, np.nan)


def _summary(name: str, path, rows: list[dict], surface_tol: float,
             window: tuple[float, float] = WINDOW) -> dict:
    """The steady window's R_x figures and the run's counts."""
    steady = [r for r in rows if window[0] <= r["slide_over_R"] <= window[1] + 1e-9]
    rx = np.array([r["reaction_x"] for r in steady])
    ry = np.array([r["reaction_y"] for r in steady])
    orders = np.array([r["order"] for r in rows])
    return {
        "discretisation": name, "status": path.status, "steps": len(rows),
        "iterations": int(sum(r["iterations"] for r in rows)),
        "surface_tol": surface_tol,
        "steady_steps": len(steady),
        "rx_amplitude": float((rx.max() - rx.min()) / 2) if rx.size else float("nan"),
        "rx_rms": float(np.sqrt(np.mean(rx**2))) if rx.size else float("nan"),
        "rx_mean": float(rx.mean()) if rx.size else float("nan"),
        "ry_mean": float(ry.mean()) if ry.size else float("nan"),
        "cutbacks": int(sum(r["cutbacks"] for r in rows)),
        "failed_at": path.steps[-1].failed_at if path.status != "converged" else None,
        "median_order": float(np.nanmedian(orders)), "min_order": float(np.nanmin(orders)),
        "max_surface_depth": max(r["surface_depth"] for r in rows),
        "rows": rows,
    }


def report(record: dict) -> list[str]:
    """The markdown lines of the comparison."""
    lines = [
        f"# Frictionless ironing: mortar against node-to-segment ({record['mesh']} mesh, "
        f"the {record['striker']} strikes)", "",
        f"Steady window slide/R = {WINDOW[0]} ... {WINDOW[1]}; R_x should vanish there "
        "(elastic, frictionless).", "",
        "| pair | status | steps | cut-backs | Newton its | R_x amplitude | R_x RMS | mean R_x "
        "| mean -R_y | median order | largest surface depth |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for d in DISCRETISATIONS + tuple(record.get("rigid", {})):
        r = record[d] if d in record else record["rigid"][d]
        lines.append(
            f"| {d} | {r['status']} | {r['steps']} | {r['cutbacks']} | {r['iterations']} | "
            f"{r['rx_amplitude']:.4f} | "
            f"{r['rx_rms']:.4f} | {r['rx_mean']:+.4f} | {-r['ry_mean']:.3f} | "
            f"{r['median_order']:.2f} | {r['max_surface_depth']:.2e} |")
    lines += ["", f"Amplitude ratio mortar / node-to-segment: {record['amplitude_ratio']:.3f}; "
              f"RMS ratio {record['rms_ratio']:.3f}. Node-to-segment ran with surface_tol = "
              f"{record['node-to-segment']['surface_tol']:g} h."]
    if record.get("rigid"):
        lines += ["", "Rigid circle rows: the indenter replaced by an exact rigid circle on the "
                  "same path over the same block mesh (`--rigid`): the R_x that the block's own "
                  "discretisation leaves, with no polygon on the indenter's side."]
    return lines


def figure(record: dict, path: Path) -> None:
    """R_x against the slide for both pairs."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    for d, style in zip(DISCRETISATIONS, ("s-", "o-"), strict=True):
        rows = record[d]["rows"]
        ax.plot([r["slide_over_R"] for r in rows], [-r["reaction_x"] for r in rows], style,
                ms=3, label=f"{d} (amplitude {record[d]['rx_amplitude']:.3f})")
    ax.axvspan(*WINDOW, color="0.93", zorder=0, label="steady window")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("slide / R (press phase at 0)")
    ax.set_ylabel("horizontal reaction on the indenter")
    ax.set_title(f"Frictionless ironing (vertical reaction about "
                 f"{-record['mortar']['ry_mean']:.1f})")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--coarse", action="store_true", help="h = 0.08 / 0.12 (tests)")
    parser.add_argument("--nts-surface-tol", type=float, default=SolverSettings().surface_tol)
    parser.add_argument("--swap", action="store_true", help="the indenter strikes the block")
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    parser.add_argument("--figure", type=Path, default=None)
    parser.add_argument("--steps", type=int, default=STEPS,
                        help=f"load steps of the whole path (default {STEPS}: the slide "
                             "sampled every 0.006; the scene has 50)")
    parser.add_argument("--h-indenter", type=float, default=None,
                        help="facet size at the indenter's tip (shipped 0.04)")
    parser.add_argument("--h-block", type=float, default=None,
                        help="facet size along the block's face (shipped 0.03)")
    parser.add_argument("--rigid", action="store_true",
                        help="also an exact rigid circle on the same path (nodal and Gauss "
                             "contact on the block): the block's own floor")
    parser.add_argument("--arc-grading", type=float, default=None,
                        help="facet size at the arc's ends over the tip's (shipped 4)")
    args = parser.parse_args()
    sizes = {k: v for k, v in (("h_indenter", args.h_indenter), ("h_block", args.h_block),
                               ("arc_grading", args.arc_grading)) if v is not None}
    mesh = "coarse" if args.coarse else ("shipped" if not sizes else ", ".join(
        f"{k} = {v:g}" for k, v in sizes.items()))
    record: dict = {"machine": harness.machine(), "mesh": mesh,
                    "striker": "indenter" if args.swap else "block", "steps": args.steps}
    record["node-to-segment"] = run("node-to-segment", args.coarse, args.nts_surface_tol,
                                    args.swap, args.steps, sizes)
    record["mortar"] = run("mortar", args.coarse, SolverSettings().surface_tol, args.swap,
                           args.steps, sizes)
    if args.rigid:
        args.out.mkdir(parents=True, exist_ok=True)
        record["rigid"] = {f"rigid circle, {q}": run_rigid(q, sizes, args.steps, args.out)
                           for q in ("nodal", "gauss")}
    nts, mortar = record["node-to-segment"], record["mortar"]
    record["amplitude_ratio"] = mortar["rx_amplitude"] / nts["rx_amplitude"]
    record["rms_ratio"] = mortar["rx_rms"] / nts["rx_rms"]
    if MPI.COMM_WORLD.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "ironing_mortar.json").write_text(json.dumps(record, indent=2))
        lines = report(record)
        (args.out / "ironing_mortar.md").write_text("\n".join(lines) + "\n")
        figure(record, args.figure or args.out / "ironing_mortar.png")
        print("\n".join(lines))


if __name__ == "__main__":
    main()
