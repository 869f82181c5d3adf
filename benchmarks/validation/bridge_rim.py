"""A bridge across two supports: which underside strikes, node-to-segment and mortar, 4 meshes.

``scenes/bridge.toml`` (plane strain, a bridge E = 100 on two supports
E = 200, pushed 0.02 in the middle, GNRM, 2 steps) on four meshes (the
shipped h_support = 0.1, h_bridge = 0.05, then halved three times). Each pair
strikes with the bridge's whole underside half (the shipped scene: it runs
past the support's rim over the gap) or with the part over the support only
(``whole_underside = 0``), as node-to-segment and as mortar. Per run the
load the bridge carries (the top support's reaction) and the Newton count.

As the supports spread under the load their top corners slide out under
the bridge, beyond x = 1 and x = 2: a striker tagged over the supports only
misses them, and the load comes out low by about 4 % (mortar) on every mesh.
Node-to-segment opens striker nodes past the rim by more than a quarter of
their facet size; those closer stand in for the corner below them.

Run: ``python benchmarks/validation/bridge_rim.py [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.harness import machine, md_table, write
from fenics_contact import build_problem, load_scene, scene_strategy, solve_load_path

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "bridge.toml"
#: Mesh refinement factors of the shipped sizes.
REFINEMENTS = (1, 2, 4, 8)


def solve(refinement: int, whole: bool, discretisation: str) -> dict:
    """One run of the bridge scene."""
    scene = load_scene(SCENE)
    mesh = dataclasses.replace(scene.mesh, parameters={
        **scene.mesh.parameters, "h_support": 0.1 / refinement,
        "h_bridge": 0.05 / refinement, "whole_underside": int(whole)})
    pairs = tuple(dataclasses.replace(p, discretisation=discretisation) for p in scene.pairs)
    scene = dataclasses.replace(scene, mesh=mesh, pairs=pairs)
    problem = build_problem(scene)
    path = solve_load_path(scene_strategy(scene, problem), scene.solver.steps)
    return {"refinement": refinement, "h_bridge": 0.05 / refinement,
            "striker": "whole underside" if whole else "over the supports",
            "discretisation": discretisation, "status": path.status,
            "iterations": path.iterations,
            "load": -problem.support_reactions()["bridge_top"][1]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    args = parser.parse_args()
    runs = [solve(k, whole, d) for k in REFINEMENTS for whole in (True, False)
            for d in ("node-to-segment", "mortar")]
    rows = [[r["h_bridge"], r["striker"], r["discretisation"], r["iterations"],
             f"{r['load']:.6f}", r["status"]] for r in runs]
    table = md_table(("h bridge", "striker", "pair", "Newton", "load", "status"), rows)
    write("bridge_rim", {"machine": machine(), "scene": str(SCENE.relative_to(ROOT)),
                         "runs": runs}, table, args.out)
    print(table)


if __name__ == "__main__":
    main()
