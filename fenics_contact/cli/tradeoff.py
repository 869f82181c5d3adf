"""``fenics-contact tradeoff``: speed against accuracy over methods x r on scenes (meshes)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from pathlib import Path

from fenics_contact.cli.progress import progress_to_csv
from fenics_contact.cli.stability import add_contact_set_option
from fenics_contact.cli.study import floats, methods


def tradeoff_and_write(cases: Sequence, args: argparse.Namespace) -> int:
    """Run the trade-off on ``cases`` (:class:`TradeoffCase`); write JSON, CSV, table, picture."""
    from mpi4py import MPI

    from fenics_contact.output.io import write_csv, write_json
    from fenics_contact.sweeps.sweep_plots import tradeoff_plot
    from fenics_contact.sweeps.tradeoff import markdown_table, run_tradeoff

    out: Path = args.out
    rank0 = MPI.COMM_WORLD.rank == 0

    def line(rec) -> str:
        if not math.isnan(rec.mu):
            last = f"Ft err {rec.ft_error:.1e}  stick slip {rec.stick_slip:.1e}"
        else:  # a peak error only where a Hertz reference is known (not for any scene)
            last = f"p0 err {rec.p0_error:.1e}" if math.isfinite(rec.p0_error) else ""
        return (f"  {rec.case:11s} {rec.mesh:9s} {rec.method:8s} r = {rec.r_relative:<8g} "
                f"{rec.status:15s} it {rec.iterations:5d}  {rec.wall_s:7.3f} s  "
                f"u err {rec.u_error:.1e}  {last}")

    _, show = progress_to_csv(
        out / "tradeoff.csv", line,
        "tradeoff's own tolerance, max(1e-10 E h^(d-1), the round-off floor at r), written "
        "as atol; not the scene's")
    records = run_tradeoff(
        cases, args.methods, args.r, progress=show, repeats=args.repeats,
        max_iterations=args.max_iterations, contact_set=args.contact_set,
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


def add_tradeoff_options(cmd: argparse.ArgumentParser, default_out: Path) -> None:
    """Methods, r values, repeats, iteration cap and output folder of a trade-off."""
    from fenics_contact.sweeps.tradeoff import FULL_R, METHODS

    cmd.add_argument("--methods", type=methods, default=list(METHODS),
                     help="comma-separated strategies (default penalty,sua,nua,gnrm,auto)")
    cmd.add_argument("--r", type=floats, default=list(FULL_R),
                     help="comma-separated r relative to E/h (default 1e-4 ... 1e8)")
    cmd.add_argument("--repeats", type=int, default=3,
                     help="timed repeats of a converged run; the median is kept (default 3)")
    cmd.add_argument("--max-iterations", type=int, default=200,
                     help="Newton iteration cap per load step (default 200)")
    add_contact_set_option(cmd)
    cmd.add_argument("--out", type=Path, default=default_out, help="output folder")


def _tradeoff(args: argparse.Namespace) -> int:
    from fenics_contact.scene.schema import load_scene
    from fenics_contact.sweeps.tradeoff import TradeoffCase

    cases = []
    for path in args.scenes:
        scene = load_scene(path)
        cases.append(TradeoffCase(args.name or scene.name, path.stem, scene))
    return tradeoff_and_write(cases, args)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``tradeoff`` subcommand."""
    cmd = sub.add_parser(
        "tradeoff",
        help="measure wall time against accuracy over methods x r on scenes",
        description="Sweep methods x r (relative to E/h) on each scene (give the same "
        "problem on several meshes as several scene files, coarse first); write "
        "tradeoff.json, tradeoff.csv, table.md and tradeoff.png (error against time, "
        "Pareto front marked). The project's own trade-off (Hertz, the Example 2 bar, the "
        "sliding block with friction, three meshes each) is benchmarks/research/tradeoff.py."
        " Each load step starts from the last converged state (predictor \"previous\", "
        "whatever the scene says), so that every method starts alike, each Newton step "
        "takes its contact set by the sign rule unless --contact-set exact; its stopping "
        "tolerance is its own, the same for every method and r: atol = max(1e-10 E "
        "h^(d-1), the round-off floor at r), written per run as atol in tradeoff.csv, and no "
        "rtol (a scene's default is atol = max(1e-8, 1e-12 E h^(d-1)) with rtol = 1e-10, "
        "tighter or looser than this one depending on E and h): iteration counts match "
        "`run` with predictor = \"previous\", the same contact_set, that atol and rtol = 0, "
        "where no step needs a cut-back (a trade-off allows none).",
    )
    cmd.add_argument("scenes", nargs="+", type=Path, help="scene files (.toml)")
    cmd.add_argument("--name", default=None,
                     help="one name for all scenes (the meshes of one problem); default: "
                     "each scene's own")
    add_tradeoff_options(cmd, Path("results/tradeoff"))
    cmd.set_defaults(func=_tradeoff)
