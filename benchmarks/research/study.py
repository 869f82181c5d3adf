"""``fenics-contact study`` on the lab's named cases: the paper's Tables 1 and 2 beside ours.

Usage (from the repository root)::

    python benchmarks/research/study.py paper-ex1 [--beside paper-ex1-wedge]
        [--methods ...] [--r ...] [--out results/paper-ex1]
    python benchmarks/research/study.py paper-ex2 [--out results/paper-ex2-study]
    python benchmarks/research/study.py two-cylinders --relative --r 0.01,1,100

The cases: ``paper-ex1`` (the prescribed striker node on one element, the
one custom problem), ``paper-ex1-wedge`` (its rigid-wedge analog, a scene)
and ``paper-ex2`` (the bar on a cradle, ``scenes/paper_ex2.toml``), each
printed beside the paper's table, Example 1 with the penalty displacements;
``two-cylinders`` (h = 0.02, 3 steps) and ``block-on-block`` (the patch test
on 8 and 11 divisions). The options are those of ``fenics-contact study``.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import fenics_contact  # noqa: F401  (the DOLFINx wheel first)
from benchmarks.cases import bar_on_cradle, block_on_block, two_cylinders, wedge_on_corner
from benchmarks.research.paper import PAPER_TABLE_1, PAPER_TABLE_2
from benchmarks.research.paper_ex1 import StrikerOnFacet, corner_displacement, exact_corner
from fenics_contact.cli.study import add_study_options, study_and_write
from fenics_contact.sweeps.study import Subject


def subjects() -> dict[str, Subject]:
    """The named cases, the paper's with their published tables and probes."""
    striker, h = StrikerOnFacet(), -0.25
    return {
        "paper-ex1": Subject("paper-ex1", striker, corner_displacement,
                             exact_corner(striker.exact_u), PAPER_TABLE_1),
        "paper-ex1-wedge": Subject("paper-ex1-wedge", wedge_on_corner(h=h), corner_displacement,
                                   exact_corner(2.0 * h), PAPER_TABLE_1),
        "paper-ex2": Subject("paper-ex2", bar_on_cradle(), published=PAPER_TABLE_2),
        "two-cylinders": Subject("two-cylinders", two_cylinders()),
        "block-on-block": Subject("block-on-block", block_on_block()),
    }


def main(argv: Sequence[str] | None = None) -> int:
    """Command line."""
    known = subjects()
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("example", choices=sorted(known))
    parser.add_argument("--beside", action="append", default=[], choices=sorted(known))
    add_study_options(parser, Path("results/study"))
    args = parser.parse_args(argv)
    return study_and_write([known[args.example], *(known[b] for b in args.beside)], args)


if __name__ == "__main__":
    sys.exit(main())
