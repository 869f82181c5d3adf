"""Two cylinders against Hertz: pressure profile picture and accuracy record.

Runs scenes/two_cylinders_node_to_segment.toml (two identical linear-elastic half-disks,
R = 1, E = 200, nu = 0.3, non-matching meshes, GNRM, 10 steps) and compares
the final nodal pressures with Hertz for two identical cylinders
(1/R_eff = 2/R, 1/E* = 2 (1 - nu^2)/E) at the computed force. Also solves
with r = 1e-2 and 1e2 (relative) to show the answer does not depend on r.
Writes results/bench/two_cylinders.json and two_cylinders_hertz.png.

Run: ``python benchmarks/validation/two_cylinders.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from fenics_contact.references.hertz import fit_contact_profile, hertz_line_contact
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene


def solve(scene, out: Path) -> dict:
    outcome = run_scene(scene, out, pictures=False)
    problem = outcome.problem
    state = problem.contact_state()
    comm = problem.comm
    x = np.concatenate(comm.allgather(problem.nodal_coordinates()[:, 0]))
    p = np.concatenate(comm.allgather(state.pressure))
    return {"x": x, "p": p, "force": state.contact_force,
            "iterations": [s.iterations for s in outcome.path.steps],
            "max_penetration": state.max_penetration, "r_relative": problem.r_relative}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path,
                        default=Path("scenes/two_cylinders_node_to_segment.toml"))
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    args = parser.parse_args()
    scene = load_scene(args.scene)
    runs = {}
    for r in (1e-2, 1.0, 1e2):
        pair = dataclasses.replace(scene.pairs[0], r=r)
        runs[r] = solve(dataclasses.replace(scene, pairs=(pair,)), args.out / f"two_cyl_r{r:g}")
    base = runs[1.0]
    # two identical cylinders: R_eff = R/2, E* = E / (2 (1 - nu^2))
    hertz = hertz_line_contact(base["force"], 0.5, 100.0, 0.3)
    fit = fit_contact_profile(base["x"], base["p"])
    order = np.argsort(base["x"])
    record = {
        "machine": harness.machine(),
        "force": base["force"], "iterations": base["iterations"],
        "max_penetration": base["max_penetration"],
        "a_hertz": hertz.a, "a_fit": fit.a, "a_error": fit.a / hertz.a - 1,
        "p0_hertz": hertz.p0, "p0_fit": fit.p0, "p0_error": fit.p0 / hertz.p0 - 1,
        "p0_nodal": fit.nodal_peak, "p0_nodal_error": fit.nodal_peak / hertz.p0 - 1,
        "r_independence": {
            f"{r:g}": {"iterations": run["iterations"],
                       "force_rel_diff": abs(run["force"] - base["force"]) / base["force"],
                       "pressure_max_abs_diff": float(np.max(np.abs(run["p"] - base["p"])))}
            for r, run in runs.items()
        },
        "profile": {"x": base["x"][order].tolist(), "p": base["p"][order].tolist()},
    }
    if MPI.COMM_WORLD.rank == 0:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "two_cylinders.json").write_text(json.dumps(record, indent=2))
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        xs = np.linspace(-1.3 * hertz.a, 1.3 * hertz.a, 400)
        ax.plot(xs, hertz.pressure(xs), "k-", label="Hertz, two cylinders")
        ax.plot(base["x"][order], -base["p"][order], "o", ms=4, label="nodes (striker side)")
        ax.set_xlim(-1.5 * hertz.a, 1.5 * hertz.a)
        ax.set_xlabel("x")
        ax.set_ylabel("contact pressure")
        ax.set_title(f"Two cylinders: a {record['a_error']:+.2%}, p0 {record['p0_error']:+.2%}")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.out / "two_cylinders_hertz.png", dpi=120)
        print(json.dumps(record, indent=2))


if __name__ == "__main__":
    main()
