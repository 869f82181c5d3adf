"""The project's grid of extreme cases, run by ``fenics_contact.sweeps.stability``.

Usage (from the repository root)::

    python benchmarks/robustness/stability_grid.py [--cases E,bar-r1e12] [--methods gnrm,auto]
        [--out results/stability]

Each case is a scene of :mod:`benchmarks.cases` with one knob at an
extreme: r from 1e-8 to 1e12 E/h (bar and Hertz cylinder), E from 1e-3 to
1e12 (displacement loading: forces scale with E), nu up to 0.4999, 1/10/100
load steps, an initial penetration, a grazing start, no contact, full
contact, a very coarse and a fine mesh; two deformable bodies (r, stiffness
ratio, large sliding), node-to-segment and mortar (``mortar-r``, ``mortar-stiffness``,
``mortar-sliding``); the sliding block with Coulomb friction (``friction``:
mu from 0 to 10 and a load reversal; ``friction-r``: r from 1e-8 to 1e12 E/h
with the default cap r_t = min(r, 2 E/L) and with r_t = r); the sliding
blocks pair with friction (``two-body-friction``, ``two-body-friction-r``);
several contacts among several bodies and self-contact (``many-contacts``).
The results and the picture go where ``--out`` says
(``docs/tradeoff_and_stability.md`` shows them).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.cases import (
    REVERSAL,
    REVERSAL_PAIR,
    bar_on_cradle,
    block_on_plane,
    hertz_cylinder,
    ironing,
    junction_blocks,
    sliding_block,
    sliding_blocks,
    stack_automatic,
    tube_crush,
    two_cylinders,
)
from fenics_contact.sweeps.stability import StabilityCase


def full_grid() -> list[StabilityCase]:
    """Every case of the stability study."""
    cases = [
        StabilityCase(f"{name}-r1e{e}", "r", scene, 10.0**e)
        for name, scene in (("bar", bar_on_cradle()), ("hertz", hertz_cylinder(0.01)))
        for e in range(-8, 13, 2)
    ]
    cases += [StabilityCase(f"bar-E1e{e}", "E", bar_on_cradle(E=10.0**e))
              for e in (-3, 0, 3, 6, 9, 12)]
    cases += [StabilityCase(f"bar-nu{nu:g}", "nu", bar_on_cradle(nu=nu))
              for nu in (0.0, 0.3, 0.49, 0.4999)]
    cases += [StabilityCase(f"bar-steps{n}", "steps", bar_on_cradle(steps=n))
              for n in (1, 10, 100)]
    cases += [
        StabilityCase("bar-penetrating", "start", bar_on_cradle(end_gap=-0.02)),
        StabilityCase("bar-grazing", "start", bar_on_cradle(end_gap=0.0)),
        StabilityCase("hertz-grazing", "start", hertz_cylinder(0.01)),
        StabilityCase("bar-no-contact", "start", bar_on_cradle(end_gap=1.0)),
        StabilityCase("block-full-contact", "start", block_on_plane()),
        StabilityCase("bar-coarse-3x1", "mesh", bar_on_cradle(3, 1)),
        StabilityCase("bar-fine-48x16", "mesh", bar_on_cradle(48, 16, law="neo-hookean")),
        StabilityCase("bar-fine-48x16-svk", "mesh", bar_on_cradle(48, 16)),
    ]
    # Two deformable bodies: r, stiffness ratio, grazing start (the cylinders
    # touch at one point at t = 0) and large sliding.
    cases += [StabilityCase(f"two-cyl-r1e{e}", "two-body-r", two_cylinders(), 10.0**e)
              for e in range(-8, 13, 4)]
    cases += [
        StabilityCase(f"two-cyl-stiffness1e{e}", "two-body-stiffness",
                      two_cylinders(stiffness_ratio=10.0**e))
        for e in (-3, 0, 3)
    ]
    cases += [StabilityCase("ironing-short", "two-body-sliding", ironing())]
    return (cases + mortar_grid() + friction_grid() + pair_friction_grid()
            + many_contacts_grid())


def mortar_grid() -> list[StabilityCase]:
    """The two-body cases on mortar pairs: r, stiffness ratio, large sliding.

    The same two cylinders (non-matching arcs, touching at one point at
    t = 0: a grazing start) and the short ironing with the block striking,
    as in scenes/ironing.toml.
    """
    cases = [StabilityCase(f"mortar-cyl-r1e{e}", "mortar-r",
                           two_cylinders(discretisation="mortar"), 10.0**e)
             for e in range(-8, 13, 4)]
    cases += [StabilityCase(f"mortar-cyl-stiffness1e{e}", "mortar-stiffness",
                            two_cylinders(stiffness_ratio=10.0**e, discretisation="mortar"))
              for e in (-3, 3)]
    cases += [StabilityCase("mortar-ironing-short", "mortar-sliding",
                            ironing(discretisation="mortar", block_strikes=True))]
    return cases


def many_contacts_grid() -> list[StabilityCase]:
    """Several contacts among several bodies (pairs found by [pairing] automatic = true).

    A body touching two others (the middle block of a stack; a block on two
    blocks side by side, one node on both), a contact opening while another
    closes (that block sliding off the left block onto the right one; once
    off, the left block is held down by nothing, so a variant holds its
    outer wall vertically), and
    self-contact (the tube crushed until its inner wall closes).
    """
    return [
        StabilityCase("stack-automatic", "many-contacts", stack_automatic()),
        StabilityCase("junction", "many-contacts", junction_blocks()),
        StabilityCase("junction-slide-off", "many-contacts", junction_blocks(0.6, 10)),
        StabilityCase("junction-slide-off-held", "many-contacts",
                      junction_blocks(0.6, 10, held=True)),
        StabilityCase("junction-r1e8", "many-contacts", junction_blocks(), 1e8),
        StabilityCase("tube-self-contact", "many-contacts", tube_crush()),
    ]


def friction_grid() -> list[StabilityCase]:
    """The sliding block with Coulomb friction: mu 0 ... 10, r extremes, a load reversal."""
    cases = [StabilityCase(f"slide-mu{mu:g}", "friction", sliding_block(mu), 1.0)
             for mu in (0.0, 0.1, 0.3, 1.0, 10.0)]
    cases += [StabilityCase(f"slide-r1e{e}", "friction-r", sliding_block(), 10.0**e)
              for e in range(-8, 13, 4)]
    cases += [
        StabilityCase(f"slide-rt=r-r1e{e}", "friction-r", sliding_block(tangential_r_max=None),
                      10.0**e)
        for e in (0, 4)
    ]
    cases += [StabilityCase("slide-reversal", "friction", sliding_block(schedule=REVERSAL), 1.0)]
    return cases


def pair_friction_grid() -> list[StabilityCase]:
    """The sliding blocks pair with friction: mu 0 ... 10, r extremes, a load reversal."""
    cases = [StabilityCase(f"blocks-mu{mu:g}", "two-body-friction", sliding_blocks(mu), 1.0)
             for mu in (0.0, 0.3, 1.0, 10.0)]
    cases += [StabilityCase(f"blocks-r1e{e}", "two-body-friction-r", sliding_blocks(), 10.0**e)
              for e in range(-8, 13, 4)]
    cases += [StabilityCase("blocks-reversal", "two-body-friction",
                            sliding_blocks(path=REVERSAL_PAIR), 1.0)]
    return cases


if __name__ == "__main__":
    from fenics_contact.cli.stability import run_cases

    sys.exit(run_cases(full_grid(), sys.argv[1:], default_out=Path("results/stability")))
