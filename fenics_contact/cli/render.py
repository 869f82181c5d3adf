"""``fenics-contact render``: draw any step and field of a finished run (off-screen PNG)."""

from __future__ import annotations

import argparse
from pathlib import Path


def _render(args: argparse.Namespace) -> int:
    from fenics_contact.output.render import render_step

    path = render_step(args.out, step=args.step, field=args.field, path=args.png)
    print(f"Wrote {path}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``render`` subcommand."""
    render = sub.add_parser(
        "render",
        help="draw a field of a finished load step as a PNG",
        description="Draw one field of one finished load step of a run on the deformed mesh "
        "(true scale), from the run's files alone: no ParaView needed.",
    )
    render.add_argument("out", type=Path, help="the run's output folder (its --out)")
    render.add_argument("--step", type=int, default=None,
                        help="load step, 1-based (default: the last finished one)")
    render.add_argument("--field", default=None,
                        help="a field of the step file, e.g. displacement, gap, von_mises, "
                        "stick_slip (default: contact_pressure, or displacement where the "
                        "run wrote no pressure)")
    render.add_argument("--png", type=Path, default=None,
                        help="the picture to write (default OUT/render_step_NNNN_FIELD.png)")
    render.set_defaults(func=_render)
