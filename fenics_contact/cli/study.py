"""``fenics-contact study``: method x r sweeps on a built-in example."""

from __future__ import annotations

import argparse
import math
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


def _study(args: argparse.Namespace) -> int:
    from fenics_contact.output.io import write_csv, write_json
    from fenics_contact.output.plotting import iterations_against_r, residual_histories
    from fenics_contact.solvers.diagnostics import SolverSettings
    from fenics_contact.studies.study import comparison_table, paper_table, probe_line, run_study
    from fenics_contact.verification.examples import EXAMPLES

    example = EXAMPLES[args.example]()
    out: Path = args.out
    settings = SolverSettings(atol=args.tol, max_iterations=args.max_iterations)

    def show(rec) -> None:
        print(
            f"  {rec.method:8s} r = {rec.r:<10g} {rec.status:15s} iterations {rec.iterations:4d}"
            f"  updates {rec.updates:4d}  {rec.wall_s:6.2f} s",
            flush=True,
        )

    print(f"Study {args.example}: methods {','.join(args.methods)}; r = {args.r}", flush=True)
    records = run_study(
        example, args.methods, args.r, relative=args.relative, settings=settings,
        quadrature=args.quadrature, progress=show,
    )
    table = paper_table(records, limit=args.max_iterations)
    print()
    print(table)
    sources: list = [(args.example, records)]
    published = getattr(example, "published_table", None)
    if published is not None:
        sources.append(("paper", published))
    for other in args.beside:
        print(f"\nStudy {other} (beside {args.example})", flush=True)
        sources.append((other, run_study(
            EXAMPLES[other](), args.methods, args.r, relative=args.relative,
            settings=settings, quadrature=args.quadrature, progress=show,
        )))
    if len(sources) > 1:
        table = comparison_table(sources, args.r, args.methods, limit=args.max_iterations)
        print(f"\n{args.example} beside {', '.join(label for label, _ in sources[1:])}:\n")
        print(table)
        print()
    for label, source in sources:
        if not isinstance(source, dict) and "penalty" in args.methods:
            if any(math.isfinite(rec.probe) for rec in source):
                print(f"Penalty probe ({label}): {probe_line(source)}")
    write_json(out / "study.json", [r.to_dict() for r in records])
    write_csv(out / "study.csv", [r.row() for r in records])
    (out / "table.md").write_text(table + "\n")
    residual_histories(records, out / "residuals.png")
    iterations_against_r(records, out / "iterations.png")
    print(f"\nWrote {out}/study.json, study.csv, table.md, residuals.png, iterations.png")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``study`` subcommand."""
    from fenics_contact.verification.examples import EXAMPLES

    study = sub.add_parser(
        "study",
        help="compare solution strategies over r on a built-in example",
        description="Run methods x r on an example and write study.json, study.csv, "
        "table.md and PNG plots (residual histories, iterations against r).",
    )
    study.add_argument("example", choices=sorted(EXAMPLES), help="which example to solve")
    study.add_argument(
        "--methods", type=methods, default=["penalty", "sua", "nua", "gnrm"],
        help="comma-separated strategies: penalty,sua,nua,gnrm (default: all four)",
    )
    study.add_argument(
        "--r", type=floats, default=[1.0, 10.0, 100.0, 1000.0, 10000.0],
        help="comma-separated r values, e.g. 1e6,1e8 (default 1,10,100,1000,10000)",
    )
    study.add_argument(
        "--relative", action="store_true",
        help="read r relative to E/h (h: mean contact facet size) instead of absolute",
    )
    study.add_argument(
        "--quadrature", choices=["nodal", "gauss"], default="nodal",
        help="contact integration: nodal (vertex rule, node-on-facet) or gauss",
    )
    study.add_argument(
        "--beside", type=str, action="append", default=[], choices=sorted(EXAMPLES),
        metavar="EXAMPLE",
        help="also run EXAMPLE with the same settings and print its rows beside "
        "(repeatable; e.g. --beside paper-ex1-wedge)",
    )
    study.add_argument("--tol", type=float, default=1e-8, help="residual tolerance (1e-8)")
    study.add_argument(
        "--max-iterations", type=int, default=500,
        help="Newton iteration limit per load step (500, as in the paper)",
    )
    study.add_argument("--out", type=Path, default=Path("results/study"), help="output folder")
    study.set_defaults(func=_study)
