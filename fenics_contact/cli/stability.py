"""``fenics-contact stability``: every method on a grid of extreme cases."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from fenics_contact.cli.study import methods


def _stability(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from fenics_contact.output.io import write_csv, write_json
    from fenics_contact.studies.stability import ERROR, full_grid, run_grid, select
    from fenics_contact.studies.sweep_plots import stability_plot

    out: Path = args.out
    rank0 = MPI.COMM_WORLD.rank == 0
    cases = select(full_grid(), args.cases)
    records = []

    def keep(rec) -> None:
        records.append(rec)
        write_csv(out / "stability.csv", [r.row() for r in records])  # survives a crash
        if rank0:
            print(
                f"  {rec.case:20s} {rec.method:8s} {rec.status:15s} it {rec.iterations:5d} "
                f"steps {rec.steps_completed}/{rec.load_steps}  {rec.wall_s:6.2f} s"
                + ("" if rec.ft_ratio is None else f"  Ft/muN {rec.ft_ratio:.6f}")
                + ("" if rec.reference_reached is None
                   else "  reference " + ("reached" if rec.reference_reached else "missed"))
                + (f"  {rec.message}" if rec.message else ""),
                flush=True,
            )

    if rank0:
        print(f"Stability: {len(cases)} cases x {len(args.methods)} methods", flush=True)
    run_grid(
        cases, args.methods, out=out, progress=keep, max_iterations=args.max_iterations,
        max_cutbacks=args.max_cutbacks, force_rtol=args.force_rtol,
    )
    write_json(out / "stability.json", [r.to_dict() for r in records])
    if rank0:
        stability_plot(records, out / "stability.png")
        print(f"\nWrote {out}/stability.csv, stability.json, stability.png and cases/*.json")
    crashed = [r for r in records if r.status == ERROR]
    if crashed:
        if rank0:
            print(
                f"fenics-contact: {len(crashed)} run(s) ended with an error (a crash, not a "
                f"solver status), first: {crashed[0].case} {crashed[0].method}: "
                f"{crashed[0].message}", file=sys.stderr,
            )
        return 1
    return 0


def _names(text: str) -> list[str]:
    return [s.strip() for s in text.split(",") if s.strip()]


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stability`` subcommand."""
    from fenics_contact.model.scaling import DEFAULT_FORCE_RTOL
    from fenics_contact.studies.stability import METHODS

    cmd = sub.add_parser(
        "stability",
        help="run every method on extreme cases and record each status",
        description="Run methods on extreme cases (r 1e-8 ... 1e12 E/h, E 1e-3 ... 1e12, "
        "nu up to 0.4999, 1/10/100 load steps, initial penetration, grazing, no and full "
        "contact, coarse and fine meshes, two deformable bodies, Coulomb friction mu 0 ... 10, "
        "r extremes and a load reversal with friction, on a rigid plane and between two "
        "blocks); record each run's status, iterations, forces, F_t/(mu N) and whether it "
        "reached the reference answer (GNRM at r = 1 E/h); write stability.csv, "
        "stability.json, stability.png and per-run step records under cases/. Exit code 0, "
        "or 1 when a run ended with an error (an exception, not a solver status).",
    )
    cmd.add_argument("--cases", type=_names, default=None,
                     help="comma-separated case names or groups (r, E, nu, steps, start, mesh, "
                     "two-body-r, two-body-stiffness, two-body-sliding, friction, friction-r, "
                     "two-body-friction, two-body-friction-r); default: all")
    cmd.add_argument("--methods", type=methods, default=list(METHODS),
                     help="comma-separated strategies (default penalty,sua,nua,gnrm,auto)")
    cmd.add_argument("--max-iterations", type=int, default=100,
                     help="Newton iteration cap per load step (default 100)")
    cmd.add_argument("--max-cutbacks", type=int, default=0,
                     help="step halvings allowed after a failed step (default 0)")
    cmd.add_argument("--force-rtol", type=float, default=DEFAULT_FORCE_RTOL,
                     help="tolerance relative to the force scale E h^(d-1) (default 1e-10)")
    cmd.add_argument("--out", type=Path, default=Path("results/stability"), help="output folder")
    cmd.set_defaults(func=_stability)
