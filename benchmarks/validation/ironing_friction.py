"""Ironing with Coulomb friction: force ratio against the slide, iterations, convergence order.

Runs scenes/ironing_friction.toml (mu = 0.3) and the same scene frictionless
(the pair's mu removed), GNRM with the scene's predictor. After each
converged step it records the reaction on the indenter's top face R (the
force the support exerts on the indenter: the contact force on it is -R),
the normal contact force N = -int p dA, the frictional force in each node's
own frame F_t = int |tau| dA, the stick/slip counts, the Newton iterations
and the estimated order of the last iterations.

Ratios, per step:

- ``reaction_ratio`` = R_x / -R_y: horizontal over vertical reaction;
- ``ploughing_ratio``: the same for the frictionless run, the horizontal
  force that the block's bow wave (the tilt of the contact patch) gives
  without any friction;
- ``normal_tilt_deg``: the angle phi of the resultant normal contact force on
  the indenter from the vertical (positive: it pushes the indenter back, the
  ploughing resistance). The resultant is F_n = F_c - F_f, with F_c = -R the
  whole contact force and F_f = -int T tau dA the friction force;
- ``resultant_ratio`` = |F_f| / |F_n|: in 2D, with every node slipping the
  same way, the friction resultant is the normal resultant turned by 90
  degrees times mu, so this is mu and R_x / -R_y = tan(phi + atan(mu)):
  the whole offset of the reaction ratio from mu is the tilt phi;
- ``corrected_ratio`` = tan(atan(reaction_ratio) - phi): the reaction ratio
  with the tilt of the normal resultant rotated out;
- ``frame_ratio`` = F_t / N: tangential over normal contact force in the
  contact frame (mu wherever every contact node slips).

Writes results/bench/ironing_friction.{json,csv,md} and
docs/images/ironing_friction.png (with ``--picture``).

Run: ``python benchmarks/validation/ironing_friction.py [--coarse] [--out results/bench]
[--picture PATH]``.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from benchmarks.validation.ironing import order, setup
from fenics_contact.scene.schema import load_scene
from fenics_contact.solvers.stepping import solve_load_path

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "ironing_friction.toml"
#: Indenter radius (meshes/ironing.geo).
RADIUS = 0.5
#: Steady sliding: slide / R in this window (after the stick-to-slip transition,
#: before the indenter nears the block's far end).
STEADY = (0.6, 2.4)


def run(mu: float | None, coarse: bool, indenter_E: float | None = None) -> dict:
    """One ironing run; ``mu = None`` frictionless. Returns the per-step rows and totals."""
    scene = load_scene(SCENE)
    pair = dataclasses.replace(scene.pairs[0], mu=mu)
    scene = dataclasses.replace(scene, pairs=(pair,))
    if indenter_E is not None:  # same moduli: Dundurs beta = 0, no normal-tangential coupling
        bodies = tuple(dataclasses.replace(b, E=indenter_E) if b.name == "indenter" else b
                       for b in scene.bodies)
        scene = dataclasses.replace(scene, bodies=bodies)
    if coarse:
        scene = dataclasses.replace(scene, mesh=dataclasses.replace(
            scene.mesh, parameters={"h_indenter": 0.08, "h_block": 0.12}))
    problem, top, knots, strategy = setup(scene)
    rows: list[dict] = []
    # the tangential force vector acts on the striker: the friction force on the
    # indenter is its opposite when the indenter strikes, itself when the block does
    on_indenter = -1.0 if pair.striker == "striker_arc" else 1.0

    def on_step(step) -> None:
        force = problem.reaction(top)
        state = problem.contact_state()
        friction = (on_indenter * problem.tangential_force_vector()
                    if hasattr(problem, "lam_t") else np.zeros(2))
        normal = -force - friction
        rows.append({
            "step": step.step, "load_factor": step.load_factor,
            "slide_over_R": float(np.interp(step.load_factor, knots[:, 0], knots[:, 1])) / RADIUS,
            "reaction_x": float(force[0]), "reaction_y": float(force[1]),
            "reaction_ratio": float(force[0] / -force[1]),
            "normal_force": step.contact_force,
            "frame_tangential_force": float(getattr(state, "tangential_magnitude", 0.0)),
            "normal_tilt_deg": float(np.degrees(np.arctan2(-normal[0], normal[1]))),
            "resultant_ratio": float(np.linalg.norm(friction) / np.linalg.norm(normal)),
            "stick": step.stick_count, "slip": step.slip_count, "active": step.active_count,
            "iterations": step.iterations, "order": order(step.residuals[-1]),
            "max_penetration": step.max_penetration, "residuals": step.residuals[-1],
        })

    path = solve_load_path(strategy, scene.solver.steps, max_cutbacks=0, on_step=on_step)
    return {"mu": mu, "status": path.status, "rows": rows,
            "iterations": int(sum(r["iterations"] for r in rows))}


def interval(pair: tuple[float, float], digits: int) -> str:
    """'lo ... hi' with the given decimals."""
    return f"{pair[0]:.{digits}f} ... {pair[1]:.{digits}f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--coarse", action="store_true", help="h_indenter 0.08, h_block 0.12")
    parser.add_argument("--out", type=Path, default=harness.OUT)
    parser.add_argument("--picture", type=Path, default=None)
    parser.add_argument("--indenter-E", type=float, default=None,
                        help="the indenter's Young's modulus (default the scene's, 1000; "
                        "100 makes the bodies alike: Dundurs beta = 0)")
    args = parser.parse_args()
    friction = run(0.3, args.coarse, args.indenter_E)
    plain = run(None, args.coarse, args.indenter_E)
    mu = 0.3
    for row, ref in zip(friction["rows"], plain["rows"], strict=False):
        row["ploughing_ratio"] = ref["reaction_ratio"]
        row["iterations_frictionless"] = ref["iterations"]
        row["ploughing_tilt_deg"] = ref["normal_tilt_deg"]
        row["order_frictionless"] = ref["order"]
        row["corrected_ratio"] = math.tan(
            math.atan(row["reaction_ratio"]) - math.radians(row["normal_tilt_deg"]))
        row["frame_ratio"] = row["frame_tangential_force"] / row["normal_force"]
    rows = friction["rows"]
    steady = [r for r in rows if STEADY[0] <= r["slide_over_R"] <= STEADY[1]
              and "ploughing_ratio" in r]

    def span(key: str) -> tuple[float, float]:
        values = [r[key] for r in steady]
        return (min(values), max(values)) if values else (math.nan, math.nan)

    pairs = [0.5 * (a["reaction_ratio"] + b["reaction_ratio"])
             for a, b in zip(steady[::2], steady[1::2], strict=False)]
    press = [r for r in rows if r["slide_over_R"] == 0.0]
    slide = [r for r in rows if r["slide_over_R"] > 0.0]
    tails = [r["order"] for r in slide if not math.isnan(r["order"])]
    tails0 = [r["order"] for r in plain["rows"][len(press):] if not math.isnan(r["order"])]
    summary = {
        "mu": mu, "coarse": args.coarse, "indenter_E": args.indenter_E,
        "status": friction["status"],
        "status_frictionless": plain["status"],
        "steady_window_slide_over_R": STEADY, "steady_steps": len(steady),
        "reaction_ratio": span("reaction_ratio"), "ploughing_ratio": span("ploughing_ratio"),
        "corrected_ratio": span("corrected_ratio"), "frame_ratio": span("frame_ratio"),
        "resultant_ratio": span("resultant_ratio"), "normal_tilt_deg": span("normal_tilt_deg"),
        "ploughing_tilt_deg": span("ploughing_tilt_deg"),
        "mean_reaction_ratio": float(np.mean([r["reaction_ratio"] for r in steady])),
        "mean_ploughing_ratio": float(np.mean([r["ploughing_ratio"] for r in steady])),
        "mean_normal_tilt_deg": float(np.mean([r["normal_tilt_deg"] for r in steady])),
        "two_step_mean_reaction_ratio": (min(pairs), max(pairs)) if pairs else (math.nan,) * 2,
        "all_slip_in_window": all(r["stick"] == 0 for r in steady),
        "iterations": friction["iterations"], "iterations_frictionless": plain["iterations"],
        "max_step_iterations": max(r["iterations"] for r in rows),
        "max_step_iterations_frictionless": max(r["iterations"] for r in plain["rows"]),
        "max_ratio_per_step": max(
            r["iterations"] / max(r.get("iterations_frictionless", 1), 1) for r in rows),
        "press_iterations": [r["iterations"] for r in press],
        "median_order_sliding": float(np.median(tails)) if tails else math.nan,
        "min_order_sliding": float(np.min(tails)) if tails else math.nan,
        "median_order_sliding_frictionless": float(np.median(tails0)) if tails0 else math.nan,
        "max_penetration_over_R": max(r["max_penetration"] for r in rows) / RADIUS,
    }
    if MPI.COMM_WORLD.rank != 0:
        return
    table = harness.md_table(
        ["quantity", "value"],
        [["status (friction / frictionless)", f"{summary['status']} / {plain['status']}"],
         ["steps in the steady window", summary["steady_steps"]],
         ["reaction ratio R_x/-R_y (min, max)", interval(summary["reaction_ratio"], 4)],
         ["frictionless (ploughing) ratio", interval(summary["ploughing_ratio"], 4)],
         ["mean reaction ratio in the window", summary["mean_reaction_ratio"]],
         ["mean of two consecutive steps (min, max)",
          interval(summary["two_step_mean_reaction_ratio"], 4)],
         ["mean frictionless ratio in the window", summary["mean_ploughing_ratio"]],
         ["tilt of the normal resultant, deg (min, max; mean)",
          f"{interval(summary['normal_tilt_deg'], 3)}; {summary['mean_normal_tilt_deg']:.3f}"],
         ["frictionless tilt, deg (min, max)", interval(summary["ploughing_tilt_deg"], 3)],
         ["friction / normal resultant |F_f| / |F_n|", interval(summary["resultant_ratio"], 8)],
         ["reaction ratio with the tilt rotated out", interval(summary["corrected_ratio"], 8)],
         ["frame ratio int|tau| / N", interval(summary["frame_ratio"], 6)],
         ["every contact node slips in the window", summary["all_slip_in_window"]],
         ["Newton iterations (friction / frictionless)",
          f"{summary['iterations']} / {summary['iterations_frictionless']}"],
         ["max per step (friction / frictionless)",
          f"{summary['max_step_iterations']} / {summary['max_step_iterations_frictionless']}"],
         ["max per-step ratio friction / frictionless", summary["max_ratio_per_step"]],
         ["order of the last iterations while sliding (median, min)",
          f"{summary['median_order_sliding']:.2f}, {summary['min_order_sliding']:.2f}"],
         ["same, frictionless (median)", summary["median_order_sliding_frictionless"]],
         ["max penetration / R", summary["max_penetration_over_R"]]],
    )
    text = f"# Ironing with friction (mu = {mu}, GNRM)\n\n{table}\n"
    name = ("ironing_friction" + ("_coarse" if args.coarse else "")
            + (f"_E{args.indenter_E:g}" if args.indenter_E is not None else ""))
    harness.write(name, {"machine": harness.machine(), "summary": summary,
                         "friction": friction, "frictionless": plain}, text, args.out)
    with open(args.out / f"{name}.csv", "w", newline="") as handle:
        keys = [k for k in rows[0] if k != "residuals"]
        writer = csv.DictWriter(handle, fieldnames=keys, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)
    print(text)
    if args.picture is not None:
        picture(rows, mu, args.picture)


def picture(rows: list[dict], mu: float, path: Path) -> None:
    """Force ratios against the slide, with the band mu +- 2 %."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in rows if r["slide_over_R"] > 0 and "ploughing_ratio" in r]
    s = [r["slide_over_R"] for r in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.axhspan(0.98 * mu, 1.02 * mu, color="#dddddd", label="mu +- 2 %")
    ax.plot(s, [r["reaction_ratio"] for r in rows], "o-", ms=3, label="R_x / -R_y (friction)")
    ax.plot(s, [r["ploughing_ratio"] for r in rows], "s-", ms=3,
            label="R_x / -R_y frictionless (ploughing)")
    ax.plot(s, [r["corrected_ratio"] for r in rows], "^-", ms=3,
            label="tilt of the normal resultant rotated out")
    ax.plot(s, [r["frame_ratio"] for r in rows], "k--", lw=1, label="int |tau| / N (contact frame)")
    ax.axvspan(*STEADY, color="#1f77b4", alpha=0.06, label="steady window")
    ax.set_xlabel("slide / R")
    ax.set_ylabel("force ratio")
    ax.set_title(f"Ironing with Coulomb friction, mu = {mu}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
