"""O-ring cross-section squeezed between two plates: force against Lindley, contact width.

Runs scenes/o_ring.toml (half model, neo-Hookean, nu = 0.49, d = 2, E = 6,
squeezed to 30 % in 10 steps) and compares the force per unit length of
the whole ring, F/L = 2 x a plate's force, with Lindley's empirical
F/L = E d (1.25 c^1.5 + 50 c^6) at every compression c, and with the
exact small-strain answer of plane-strain elasticity (a disc under two
Hertz loads, :func:`~fenics_contact.references.hertz.diametral_approach`),
which holds while the contact is narrow (c of a few per cent). Reports the
contact width (deformed, full ring) against each plate. Writes
results/bench/o_ring.json and docs/images/o_ring.png (deformed sections at
10, 20 and 30 % coloured by contact pressure, and the force curve).

Run: ``python benchmarks/validation/o_ring.py [--scene scenes/o_ring.toml] [--out results/bench]``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from squeeze_frames import draw, squeeze

from benchmarks import harness
from fenics_contact.references.hertz import load_for_diametral_approach
from fenics_contact.scene.schema import load_scene

E, NU, D, SQUEEZE = 6.0, 0.49, 2.0, 0.3


def lindley(c: np.ndarray | float) -> np.ndarray:
    """Lindley's empirical force per unit length of an O-ring, E d (1.25 c^1.5 + 50 c^6)."""
    c = np.asarray(c, float)
    return E * D * (1.25 * c**1.5 + 50.0 * c**6)


def elastic(c: np.ndarray | float) -> np.ndarray:
    """Small-strain plane-strain F/L of a disc squeezed by c d between rigid plates."""
    return np.array([load_for_diametral_approach(ci * D, D / 2.0, E, NU) if ci > 0 else 0.0
                     for ci in np.atleast_1d(np.asarray(c, float))])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=Path("scenes/o_ring.toml"))
    parser.add_argument("--out", type=Path, default=Path("results/bench"))
    parser.add_argument("--image", type=Path, default=Path("docs/images/o_ring.png"))
    args = parser.parse_args()
    _, path, frames = squeeze(load_scene(args.scene))
    c = np.array([SQUEEZE * f.t for f in frames])
    force = np.array([2.0 * f.forces["top"] for f in frames])
    width = []
    for f in frames:
        x, p = f.contacts["top"]
        width.append(2.0 * float(np.max(x[p < 0, 0], initial=0.0)))
    record = {
        "machine": harness.machine(),
        "converged": path.converged, "iterations": [s.iterations for s in path.steps],
        "compression": c.tolist(), "force_per_length": force.tolist(),
        "lindley": lindley(c).tolist(), "ratio": (force / lindley(c)).tolist(),
        "elastic": elastic(c).tolist(), "elastic_ratio": (force / elastic(c)).tolist(),
        "contact_width": width,
        "balance": [abs(f.forces["top"] - f.forces["bottom"]) / f.forces["top"] for f in frames],
        "max_penetration": max(max(f.penetration.values()) for f in frames),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "o_ring.json").write_text(json.dumps(record, indent=1))
    for ci, fi, li, ei, wi in zip(c, force, lindley(c), elastic(c), width, strict=True):
        print(f"c = {ci:.2f}: F/L = {fi:.4f}, Lindley {li:.4f} ({fi / li - 1:+.1%}), "
              f"small-strain elasticity {ei:.4f} ({fi / ei - 1:+.1%}), "
              f"contact width {wi:.4f} ({wi / D:.3f} d)")
    n = len(frames)
    shown = [frames[i] for i in (n // 3 - 1, 2 * n // 3 - 1, n - 1)]
    fine = np.linspace(0.0, SQUEEZE, 61)
    draw(shown, args.image, mirror=True,
         title="O-ring (neo-Hookean, nu = 0.49) between two rigid plates",
         labels=[f"c = {SQUEEZE * f.t:.0%}" for f in shown],
         curve=(fine, [(lindley(fine), "Lindley"), (elastic(fine), "small-strain elasticity"),
                       (np.interp(fine, np.r_[0, c], np.r_[0, force]), "FE (plane strain)")],
          "compression c", "F/L"))
    print(f"wrote {args.image} and {args.out / 'o_ring.json'}")


if __name__ == "__main__":
    main()
