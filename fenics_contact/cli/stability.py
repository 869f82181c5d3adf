"""``fenics-contact stability``: every method on scenes at extreme r, each run with a status."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from fenics_contact.cli.progress import progress_to_csv
from fenics_contact.cli.study import floats, methods

#: r values (relative to E/h) of ``fenics-contact stability`` by default: 1e-8 ... 1e12.
EXTREME_R = tuple(10.0**e for e in range(-8, 13, 4))


def run_grid_and_write(cases: Sequence, args: argparse.Namespace) -> int:
    """Run ``cases`` with the options in ``args``; write CSV, JSON and the picture to args.out.

    Returns the exit code: 0, or 1 when a run ended with an error (an
    exception, not a solver status).
    """
    from mpi4py import MPI

    from fenics_contact.output.io import write_json
    from fenics_contact.sweeps.stability import ERROR, loose_tolerances, run_grid
    from fenics_contact.sweeps.sweep_plots import stability_plot

    out: Path = args.out
    rank0 = MPI.COMM_WORLD.rank == 0

    def line(rec) -> str:
        return (
            f"  {rec.case:20s} {rec.method:8s} {rec.outcome_text():15s} it {rec.iterations:5d} "
            f"steps {rec.steps_completed}/{rec.load_steps}  {rec.wall_s:6.2f} s"
            + ("" if rec.ft_ratio is None else f"  Ft/muN {rec.ft_ratio:.6f}")
            + ("" if rec.reference_reached is None
               else "  reference " + ("reached" if rec.reference_reached else "missed"))
            + (f"  {rec.message}" if rec.message else "")
        )

    records, keep = progress_to_csv(
        out / "stability.csv", line,
        "stability's --force-rtol times E h^(d-1); the round-off floor at r is its least")

    if rank0:
        print(f"Stability: {len(cases)} cases x {len(args.methods)} methods", flush=True)
    run_grid(
        cases, args.methods, out=out, progress=keep, max_iterations=args.max_iterations,
        max_cutbacks=args.max_cutbacks, force_rtol=args.force_rtol,
        contact_set=args.contact_set,
    )
    write_json(out / "stability.json", [r.to_dict() for r in records])
    if rank0:
        loose = loose_tolerances(records)
        if loose:
            print("\nStopping tolerance a sizeable share of the contact force (a run may stop "
                  "that far from the answer; \"converged, off the reference\" says where it "
                  "did):\n  " + "\n  ".join(loose))
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


def add_run_options(cmd: argparse.ArgumentParser, default_out: Path) -> None:
    """The options every stability run takes (methods, limits, tolerance, output folder)."""
    from fenics_contact.model.scaling import DEFAULT_FORCE_RTOL
    from fenics_contact.sweeps.stability import METHODS

    cmd.add_argument("--methods", type=methods, default=list(METHODS),
                     help="comma-separated strategies (default penalty,sua,nua,gnrm,auto)")
    cmd.add_argument("--max-iterations", type=int, default=100,
                     help="Newton iteration cap per load step (default 100)")
    cmd.add_argument("--max-cutbacks", type=int, default=0,
                     help="step halvings allowed after a failed step (default 0)")
    cmd.add_argument("--force-rtol", type=float, default=DEFAULT_FORCE_RTOL,
                     help="tolerance relative to the force scale E h^(d-1) (default 1e-10)")
    add_contact_set_option(cmd)
    cmd.add_argument("--out", type=Path, default=default_out, help="output folder")


def add_contact_set_option(cmd: argparse.ArgumentParser) -> None:
    """--contact-set: the Newton steps' contact set of every run of a sweep."""
    cmd.add_argument(
        "--contact-set", choices=("sign", "exact"), default="sign",
        help='how each Newton step chooses its contact set: "sign" (the paper\'s GNRM; '
             'the default here, whatever the scene says) or "exact" (the scenes\' own '
             "default: measure what `run` does with it; GNRM converges at larger r)")


def run_cases(cases: Sequence, argv: Sequence[str], default_out: Path) -> int:
    """Command line of a named grid of cases (``--cases`` picks names or groups)."""
    from fenics_contact.sweeps.stability import select

    parser = argparse.ArgumentParser(description="Run every method on a grid of extreme cases.")
    groups = ",".join(dict.fromkeys(c.group for c in cases))
    parser.add_argument("--cases", type=_names, default=None,
                        help=f"comma-separated case names or groups ({groups}); default: all")
    add_run_options(parser, default_out)
    args = parser.parse_args(list(argv))
    try:
        chosen = select(cases, args.cases)
    except ValueError as exc:
        parser.error(str(exc))
    return run_grid_and_write(chosen, args)


def _stability(args: argparse.Namespace) -> int:
    from fenics_contact.scene.schema import load_scene
    from fenics_contact.sweeps.stability import scene_cases

    scenes = [load_scene(path) for path in args.scenes]
    return run_grid_and_write(scene_cases(scenes, args.r), args)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``stability`` subcommand."""
    cmd = sub.add_parser(
        "stability",
        help="run every method on scenes at extreme r and record each status",
        description="Run methods on each scene at each r (default 1e-8 ... 1e12 E/h); record "
        "each run's status, iterations, forces, F_t/(mu N) and whether it reached the "
        "reference answer (GNRM at r = 1 E/h; a converged run that misses it by more than "
        "1e-6 is \"converged, off the reference\", in the picture too, and a tolerance "
        "above 1 %% of the contact force is named); write stability.csv, stability.json, "
        "stability.png and per-run step records under cases/. The project's own grid of "
        "extremes (E, nu, steps, starts, meshes, friction, pairs) is "
        "benchmarks/robustness/stability_grid.py. Exit code 0, or 1 when a run ended with "
        "an error (an exception, not a solver status)."
        " Each load step starts from the last converged state (predictor \"previous\", "
        "whatever the scene says), so that every method starts alike, and each Newton "
        "step takes its contact set by the sign rule (--contact-set); the stopping "
        "tolerance is max(--force-rtol E h^(d-1), the round-off floor at r), not the "
        "scene's atol, and no rtol: iteration counts match `run` with predictor = "
        "\"previous\", contact_set = \"sign\", the atol written in stability.csv and "
        "rtol = 0 (a scene's default rtol = 1e-10 may stop earlier; a scene's "
        "default contact_set = \"exact\" may converge where a run here does not: "
        "--contact-set exact).",
    )
    cmd.add_argument("scenes", nargs="+", type=Path, help="scene files (.toml)")
    cmd.add_argument("--r", type=floats, default=list(EXTREME_R),
                     help="comma-separated r values relative to E/h (default 1e-8,1e-4,...,1e12)")
    add_run_options(cmd, Path("results/stability"))
    cmd.set_defaults(func=_stability)
