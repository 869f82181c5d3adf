"""``fenics-contact run SCENE.toml --out DIR``: solve a scene with a progress bar."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _run(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from fenics_contact.scene.schema import load_scene

    scene = load_scene(args.scene)  # validation first: no mesh, no forms yet
    out: Path = args.out or Path("results") / scene.name
    from fenics_contact.output.folders import prepare_output_folder

    prepare_output_folder(out, MPI.COMM_WORLD)  # a bad --out ends here, before any mesh
    from tqdm import tqdm

    from fenics_contact.runner import run_scene

    quiet = args.quiet or MPI.COMM_WORLD.rank != 0
    bar = tqdm(
        total=scene.solver.steps, unit="step", desc=scene.name, disable=quiet,
        bar_format="{desc}: {n_fmt}/{total_fmt} steps |{bar}| {elapsed} {postfix}",
    )

    def residual(iteration: int, value: float) -> None:
        bar.set_postfix_str(f"iteration {iteration}, residual {value:.2e}", refresh=True)

    def step(_record: object) -> None:
        bar.update(1)

    try:
        outcome = run_scene(
            scene, out, on_step=step, on_residual=residual,
            pictures=False if args.no_pictures else None,
        )
    finally:
        bar.close()
    path = outcome.path
    if not path.converged:
        failed = path.steps[-1]
        done = len(path.steps) - 1
        print(
            f"fenics-contact: load step {failed.step} of {scene.solver.steps} did not converge "
            f"({failed.status} after {failed.cutbacks} cut-backs"
            + (f": {failed.message}" if failed.message else "")
            + f"); steps 1-{done} are in {out}/solution.xdmf",
            file=sys.stderr,
        )
        return 1
    if not quiet:
        s = outcome.summary
        print(
            f"{scene.name}: converged, {s['iterations']} Newton iterations in "
            f"{s['load_steps']} steps, {s['wall_s']:.1f} s; contact force "
            f"{path.steps[-1].contact_force:.6g}, max penetration "
            f"{path.steps[-1].max_penetration:.2e}\nWrote {out}/solution.xdmf, summary.json"
            + ("" if args.no_pictures or not scene.pictures else ", deformed.png, residuals.png")
        )
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``run`` subcommand."""
    run = sub.add_parser(
        "run",
        help="solve a TOML scene and write XDMF, JSON and pictures",
        description="Solve the contact scene described by a TOML file. Writes "
        "DIR/solution.xdmf (+ .h5: displacement, contact pressure, gap, active set and "
        "von Mises stress at every load step, for ParaView), DIR/summary.json, "
        "DIR/deformed.png (deformed body coloured by contact pressure) and "
        "DIR/residuals.png. Exit code 0 on success, 1 when a load step fails (the "
        "completed steps stay on disk), 2 for a bad scene.",
    )
    run.add_argument("scene", type=Path, help="the scene file (see scenes/ for examples)")
    run.add_argument(
        "--out", type=Path, default=None, help="output folder (default results/<scene name>)"
    )
    run.add_argument("--no-pictures", action="store_true", help="skip the PNG pictures")
    run.add_argument("--quiet", action="store_true", help="no progress bar or summary line")
    run.set_defaults(func=_run)
