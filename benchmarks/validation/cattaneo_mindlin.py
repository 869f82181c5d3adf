"""Cattaneo-Mindlin with two identical cylinders: stick half-width and traction profile.

Runs scenes/cattaneo_mindlin_node_to_segment.toml (two linear-elastic half-cylinders, R = 1,
E = 200, nu = 0.3: Dundurs beta = 0; pressed by 0.03, then the upper face
shifted by 0.014, mu = 0.3, GNRM) on three meshes: the shipped one (h =
0.003, matching arcs), the same with non-matching arcs (target_ratio 1.37)
and the coarse one of the test (h = 0.006). Per case a frictionless
pressing check against Hertz; per shift step Q/(mu P), the measured and
analytic stick half-width c, the node spacing at the stick edge, and the
relative L2 error of the nodal tangential traction against
q(x) = mu p0 [sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)].
See :mod:`fenics_contact.references.cattaneo`.

Writes <out>/cattaneo_mindlin.json, .csv, .md and the picture
(--figure, default docs/images/cattaneo_mindlin.png): the shipped mesh at
Q/(mu P) = 0.5 and 0.78.

Run: ``python benchmarks/validation/cattaneo_mindlin.py [--out results/bench]`` (about 1-2 min).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from benchmarks.validation.cattaneo import pressing_check, solve_cattaneo_mindlin
from benchmarks.validation.cattaneo_plot import traction_picture
from fenics_contact.scene.schema import MeshSpec, load_scene

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "cattaneo_mindlin_node_to_segment.toml"
#: (label, mesh parameters replacing the scene's)
CASES = [
    ("shipped: h 0.003, matching arcs", {}),
    ("h 0.003, non-matching arcs (1.37)", {"target_ratio": 1.37}),
    ("h 0.006, matching arcs", {"h_contact": 0.006}),
]


def _scene(parameters: dict):
    scene = load_scene(SCENE)
    mesh: MeshSpec = scene.mesh
    merged = {**mesh.parameters, **parameters}
    return dataclasses.replace(scene, mesh=dataclasses.replace(mesh, parameters=merged))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=harness.OUT)
    parser.add_argument("--figure", type=Path, default=ROOT / "docs/images/cattaneo_mindlin.png")
    args = parser.parse_args()
    records, rows, press_rows = [], [], []
    for label, parameters in CASES:
        scene = _scene(parameters)
        P, fit, hertz = pressing_check(scene)
        press_rows.append([label, fit.n_contact, P, fit.a / hertz.a - 1, fit.p0 / hertz.p0 - 1])
        start = time.perf_counter()
        run = solve_cattaneo_mindlin(scene)
        wall = time.perf_counter() - start
        iterations = [s.iterations for s in run.record.steps]
        print(label, f"{wall:.1f} s", iterations, flush=True)
        for t, zone, reaction in zip(run.load_factors, run.zones, run.reactions, strict=True):
            records.append({"case": label, "mesh": scene.mesh.parameters, "load_factor": t,
                            **zone.to_dict(), "reaction": list(reaction),
                            "c_over_a": zone.c_measured / zone.a,
                            "c_over_a_analytic": zone.c_analytic / zone.a,
                            "iterations": iterations, "wall_s": wall})
            rows.append([label, zone.load_ratio, zone.c_measured / zone.a,
                         zone.c_analytic / zone.a, zone.c_error, zone.c_resolution,
                         zone.traction_error])
        if not parameters:
            mu = scene.pairs[0].mu
            picks = [min(range(len(run.zones)), key=lambda k: abs(run.zones[k].load_ratio - r))
                     for r in (0.5, 0.8)]
            traction_picture(
                [(run.profiles[k], run.zones[k]) for k in picks], mu, args.figure,
                title="Two identical cylinders (beta = 0), h = 0.003: nodal traction "
                "against Cattaneo-Mindlin",
            )
    header = ["mesh", "Q/(mu P)", "c/a measured", "c/a analytic", "c error",
              "half node spacing / c", "traction L2 error"]
    press_header = ["mesh", "nodes in contact", "P", "a - Hertz", "p0 - Hertz"]
    table = (harness.md_table(press_header, press_rows) + "\n\n"
             + harness.md_table(header, rows))
    harness.write("cattaneo_mindlin", {"machine": harness.machine(), "records": records,
                                       "pressing": [dict(zip(press_header, r, strict=True))
                                                    for r in press_rows]},
                  table, args.out)
    with (args.out / "cattaneo_mindlin.csv").open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(header)
        writer.writerows(rows)
    print(table)


if __name__ == "__main__":
    main()
