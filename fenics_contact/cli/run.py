"""``fenics-contact run SCENE.toml --out DIR``: solve a scene with a progress bar."""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from fenics_contact.stop import StopOnSignal, StopRequested

if TYPE_CHECKING:
    from fenics_contact.model.problem import ContactProblem
    from fenics_contact.scene.schema import Scene
    from fenics_contact.solvers.stepping import StepRecord


def _resume_command(args: argparse.Namespace, out: Path, processes: int) -> str:
    launcher = f"mpiexec -n {processes} " if processes > 1 else ""
    scene, folder = shlex.quote(str(args.scene)), shlex.quote(str(out))
    return f"{launcher}fenics-contact run {scene} --resume {folder}"


def _checkpoint_step(out: Path) -> int:
    """The last finished step of the checkpoint in ``out`` (0 when there is none)."""
    try:
        return int(json.loads((out / "checkpoint" / "latest.json").read_text())["step"])
    except (OSError, ValueError, KeyError, TypeError):
        return 0


def _kept(done: int, out: Path) -> str:
    """Where the finished load steps 1 .. done are, in words."""
    if done == 0:
        return f"no load step finished, so {out} holds no solution.xdmf"
    steps = "step 1 is" if done == 1 else f"steps 1-{done} are"
    return f"{steps} in {out}/solution.xdmf"


def _stopped(
    stop: StopRequested, args: argparse.Namespace, out: Path, steps: int, done: int
) -> None:
    """The one line a stopped run prints (rank 0): what is done, where, how to resume."""
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    if comm.rank != 0:
        return
    if done:
        where = f"{_kept(done, out)}; resume with: {_resume_command(args, out, comm.size)}"
    else:
        where = f"no load step finished in {out}; nothing to resume, run it again"
    print(
        f"fenics-contact: stopped by {stop.signal_name} after {done} of {steps} load steps; "
        f"{where}",
        file=sys.stderr, flush=True,
    )


def _run(args: argparse.Namespace) -> int:
    from mpi4py import MPI

    from fenics_contact.scene.schema import load_scene

    with StopOnSignal(MPI.COMM_WORLD) as stop:
        scene = load_scene(args.scene)  # validation first: no mesh, no forms yet
        if args.resume is not None and args.out is not None and (
            args.out.resolve() != args.resume.resolve()
        ):
            raise ValueError(
                f"--out {args.out} and --resume {args.resume} differ: a resumed run continues "
                "in the folder it resumes; give only --resume."
            )
        out: Path = args.resume or args.out or Path("results") / scene.name
        from fenics_contact.output.folders import prepare_output_folder

        option = "--resume" if args.resume is not None else "--out"
        prepare_output_folder(out, MPI.COMM_WORLD, option)  # a bad folder ends here, before meshing
        finished = [_checkpoint_step(out) if args.resume is not None else 0]
        from fenics_contact.output.folders import OutputWriteError, run_lock

        try:
            with run_lock(out, MPI.COMM_WORLD, option):
                return _solve(args, scene, out, stop, finished)
        except StopRequested as exc:
            _stopped(exc, args, out, scene.solver.steps, finished[0])
            return exc.exit_code
        except OutputWriteError as exc:
            if MPI.COMM_WORLD.rank == 0:
                print(f"fenics-contact: {exc}; the run stopped in load step {finished[0] + 1}; "
                      f"{_kept(finished[0], out)}", file=sys.stderr, flush=True)
            return 1


def _solve(
    args: argparse.Namespace, scene: Scene, out: Path, stop: StopOnSignal, finished: list[int]
) -> int:
    """Run ``scene`` into ``out``; ``finished[0]`` follows the last finished load step."""
    from tqdm import tqdm

    from mpi4py import MPI

    from fenics_contact.runner import run_scene
    from fenics_contact.scene.slot_overflow import slot_shortfall

    steps = scene.solver.steps
    quiet = args.quiet or MPI.COMM_WORLD.rank != 0
    # a progress bar on a terminal; in a log (no terminal) one line per load step
    terminal = sys.stderr.isatty()
    bar = tqdm(
        total=steps, initial=finished[0], unit="step", desc=scene.name,
        disable=quiet or not terminal,
        bar_format="{desc}: {n_fmt}/{total_fmt} steps |{bar}| {elapsed} {postfix}",
    )

    def residual(iteration: int, value: float) -> None:
        bar.set_postfix_str(f"iteration {iteration}, residual {value:.2e}", refresh=True)
        stop.check()

    def step(record: StepRecord) -> None:
        finished[0] = record.step
        bar.update(1)
        if not (quiet or terminal):
            newton = _count(record.iterations, "Newton iteration")
            if record.cutbacks:
                newton += f" ({_count(record.cutbacks, 'cut-back')})"
            print(f"{scene.name}: load step {record.step}/{steps} {record.status}, load factor "
                  f"{record.load_factor:.4g}, {newton}, {_forces(record)}", file=sys.stderr,
                  flush=True)
        stop.check()

    stop.check()  # a signal while the scene was read
    try:
        outcome = run_scene(
            scene, out, on_step=step, on_residual=residual,
            pictures=False if args.no_pictures else None, resume=args.resume is not None,
        )
    finally:
        bar.close()
    path = outcome.path
    if not path.converged:
        failed = path.steps[-1]
        slots = slot_shortfall(outcome.problem)  # collective
        if MPI.COMM_WORLD.rank == 0:  # the same on every process: said once
            advice = _advice(scene, failed.status,
                             getattr(outcome.problem, "initial_overlap", None),
                             failed.message or "", slots)
            verdict = ("was refused" if failed.status == "held_by_springs"
                       else "did not converge")
            print(f"fenics-contact: load step {failed.step} of {steps} {verdict} "
                  f"({failed.message or failed.status}); {_kept(failed.step - 1, out)}"
                  f"{advice}", file=sys.stderr)
        return 1
    if not quiet:
        s = outcome.summary
        print(
            f"{scene.name}: converged, {_count(s['iterations'], 'Newton iteration')} in "
            f"{_count(s['load_steps'], 'step')}, {s['wall_s']:.1f} s; "
            f"{_forces(path.steps[-1])}, max penetration "
            f"{_penetration(scene, outcome.problem, path.steps[-1].max_penetration)}"
            f"{_warned(s.get('warnings', []))}"
            f"\nWrote {out}/{', '.join(_written(out))}"
        )
    return 0


#: Contacts named one by one in a run's lines; beyond, summary.json has them.
NAMED_FORCES = 4


def _forces(record: StepRecord) -> str:
    """'contact force F' for one contact; each contact's normal force for several.

    Their sum would add an obstacle's force to the forces inside an assembly
    or a body pressed on itself (a ring squeezed shut read 26.65 for plates
    of 10.06 each).
    """
    contacts = record.contacts or {}
    if len(contacts) <= 1:
        return f"contact force {record.contact_force:.6g}"
    named = [f"{name} {c['normal_force']:.6g}" for name, c in contacts.items()]
    if len(named) > NAMED_FORCES:
        named = [*named[:NAMED_FORCES], f"... ({len(named)} contacts: summary.json)"]
    return "contact forces " + ", ".join(named)


def _warned(notes: list[str]) -> str:
    """'; 2 warnings above (kept in summary.json)' after a run that warned, else ''."""
    if not notes:
        return ""
    return f"; {_count(len(notes), 'warning')} above (kept in summary.json)"


def _written(out: Path) -> list[str]:
    """The run's files in ``out`` (an earlier run's summary and pictures were removed)."""
    from fenics_contact.output.paraview import SCRIPT
    from fenics_contact.runner import RUN_FILES

    names = ["solution.xdmf", *RUN_FILES, SCRIPT]
    return [name for name in names if (out / name).is_file()]


def _count(n: int, noun: str) -> str:
    """'1 step', '2 steps'."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _advice(scene: Scene, status: str, overlap: str | None = None, message: str = "",
            slots: str | None = None) -> str:
    """What to try after a failed load step (nothing for a stop that is not the solver's).

    ``overlap``: the body's initial overlap with an obstacle, when it was warned
    about; first on the list, since no solver setting mends it. ``message``:
    the failed step's; when it already names the one fix (a node inside its
    own self-contact neighbourhood, a support that drives a node into its partner), no
    solver setting is suggested; when its residual stalled at round-off, only the
    scene's [solver] atol (the stall note itself does not say where a tolerance is set).
    ``slots``: a 2D mortar pair whose nodes overlapped
    more target facets than their slots (:func:`~fenics_contact.scene.slot_overflow.
    slot_shortfall`); first on the list, since its weighted gaps jump.
    """
    if status not in ("cycling", "diverged", "max_iterations", "inverted"):
        return ""
    from fenics_contact.solvers.diagnostics import NO_SOLVER_MENDS, ROUNDOFF_STALL

    if "the self-contact search never pairs it with" in message or NO_SOLVER_MENDS in message:
        return "."
    if ROUNDOFF_STALL in message:  # no method or step size takes a residual below round-off
        left_out = (" (or leave atol out of the scene: the default follows E)"
                    if scene.solver.atol_given else "")
        return (". To try: first a larger [solver] atol, as large as said above"
                f"{left_out}; the residual stalled at the round-off of its forces, which no "
                "method or step size lowers.")
    method = scene.solver.method
    tips = []
    if overlap:
        tips.append(f"first the start: {overlap}; place the obstacle so that the gap at "
                    "load 0 is >= 0")
    if slots:
        tips.append(f"first the slots: {slots}")
    if status == "max_iterations" and method in ("nua", "sua"):
        tips.append(f"a larger [solver] max_iterations (now {scene.solver.max_iterations}: "
                    f"{method.upper()} counts every multiplier update as an iteration and "
                    "may need hundreds per load step)")
    if method != "auto":
        tips.append('method = "auto" (Newton on both unknowns; it lowers its working r '
                    "and line-searches where plain Newton cycles)")
    if status != "max_iterations" and "svk" in {b.law for b in scene.bodies} | {scene.law}:
        tips.append('if a body is compressed by more than about 40 %, law = "neo-hookean": '
                    "the St. Venant-Kirchhoff law softens under compression (its uniaxial "
                    "stress peaks at the stretch 1/sqrt(3)), and past that an equilibrium "
                    "may not exist or not be unique, however small the steps")
    tips.append("more [solver] steps or max_cutbacks (smaller increments near the failure)")
    return ". To try: " + "; ".join(tips) + "."


def _penetration(scene: Scene, problem: ContactProblem, depth: float) -> str:
    """The depth, and as a share of the contact facet size h; a note where penalty leaves it."""
    sizes = [c.surface.h for c in problem.contacts]
    if not sizes or depth <= 0.0:
        return f"{depth:.2e}"
    h = min(sizes)
    text = f"{depth:.2e} ({depth / h:.2g} h)"
    if scene.solver.method == "penalty" and depth > 1e-3 * h:
        text += (" - the penalty method's own penetration: raise r, or use gnrm or auto for "
                 "none")
    return text


def register(sub: argparse._SubParsersAction) -> None:
    """Add the ``run`` subcommand."""
    run = sub.add_parser(
        "run",
        help="solve a TOML scene and write XDMF, JSON and pictures",
        description="Solve the contact scene described by a TOML file. Writes "
        "DIR/solution.xdmf (index of DIR/solution/step_NNNN.h5: displacement, contact "
        "pressure, gap, active set and von Mises stress at every load step, for ParaView), "
        "DIR/checkpoint/ (to resume), DIR/summary.json, DIR/deformed.png (deformed body "
        "coloured by contact pressure) and DIR/residuals.png. Each load step is on disk "
        "as soon as it finishes, whatever stops the run later. Exit code 0 on success, "
        "1 when a load step fails (the completed steps stay on disk), 2 for a bad scene "
        "or a checkpoint that does not fit it, 130/143 when stopped by SIGINT/SIGTERM.",
    )
    run.add_argument("scene", type=Path, help="the scene file (see scenes/ for examples)")
    run.add_argument(
        "--out", type=Path, default=None, help="output folder (default results/<scene name>)"
    )
    run.add_argument(
        "--resume", type=Path, default=None, metavar="DIR",
        help="continue the run whose output folder is DIR after its last finished load "
        "step (same scene and number of processes); the output stays in DIR",
    )
    run.add_argument("--no-pictures", action="store_true", help="skip the PNG pictures")
    run.add_argument("--quiet", action="store_true", help="no progress bar or summary line")
    run.set_defaults(func=_run)
