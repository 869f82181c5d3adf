"""The ``fenics-contact`` command: one module a subcommand, each with ``register``."""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence

import fenics_contact  # noqa: F401  (imports the DOLFINx wheel first)
from fenics_contact.cli import compile, mesh, render, run, stability, study, tradeoff

#: Subcommand modules, in the order ``--help`` lists them.
SUBCOMMANDS = (run, render, study, mesh, tradeoff, stability, compile)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="fenics-contact",
        description="Finite-deformation contact of hyperelastic bodies with the "
        "Alart-Curnier augmented Lagrangian (FEniCSx).",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module in SUBCOMMANDS:
        module.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``fenics-contact`` command; returns the exit code."""
    args = build_parser().parse_args(argv)
    warnings.showwarning = _one_line_warning
    try:
        return int(args.func(args))
    except (ValueError, FileNotFoundError, RuntimeError) as exc:
        if _collective(exc):  # raised alike on every process: said once
            if _rank() == 0:
                print(f"fenics-contact: error: {exc}", file=sys.stderr)
        else:
            where = f"process {_rank()}: " if _size() > 1 else ""
            print(f"fenics-contact: error: {where}{exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C outside a run's clean stop (see fenics_contact.stop)
        print("fenics-contact: stopped by SIGINT", file=sys.stderr)
        return 130


def _rank() -> int:
    from mpi4py import MPI

    return MPI.COMM_WORLD.rank


def _size() -> int:
    from mpi4py import MPI

    return MPI.COMM_WORLD.size


def _collective(exc: BaseException) -> bool:
    """Scene and checkpoint errors are raised on every process together."""
    from fenics_contact.output.checkpoint import CheckpointError
    from fenics_contact.scene.spec import SceneError

    return isinstance(exc, SceneError | CheckpointError)


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Scene warnings as one line, ``fenics-contact: warning: ...`` (others as usual).

    Scene warnings are issued on every process alike and printed by the first.
    """
    from fenics_contact.scene.build import SceneWarning

    if issubclass(category, SceneWarning):
        if _rank() == 0:
            print(f"fenics-contact: warning: {message}", file=sys.stderr)
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


if __name__ == "__main__":
    sys.exit(main())
