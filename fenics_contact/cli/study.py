"""``fenics-contact study``: method x r sweeps on a scene, in the paper's table layout."""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping, Sequence
from pathlib import Path


def floats(text: str) -> list[float]:
    """Parse a comma-separated list of positive numbers (argparse type)."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a comma-separated list of numbers such as 1,10,100, got {text!r}"
        ) from None
    if not values or any(not v > 0 for v in values):
        raise argparse.ArgumentTypeError(f"every r must be > 0, got {text!r}")
    return values


def methods(text: str) -> list[str]:
    """Parse a comma-separated list of strategy names (argparse type)."""
    from fenics_contact.solvers import STRATEGIES

    names = [m.strip().lower() for m in text.split(",") if m.strip()]
    unknown = [m for m in names if m not in STRATEGIES]
    if unknown or not names:
        raise argparse.ArgumentTypeError(
            f"unknown method(s) {unknown or text!r}; choose from {','.join(STRATEGIES)}"
        )
    return names


def study_and_write(subjects: Sequence, args: argparse.Namespace) -> int:
    """Run methods x r on the first subject (and on the others beside it); write the outputs.

    ``subjects``: :class:`~fenics_contact.sweeps.study.Subject` values, the
    first the one studied. Writes study.json, study.csv, table.md and the
    residual and iteration pictures into ``args.out``.
    """
    from mpi4py import MPI

    from fenics_contact.output.io import write_csv, write_json
    from fenics_contact.output.plotting import iterations_against_r, residual_histories
    from fenics_contact.solvers.diagnostics import SolverSettings
    from fenics_contact.solvers.stepping import name_tolerance
    from fenics_contact.sweeps.study import comparison_table, paper_table, probe_line, run_study

    root = MPI.COMM_WORLD.rank == 0  # every process runs the study; one speaks and writes

    def say(*text, **kwargs) -> None:
        if root:
            print(*text, **kwargs)

    first = subjects[0]
    out: Path = args.out
    settings = SolverSettings(atol=args.tol, max_iterations=args.max_iterations)

    def show(rec) -> None:
        name_tolerance(rec, "study's --tol")
        say(
            f"  {rec.method:8s} r = {rec.r:<10g} {rec.status:15s} iterations {rec.iterations:4d}"
            f"  updates {rec.updates:4d}  {rec.wall_s:6.2f} s",
            flush=True,
        )

    def study(subject) -> list:
        return run_study(
            subject.case, args.methods, args.r, relative=args.relative, settings=settings,
            quadrature=args.quadrature, progress=show, probe=subject.probe,
            exact=subject.exact,
        )

    say(f"Study {first.label}: methods {','.join(args.methods)}; r = {args.r}", flush=True)
    records = study(first)
    table = paper_table(records, limit=args.max_iterations, relative=args.relative)
    say()
    say(table)
    sources: list = [(first.label, records)]
    if first.published is not None:
        sources.append(("paper", first.published))
    for other in subjects[1:]:
        say(f"\nStudy {other.label} (beside {first.label})", flush=True)
        sources.append((other.label, study(other)))
    if len(sources) > 1:
        table = comparison_table(sources, args.r, args.methods, limit=args.max_iterations,
                                 relative=args.relative)
        say(f"\n{first.label} beside {', '.join(label for label, _ in sources[1:])}:\n")
        say(table)
        say()
    for label, source in sources:
        if not isinstance(source, Mapping) and "penalty" in args.methods:
            if any(math.isfinite(rec.probe) for rec in source):
                say(f"Penalty probe ({label}): {probe_line(source)}")
    if root:
        write_json(out / "study.json", [r.to_dict() for r in records])
        write_csv(out / "study.csv", [r.row() for r in records])
        (out / "table.md").write_text(table + "\n")
        residual_histories(records, out / "residuals.png")
        iterations_against_r(records, out / "iterations.png")
    say(f"\nWrote {out}/study.json, study.csv, table.md, residuals.png, iterations.png")
    return 0


def _study(args: argparse.Namespace) -> int:
    from fenics_contact.scene.schema import load_scene
    from fenics_contact.sweeps.study import Subject

    subjects = [Subject(path.stem, load_scene(path)) for path in [args.scene, *args.beside]]
    return study_and_write(subjects, args)


def add_study_options(cmd: argparse.ArgumentParser, default_out: Path) -> None:
    """Methods, r values and stopping rules of a study (the paper's by default)."""
    cmd.add_argument(
        "--methods", type=methods, default=["penalty", "sua", "nua", "gnrm"],
        help="comma-separated strategies: penalty, sua, nua, gnrm, auto (default: the "
             "paper's four, penalty,sua,nua,gnrm)",
    )
    cmd.add_argument(
        "--r", type=floats, default=[1.0, 10.0, 100.0, 1000.0, 10000.0],
        help="comma-separated r values, e.g. 1e6,1e8 (default 1,10,100,1000,10000)",
    )
    cmd.add_argument(
        "--relative", action="store_true",
        help="read r relative to E/h (h: mean contact facet size) instead of absolute",
    )
    cmd.add_argument(
        "--quadrature", choices=["nodal", "gauss"], default=None,
        help="contact integration: nodal (vertex rule, node-on-facet) or gauss "
        "(default: each contact's own)",
    )
    cmd.add_argument("--tol", type=float, default=1e-8,
                     help="absolute residual tolerance (force; default 1e-8; no rtol)")
    cmd.add_argument(
        "--max-iterations", type=int, default=500,
        help="Newton iteration limit per load step (500, as in the paper)",
    )
    cmd.add_argument("--out", type=Path, default=default_out, help="output folder")


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``study`` subcommand."""
    study = sub.add_parser(
        "study",
        help="compare solution strategies over r on a scene",
        description="Run methods x r on a scene (from zero, no cut-back, one tolerance for "
        "all, as in the paper) and write study.json, study.csv, table.md and PNG plots "
        "(residual histories, iterations against r). The paper's Tables 1 and 2 beside "
        "the published ones: benchmarks/research/paper_tables.py (make paper-tables)."
        " Each load step starts from the last converged state (predictor \"previous\", "
        "whatever the scene says), so that every method starts alike, and each Newton "
        "step takes its contact set by the sign rule, as the paper's GNRM; the stopping "
        "test is --tol alone (no relative tolerance): iteration counts match `run` with "
        "predictor = \"previous\", contact_set = \"sign\", atol = --tol and rtol = 0 "
        "(a scene's default rtol = 1e-10 stops some steps earlier), where no step needs a "
        "cut-back (a study allows none).",
    )
    study.add_argument("scene", type=Path, help="the scene file (.toml)")
    study.add_argument(
        "--beside", type=Path, action="append", default=[], metavar="SCENE",
        help="also run SCENE with the same settings and print its rows beside (repeatable)",
    )
    add_study_options(study, Path("results/study"))
    study.set_defaults(func=_study)
