"""Cattaneo-Mindlin with a mortar pair on non-matching arcs: stick half-width and traction.

scenes/cattaneo_mindlin_node_to_segment.toml with ``discretisation = "mortar"`` and
``target_ratio`` (1.37: non-matching arcs), h at contact and the number
of steps as given (a third of them pressing); prints per shift step
Q/(mu P), the relative error of the stick half-width c against
a sqrt(1 - Q/(mu P)), the node spacing at the stick edge (relative) and
the relative L2 error of the nodal tangential traction against
q(x) = mu p0 [sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)].

Writes OUT/cattaneo_mortar.json (one record per shift step) and .md.

Run: ``python benchmarks/validation/cattaneo_mortar.py [--h 0.002] [--ratio 1.37] [--steps 12]
[--out results/bench]``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (before dolfinx)
from benchmarks import harness
from benchmarks.validation.cattaneo import solve_cattaneo_mindlin
from fenics_contact.scene.schema import load_scene

SCENE = (Path(__file__).resolve().parents[2] / "scenes"
         / "cattaneo_mindlin_node_to_segment.toml")


def mortar_scene(directory: Path, h: float, ratio: float, steps: int) -> Path:
    """The shipped scene with a mortar pair, h at contact, target_ratio and steps."""
    text = SCENE.read_text().replace("../meshes", str(SCENE.parents[1] / "meshes"))
    for old, new in (("h_contact = 0.003", f"h_contact = {h!r}"),
                     ("target_ratio = 1.0", f"target_ratio = {ratio!r}"),
                     ("steps = 12", f"steps = {steps}"),
                     ("[0.25, 0.0, -0.03]", f"[{1 / 3!r}, 0.0, -0.03]"),
                     ('discretisation = "node-to-segment"', 'discretisation = "mortar"')):
        if old not in text:
            raise RuntimeError(f"{SCENE.name} changed: {old!r} not found")
        text = text.replace(old, new)
    path = directory / f"cattaneo_mortar_{h:g}_{ratio:g}.toml"
    path.write_text(text)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h", type=float, default=0.002)
    parser.add_argument("--ratio", type=float, default=1.37)
    parser.add_argument("--steps", type=int, default=12)
    parser.add_argument("--out", type=Path, default=harness.OUT)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        run = solve_cattaneo_mindlin(load_scene(mortar_scene(Path(tmp), args.h, args.ratio,
                                                             args.steps)))
    wall = time.perf_counter() - start
    iterations = [s.iterations for s in run.record.steps]
    records = [{**z.to_dict(), "load_factor": t, "c_over_a": z.c_measured / z.a,
                "c_over_a_analytic": z.c_analytic / z.a}
               for t, z in zip(run.load_factors, run.zones, strict=True)]
    table = harness.md_table(
        ["Q/(mu P)", "c/a", "c/a analytic", "c error", "spacing", "traction L2", "stick", "slip"],
        [[r["load_ratio"], r["c_over_a"], r["c_over_a_analytic"], r["c_error"],
          r["c_resolution"], r["traction_error"], r["stick_nodes"], r["slip_nodes"]]
         for r in records])
    harness.write("cattaneo_mortar", {
        "machine": harness.machine(), "h_contact": args.h, "target_ratio": args.ratio,
        "steps": args.steps, "iterations": iterations, "wall_s": wall, "records": records,
    }, table, args.out)
    print("Newton iterations per step:", [s.iterations for s in run.record.steps])
    print("Q/(mu P)  c error  spacing  traction L2  stick  slip")
    for z in run.zones:
        print(f"{z.load_ratio:8.3f}  {z.c_error:+7.4f}  {z.c_resolution:7.4f}  "
              f"{z.traction_error:11.4f}  {z.stick_nodes:5d}  {z.slip_nodes:4d}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
