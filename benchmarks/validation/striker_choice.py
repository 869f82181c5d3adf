"""Which surface of a mortar pair strikes: a hemisphere on a softer block, both ways, two meshes.

``scenes/sphere_on_block_3d.toml`` (quarter model, R = 1, E = 200 on
E = 100, nu = 0.3, pushed 0.016, GNRM, 4 steps) on two mesh pairs near the
contact: the hemisphere coarser than the block (0.016 / 0.012, shipped) and
finer (0.012 / 0.016); on each, the hemisphere's cap strikes (shipped) or the
block's top. Hertz for two dissimilar bodies at the computed load P (4 x the
top support's reaction): R_eff = R, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2,
a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2). Per run: Newton
iterations, the largest nodal pressure against p0, the nodal scatter (the
standard deviation of (p - p_Hertz) / p0 over the striker nodes with
r < a - 2 h, h the coarser size) and the relative L2 error there.

The 2D counterpart (two cylinders with the coarser target striking) is
``mortar_hertz.py --swap``. Writes ``<out>/striker_choice.json`` and ``.md``.

Run: ``python benchmarks/validation/striker_choice.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.harness import md_table, write
from fenics_contact import build_problem, load_scene, scene_strategy, solve_load_path

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "sphere_on_block_3d.toml"
#: (hemisphere, block) facet sizes near the contact.
MESHES = ((0.016, 0.012), (0.012, 0.016))
R, E1, NU1, E2, NU2 = 1.0, 200.0, 0.3, 100.0, 0.3


def hertz(P: float) -> tuple[float, float]:
    """(a, p0) of two dissimilar elastic bodies, R_eff = R, under the total load P."""
    e_star = 1.0 / ((1 - NU1**2) / E1 + (1 - NU2**2) / E2)
    a = (3 * P * R / (4 * e_star)) ** (1 / 3)
    return a, 3 * P / (2 * np.pi * a**2)


def solve(sizes: tuple[float, float], striker: str) -> dict:
    """One run of the scene on ``sizes`` with ``striker`` ("sphere" or "block") striking."""
    scene = load_scene(SCENE)
    mesh = dataclasses.replace(scene.mesh, parameters={
        **scene.mesh.parameters, "h_sphere": sizes[0], "h_block": sizes[1]})
    pair = scene.pairs[0]
    if striker == "block":
        pair = dataclasses.replace(pair, striker=pair.target, target=pair.striker)
    scene = dataclasses.replace(scene, mesh=mesh, pairs=(pair,))
    problem = build_problem(scene)
    path = solve_load_path(scene_strategy(scene, problem), scene.solver.steps)
    P = 4.0 * abs(problem.support_reactions()["top"][2])
    a, p0 = hertz(P)
    comm = problem.comm
    xyz = np.concatenate(comm.allgather(problem.nodal_coordinates()))
    p = -np.concatenate(comm.allgather(problem.contact_state().pressure))
    r = np.hypot(xyz[:, 0], xyz[:, 1])
    exact = p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0.0, None))
    inside = r < a - 2 * max(sizes)
    error = (p - exact)[inside] / p0
    return {
        "h_sphere": sizes[0], "h_block": sizes[1], "striker": striker,
        "striker_finer": (sizes[0] < sizes[1]) == (striker == "sphere"),
        "status": path.status, "iterations": path.iterations, "load": P,
        "a_hertz": a, "p0_hertz": p0, "nodes_inside": int(inside.sum()),
        "peak_error": float(p.max() / p0 - 1.0),
        "scatter": float(np.std(error)),
        "l2_inside": float(np.sqrt(np.sum((p - exact)[inside] ** 2) / np.sum(exact[inside] ** 2))),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    args = parser.parse_args()
    runs = [solve(sizes, striker) for sizes in MESHES for striker in ("sphere", "block")]
    for run in runs:
        run["striker"] = f"{run['striker']} ({'finer' if run['striker_finer'] else 'coarser'})"
    rows = [[f"{r['h_sphere']} / {r['h_block']}", r["striker"], r["iterations"],
             f"{r['load']:.5f}", f"{r['peak_error']:+.2%}", f"{r['scatter']:.2%}",
             f"{r['l2_inside']:.2%}", r["nodes_inside"]] for r in runs]
    table = md_table(("h hemisphere / block", "striker", "Newton", "P", "largest p vs p0",
                      "scatter std (p - p_Hertz)/p0", "L2, r < a - 2h", "nodes"), rows)
    write("striker_choice", {"scene": str(SCENE.relative_to(ROOT)), "runs": runs}, table,
          args.out)
    print(table)


if __name__ == "__main__":
    main()
