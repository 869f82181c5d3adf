"""Two cylinders against Hertz with mortar and node-to-segment pairs, on three meshes.

Two identical linear-elastic half-disks (R = 1, E = 200, nu = 0.3,
non-matching meshes: the target's contact size is 1.37 h) pushed together by
0.02 in 6 steps (GNRM, r = 1 E/h), on h = 0.02, 0.01 and 0.005, with each
discretisation of the pair. For each run: the largest nodal pressure against
Hertz's p0 (two identical cylinders: R_eff = R/2, E* = E / (2 (1 - nu^2)),
at the computed force), the relative L2 error of the nodal pressures over
the whole zone (|x| < 1.5 a) and inside it (|x| < a - 2 h), and the Newton
iterations, beside the continuous L2 error of the exact profile's own P1
interpolant at that a/h (a guide to the resolution; least and largest over
where the nodes fall, :func:`~fenics_contact.references.hertz.interpolation_error`).
Writes ``<out>/mortar_hertz.json`` and ``.md`` and the picture of both
profiles on the shipped mesh, h = 0.005 (``--figure``). ``--swap``: the lower
(coarser) arc strikes, into ``mortar_hertz_swap.json`` and ``.md``.

Run: ``python benchmarks/validation/mortar_hertz.py [--out results/bench]
[--figure docs/images/mortar_hertz.png] [--swap]``.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np

from mpi4py import MPI

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.cases import two_cylinders
from benchmarks.harness import figure_parser, report, save_figure
from fenics_contact import build_problem, make_strategy, solve_load_path
from fenics_contact.references.hertz import hertz_line_contact, interpolation_error
from fenics_contact.solvers.diagnostics import SolverSettings

SIZES = (0.02, 0.01, 0.005)
#: h_contact of scenes/two_cylinders.toml.
SHIPPED = 0.005
DISCRETISATIONS = ("node-to-segment", "mortar")


def solve(h: float, discretisation: str, swap: bool = False) -> dict:
    """One run: the nodal profile, the force and the errors against Hertz.

    ``swap``: the lower cylinder's arc (the coarser, 1.37 h) strikes.
    """
    scene = two_cylinders(h, steps=6)
    pair = dataclasses.replace(scene.pairs[0], discretisation=discretisation)
    if swap:
        pair = dataclasses.replace(pair, striker=pair.target, target=pair.striker)
    problem = build_problem(dataclasses.replace(scene, pairs=(pair,)))
    strategy = make_strategy("gnrm", problem, SolverSettings(atol=1e-10, rtol=1e-12))
    path = solve_load_path(strategy, scene.solver.steps)
    state = problem.contact_state()
    comm = problem.comm
    x = np.concatenate(comm.allgather(problem.nodal_coordinates()[:, 0]))
    p = -np.concatenate(comm.allgather(state.pressure))
    order = np.argsort(x)
    x, p = x[order], p[order]
    hertz = hertz_line_contact(state.contact_force, 0.5, 100.0, 0.3)
    exact = hertz.pressure(x)

    def l2(where: np.ndarray) -> float:
        return float(np.sqrt(np.sum((p - exact)[where] ** 2) / np.sum(exact[where] ** 2)))

    return {
        "h": h, "discretisation": discretisation, "status": path.status,
        "iterations": path.iterations, "force": state.contact_force,
        "a_hertz": hertz.a, "p0_hertz": hertz.p0,
        "peak_error": float(p.max() / hertz.p0 - 1.0),
        "l2_whole": l2(np.abs(x) < 1.5 * hertz.a),
        "l2_inside": l2(np.abs(x) < hertz.a - 2 * h),
        "exact_interpolant": "{:.1%} ... {:.1%}".format(*interpolation_error(hertz.a / h)),
        "x": x.tolist(), "p": p.tolist(),
    }


def picture(runs: list[dict], h: float, path: Path) -> None:
    """Both discretisations' nodal pressures against Hertz at mesh size h."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    chosen = [r for r in runs if r["h"] == h]
    a, p0 = chosen[0]["a_hertz"], chosen[0]["p0_hertz"]
    xs = np.linspace(-1.3 * a, 1.3 * a, 400)
    ax.plot(xs / a, p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0, None)) / p0, "k-",
            label="Hertz, two cylinders")
    for run, marker in zip(chosen, ("s", "o"), strict=True):
        x, p = np.array(run["x"]), np.array(run["p"])
        ax.plot(x / a, p / p0, marker, ms=4, mfc="none" if marker == "s" else None,
                label=f"{run['discretisation']}: peak {run['peak_error']:+.2%}, "
                      f"L2 {run['l2_whole']:.1%} (inside {run['l2_inside']:.1%})")
    ax.set_xlim(-1.4, 1.4)
    ax.set_xlabel("x / a")
    ax.set_ylabel("p / p0 (Hertz)")
    ax.set_title(f"Two cylinders on non-matching meshes, h = {h:g} R")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)


def main() -> None:
    """Command line."""
    parser = figure_parser(__doc__, SIZES)
    parser.add_argument("--swap", action="store_true",
                        help="the coarser arc strikes (mortar_hertz_swap.json/.md)")
    args = parser.parse_args()
    sizes = args.sizes
    runs = [solve(h, d, args.swap) for h in sizes for d in DISCRETISATIONS]
    if MPI.COMM_WORLD.rank != 0:
        return
    name = "mortar_hertz_swap" if args.swap else "mortar_hertz"
    table = report(name, runs, ["h", "pair", "status", "Newton", "peak vs p0",
                                "L2 |x| < 1.5 a", "exact profile, P1", "L2 |x| < a - 2h"],
                   ["h", "discretisation", "status", "iterations", "peak_error", "l2_whole",
                    "exact_interpolant", "l2_inside"], args.out, drop=("x", "p"))
    print(table)
    if args.figure is not None:
        picture(runs, SHIPPED if SHIPPED in sizes else sizes[0], args.figure)


if __name__ == "__main__":
    main()
