"""The project's speed-accuracy trade: Hertz, the Example 2 bar and the sliding block.

Usage (from the repository root)::

    python benchmarks/research/tradeoff.py [--scene hertz,bar,slide | frictionless | friction
        | all] [--mu 0.1,0.3] [--meshes 3] [--methods ...] [--r ...] [--repeats 3]
        [--out results/tradeoff]

Each scene on up to three meshes, coarse first (Hertz h = 0.02, 0.01,
0.005 with its peak-pressure error against Hertz; the bar 6 x 2, 12 x 4,
18 x 6; the sliding block 10 x 5, 20 x 10, 40 x 20 at each mu), through
``fenics-contact tradeoff``'s machinery. ``docs/tradeoff_and_stability.md``
holds the measured tables and the picture.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.cases import bar_on_cradle, hertz_cylinder, sliding_block
from fenics_contact.cli.tradeoff import add_tradeoff_options, tradeoff_and_write
from fenics_contact.references.measure import measure_hertz
from fenics_contact.sweeps.tradeoff import TradeoffCase

FRICTIONLESS_SCENES = ("hertz", "bar")
FRICTION_SCENES = ("slide",)
#: Coulomb coefficient of the friction cases by default (each mu costs a full grid).
FRICTION_MU = (0.3,)


def hertz_peak_error(E: float = 200.0, nu: float = 0.3, radius: float = 1.0):
    """The Hertz peak-pressure error of a solved half-cylinder (NaN if not measurable)."""
    def error(problem) -> float:
        try:
            return float(measure_hertz(problem, radius, E, nu).p0_error)
        except ValueError:
            return math.nan
    return error


def scene_meshes(name: str, count: int = 3, mu: Sequence[float] = FRICTION_MU
                 ) -> list[TradeoffCase]:
    """The scene ``name`` on ``count`` meshes, coarse to fine ('slide': each mesh x mu)."""
    if name == "hertz":
        return [TradeoffCase("hertz", f"h={h:g}", hertz_cylinder(h), hertz_peak_error())
                for h in (0.02, 0.01, 0.005)[:count]]
    if name == "bar":
        # SVK: from 24 x 8 on, the strain under the punch corners reaches the law's
        # compressive instability and no method converges (see docs).
        return [TradeoffCase("bar", f"{6 * k}x{2 * k}", bar_on_cradle(6 * k, 2 * k))
                for k in (1, 2, 3)[:count]]
    if name == "slide":
        return [TradeoffCase("slide", f"{10 * k}x{5 * k}", sliding_block(m, nx=10 * k, ny=5 * k))
                for m in mu for k in (1, 2, 4)[:count]]
    raise ValueError(f"Unknown trade-off scene {name!r}; use one of "
                     f"{', '.join(FRICTIONLESS_SCENES + FRICTION_SCENES)}.")


def _scenes(text: str) -> list[str]:
    """Scene names, with the groups 'frictionless', 'friction' and 'all' expanded."""
    groups = {"frictionless": FRICTIONLESS_SCENES, "friction": FRICTION_SCENES,
              "all": FRICTIONLESS_SCENES + FRICTION_SCENES}
    known = FRICTIONLESS_SCENES + FRICTION_SCENES
    names: list[str] = []
    for name in (s.strip().lower() for s in text.split(",") if s.strip()):
        names += groups.get(name, (name,))
    bad = [s for s in names if s not in known]
    if bad or not names:
        raise argparse.ArgumentTypeError(
            f"unknown scene(s) {bad or text!r}; use {','.join(known)} or a group: "
            f"{','.join(groups)}")
    return list(dict.fromkeys(names))


def _coefficients(text: str) -> list[float]:
    """Comma-separated Coulomb coefficients, each finite and > 0."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or not all(0 < v < float("inf") for v in values):
        raise argparse.ArgumentTypeError(
            f"--mu takes comma-separated friction coefficients > 0 such as 0.1,0.3,1, got {text!r}")
    return values


def main(argv: Sequence[str] | None = None) -> int:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scene", type=_scenes, default=list(FRICTIONLESS_SCENES),
                        help="hertz,bar,slide or a group: frictionless, friction, all")
    parser.add_argument("--mu", type=_coefficients, default=list(FRICTION_MU),
                        help="Coulomb coefficients of the friction cases (default 0.3)")
    parser.add_argument("--meshes", type=int, choices=[1, 2, 3], default=3,
                        help="how many meshes, coarse first (default 3)")
    add_tradeoff_options(parser, Path("results/tradeoff"))
    args = parser.parse_args(argv)
    cases = [c for name in args.scene for c in scene_meshes(name, args.meshes, args.mu)]
    return tradeoff_and_write(cases, args)


if __name__ == "__main__":
    sys.exit(main())
