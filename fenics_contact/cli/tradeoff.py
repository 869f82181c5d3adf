"""``fenics-contact tradeoff``: speed against accuracy over methods x r x meshes."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from fenics_contact.cli.study import floats, methods


def _tradeoff(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from fenics_contact.output.io import write_csv, write_json
    from fenics_contact.studies.sweep_plots import tradeoff_plot
    from fenics_contact.studies.tradeoff import markdown_table, run_tradeoff

    out: Path = args.out
    rank0 = MPI.COMM_WORLD.rank == 0

    done = []

    def show(rec) -> None:
        done.append(rec)
        write_csv(out / "tradeoff.csv", [r.row() for r in done])  # survives a crash
        if rank0:
            last = (f"p0 err {rec.p0_error:.1e}" if math.isnan(rec.mu) else
                    f"Ft err {rec.ft_error:.1e}  stick slip {rec.stick_slip:.1e}")
            print(
                f"  {rec.case:11s} {rec.mesh:9s} {rec.method:8s} r = {rec.r_relative:<8g} "
                f"{rec.status:15s} it {rec.iterations:5d}  {rec.wall_s:7.3f} s  "
                f"u err {rec.u_error:.1e}  {last}",
                flush=True,
            )

    records = run_tradeoff(
        args.scene, args.methods, args.r, meshes=args.meshes, mu=args.mu, progress=show,
        repeats=args.repeats, max_iterations=args.max_iterations,
    )
    table = markdown_table(records)
    if rank0:
        print()
        print(table)
    write_json(out / "tradeoff.json", [r.row() for r in records])
    write_csv(out / "tradeoff.csv", [r.row() for r in records])
    if rank0:
        (out / "table.md").write_text(table + "\n")
        tradeoff_plot(records, out / "tradeoff.png")
        print(f"\nWrote {out}/tradeoff.json, tradeoff.csv, table.md, tradeoff.png")
    return 0


def _scenes(text: str) -> list[str]:
    """Scene names, with the groups 'frictionless', 'friction' and 'all' expanded."""
    from fenics_contact.studies.tradeoff import FRICTION_SCENES, FRICTIONLESS_SCENES

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
            f"{','.join(groups)}"
        )
    return list(dict.fromkeys(names))


def _coefficients(text: str) -> list[float]:
    """Comma-separated Coulomb coefficients, each finite and > 0."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or not all(0 < v < float("inf") for v in values):
        raise argparse.ArgumentTypeError(
            f"--mu takes comma-separated friction coefficients > 0 such as 0.1,0.3,1, got {text!r}"
        )
    return values


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``tradeoff`` subcommand."""
    from fenics_contact.studies.tradeoff import FRICTION_MU, FULL_R, METHODS

    cmd = sub.add_parser(
        "tradeoff",
        help="measure wall time against accuracy over methods x r x meshes",
        description="Sweep methods x r (relative to E/h) x meshes on the Hertz cylinder and "
        "the Example 2 bar, and with Coulomb friction on the sliding block (scene 'slide', "
        "one case per mu); write tradeoff.json, tradeoff.csv, table.md and tradeoff.png "
        "(error against time, Pareto front marked).",
    )
    cmd.add_argument("--scene", type=_scenes, default=["hertz", "bar"],
                     help="comma-separated scenes hertz,bar,slide or groups frictionless "
                     "(hertz,bar), friction (slide), all (default frictionless)")
    cmd.add_argument("--mu", type=_coefficients, default=list(FRICTION_MU),
                     help="Coulomb coefficients of the friction cases (default "
                     f"{','.join(f'{m:g}' for m in FRICTION_MU)})")
    cmd.add_argument("--methods", type=methods, default=list(METHODS),
                     help="comma-separated strategies (default penalty,sua,nua,gnrm,auto)")
    cmd.add_argument("--r", type=floats, default=list(FULL_R),
                     help="comma-separated r relative to E/h (default 1e-4 ... 1e8)")
    cmd.add_argument("--meshes", type=int, choices=[1, 2, 3], default=3,
                     help="how many meshes, coarse first (default 3)")
    cmd.add_argument("--repeats", type=int, default=3,
                     help="timed repeats of a converged run; the median is kept (default 3)")
    cmd.add_argument("--max-iterations", type=int, default=200,
                     help="Newton iteration cap per load step (default 200)")
    cmd.add_argument("--out", type=Path, default=Path("results/tradeoff"), help="output folder")
    cmd.set_defaults(func=_tradeoff)
