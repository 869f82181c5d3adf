"""A thin tube crushed between two plates until its inner wall closes: two meshes, picture.

Runs scenes/tube_crush.toml (half model, self-contact of the inner wall)
on its own mesh and on a mesh twice as fine through and along the wall,
compares the plate force against the plate's travel before the inner wall
touches (the load factors where neither run has self-contact) and after,
and reports the self-contact penetration and the balance of the plates.
Writes results/bench/tube_crush.json and docs/images/tube_crush.png
(crushed sections coloured by contact pressure, force-travel curves).

Run: ``python benchmarks/validation/tube_crush.py [--refine 2] [--n-t 4 --n-q 54]
[--method auto] [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from squeeze_frames import draw, squeeze

from benchmarks import harness
from fenics_contact.scene.schema import load_scene

WALL = 0.1


def curve(frames) -> dict:
    """Travel of the top plate, plate forces, self-contact force, active nodes, penetration."""
    return {
        "t": [f.t for f in frames],
        "top": [f.forces["top"] for f in frames],
        "bottom": [f.forces["bottom"] for f in frames],
        "inner": [f.forces["inner"] for f in frames],
        "inner_active": [int(np.sum(f.contacts["inner"][1] < 0)) for f in frames],
        "inner_penetration": [f.penetration["inner"] for f in frames],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=Path("scenes/tube_crush.toml"))
    parser.add_argument("--refine", type=int, default=2)
    parser.add_argument("--n-t", type=int, help="layers through the wall (default: the scene's)")
    parser.add_argument("--n-q", type=int, help="divisions along a quarter (default: the scene's)")
    parser.add_argument("--method", help="solution strategy (default: the scene's; 'auto' "
                        "closes the 24-layer tube where GNRM cycles)")
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    parser.add_argument("--image", type=Path, default=Path("docs/images/tube_crush.png"))
    args = parser.parse_args()
    scene = load_scene(args.scene)
    if args.method is not None:
        scene = dataclasses.replace(scene, solver=dataclasses.replace(scene.solver,
                                                                      method=args.method))
    travel = -scene.obstacles[1].obstacle.motion[1]
    params = dict(scene.mesh.parameters)
    params.update({k: v for k, v in (("n_t", args.n_t), ("n_q", args.n_q)) if v is not None})
    fine = {k: args.refine * v for k, v in params.items()}
    runs = {}
    for label, p in (("coarse", params), ("fine", fine)):
        variant = dataclasses.replace(scene, mesh=dataclasses.replace(scene.mesh, parameters=p))
        _, path, frames = squeeze(variant)
        runs[label] = {"parameters": p, "converged": path.converged,
                       "iterations": [s.iterations for s in path.steps], **curve(frames)}
        if label == "coarse":
            shown = frames
    c, f = runs["coarse"], runs["fine"]
    # compare at the load factors both runs reached (a run may stop early)
    n = min(len(c["t"]), len(f["t"]))
    t = np.array(c["t"][:n])
    assert np.allclose(t, f["t"][:n]), "the two runs took different load steps"
    rel = np.abs(np.array(c["top"][:n]) - np.array(f["top"][:n])) / np.array(f["top"][:n])
    before = (np.array(c["inner_active"][:n]) == 0) & (np.array(f["inner_active"][:n]) == 0)
    record = {
        "machine": harness.machine(),
        **runs, "travel": travel,
        "before_touch_max_difference": float(rel[before].max()),
        "after_touch_max_difference": float(rel[~before].max()) if np.any(~before) else None,
        "max_penetration_over_wall": max(max(r["inner_penetration"]) for r in runs.values()) / WALL,
        "plate_balance": max(abs(a - b) / a for r in runs.values()
                             for a, b in zip(r["top"], r["bottom"], strict=True)),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "tube_crush.json").write_text(json.dumps(record, indent=1))
    print(f"coarse {params}, fine {fine}; converged: {c['converged']}, {f['converged']} "
          f"({len(c['t'])} and {len(f['t'])} steps)")
    print(f"plate force, before the inner wall touches: max difference {rel[before].max():.2%}")
    if np.any(~before):
        print(f"after: {rel[~before].max():.2%} (load factors {t[~before].round(3).tolist()})")
    print(f"self-contact penetration / wall: {record['max_penetration_over_wall']:.2e}; "
          f"plate balance {record['plate_balance']:.1e}")
    touched = [i for i, fr in enumerate(shown) if np.any(fr.contacts["inner"][1] < 0)]
    first = touched[0] if touched else len(shown) - 1
    picks = [len(shown) // 2, max(first - 1, 0), len(shown) - 1]
    draw([shown[i] for i in picks], args.image, mirror=True,
         title="Tube crushed between two plates: plates and self-contact of the inner wall",
         labels=[f"travel {travel * shown[i].t:.3f}" for i in picks],
         curve=(travel * t, [(np.array(c["top"][:n]), "FE coarse"),
                             (np.array(f["top"][:n]), "FE fine")],
                "plate travel", "plate force"), log=True)
    print(f"wrote {args.image} and {args.out / 'tube_crush.json'}")


if __name__ == "__main__":
    main()
