"""Run a scene: solve its load path, write XDMF, JSON, checkpoints and pictures as it goes."""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from mpi4py import MPI

from fenics_contact.model.problem import ContactProblem
from fenics_contact.output.checkpoint import (
    LATEST,
    CheckpointWriter,
    identity,
    read_latest,
    restore,
)
from fenics_contact.output.folders import agree, write_failure
from fenics_contact.output.io import write_json
from fenics_contact.output.paraview import SCRIPT, write_paraview_script
from fenics_contact.output.xdmf import StepWriter, finished_steps, step_files
from fenics_contact.scene.body_overlap import OverlapWatch, warn_body_overlap
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.checks import warn_untagged_penetration
from fenics_contact.scene.pressure_scatter import warn_pressure_scatter
from fenics_contact.scene.schema import Scene
from fenics_contact.scene.self_overlap import warn_self_overlap
from fenics_contact.scene.slot_overflow import warn_slot_overflow, warn_slots_capped
from fenics_contact.scene.striker_advice import advise_striker
from fenics_contact.scene.unpaired_overlap import warn_unpaired_overlap
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.auto import AutoStrategy
from fenics_contact.solvers.base import SolveResult
from fenics_contact.solvers.linear import LinearSolverSettings
from fenics_contact.solvers.predictor import ActiveSetPredicted, Extrapolated
from fenics_contact.solvers.stepping import RunRecord, StepRecord, solve_load_path, start_record
from fenics_contact.stop import StopRequested


@dataclass
class RunOutcome:
    """What a run produced."""

    problem: ContactProblem
    path: RunRecord
    summary: dict
    out: Path


def contact_settings(problem: ContactProblem) -> dict[str, dict]:
    """Each built contact's r (absolute and over its E/h), quadrature and bodies, by name.

    Read once the problem is built, before a strategy changes r: the r the
    run was asked for, whichever way the scene gave it.
    """
    used = {}
    for c in problem.contacts:
        r = float(c.r.value)
        used[c.name] = {
            "r_absolute": r, "r_relative": r / c.stiffness_scale,
            "quadrature": c.settings.quadrature,
            "bodies": tuple(getattr(c, "_names", (None, None))),
        }
    return used


def _summary(scene: Scene, record: RunRecord, used: dict[str, dict] | None = None,
             notes: Sequence[str] = ()) -> dict:
    """summary.json: the scene's identity and settings, then the run record.

    ``notes``: the scene's warnings so far (built, then checked after the run),
    as printed, under ``warnings``.

    ``bodies``, ``pairs`` (declared, then found by [pairing]) and
    ``obstacles`` hold each one's own settings; ``used``
    (:func:`contact_settings`) gives each contact's r as the run uses it.
    The top-level law, E and nu are the first body's, and quadrature, mu,
    r_absolute and r_relative the first contact's: kept for the scripts that
    read them, they describe the scene only with one body and one contact.
    """
    used = used or {}

    def built(name: str) -> dict:
        c = used.get(name, {})
        return {k: c[k] for k in ("r_absolute", "r_relative") if k in c}

    declared = {p.name for p in scene.pairs} | {o.name for o in scene.obstacles}
    automatic = [name for name in used if name not in declared]
    pairing = scene.pairing
    return {
        "scene": scene.name,
        "scene_file": str(scene.path),
        "dimension": scene.dimension,
        "law": scene.law,
        "E": scene.E,
        "nu": scene.nu,
        "quadrature": scene.contact.quadrature,
        "mu": scene.contact.mu,
        "predictor": scene.solver.predictor,
        "contact_set": scene.solver.contact_set,
        "linear_solver": scene.solver.linear_solver,
        "forcing": scene.solver.forcing,
        "reuse_preconditioner": scene.solver.reuse_preconditioner,
        "load_steps": scene.solver.steps,
        **_marked(record.to_dict()),
        "pairs": [
            {
                "name": pair.name, "striker": pair.striker, "target": pair.target,
                "automatic": False, "r": pair.r, "relative": pair.relative,
                **built(pair.name), "mu": pair.mu, "tangential_r_max": pair.tangential_r_max,
                "quadrature": used.get(pair.name, {}).get("quadrature", "nodal"),
                "discretisation": pair.discretisation, "self_contact": pair.self_contact,
                "interference_until": pair.interference_until,
                "steps": _contact_steps(record, pair.name, pair.mu is not None),
            }
            for pair in scene.pairs
        ] + [
            {
                "name": name, "striker": used[name]["bodies"][0],
                "target": used[name]["bodies"][1], "automatic": True,
                "r": pairing.r, "relative": pairing.relative, **built(name),
                "mu": pairing.mu, "tangential_r_max": pairing.tangential_r_max,
                "quadrature": used[name]["quadrature"],
                "discretisation": "node-to-segment", "self_contact": False,
                "steps": _contact_steps(record, name, pairing.mu is not None),
            }
            for name in automatic if pairing is not None
        ],
        "obstacles": [
            {
                "name": o.name, "type": o.obstacle.type, "tag": o.contact.tag,
                "r": o.contact.r, "relative": o.contact.relative, **built(o.name),
                "mu": o.contact.mu, "tangential_r_max": o.contact.tangential_r_max,
                "quadrature": o.contact.quadrature, **_shape(o.obstacle),
                "steps": [{**s, "point": _placed(o.obstacle, s["load_factor"])} for s in
                          _contact_steps(record, o.name, o.contact.mu is not None)],
            }
            for o in scene.obstacles
        ],
        "bodies": [
            {"name": b.name, "tag": b.tag, "law": b.law, "E": b.E, "nu": b.nu}
            for b in scene.bodies
        ] or [{"name": "body", "tag": None, "law": scene.law, "E": scene.E, "nu": scene.nu}],
        "warnings": list(notes),
    }


_FRICTION_KEYS = ("tangential_force", "tangential_magnitude", "stick_count", "slip_count")


def _shape(spec) -> dict:
    """An obstacle's geometry in summary.json (length).

    Its point (plane) or centre (ball) at load 0, and its normal, or its
    radius and side.
    """
    if spec.type == "plane":
        return {"point": list(spec.point), "normal": list(spec.normal)}
    return {"point": list(spec.point), "radius": spec.radius, "inside": spec.inside}


def _placed(spec, t: float) -> list[float]:
    """Where an obstacle's point (a ball's centre) is at load factor t (length)."""
    from fenics_contact.model.obstacle_contact import obstacle_offset, obstacle_schedule

    motion = np.zeros(len(spec.point)) if not spec.motion else np.asarray(spec.motion, float)
    schedule = obstacle_schedule(spec.schedule or None, len(spec.point))
    return (np.asarray(spec.point, float) + obstacle_offset(motion, schedule, t)).tolist()


def _marked(run: dict) -> dict:
    """The run's dict with each step marked ``written`` (in solution.xdmf) or not.

    A failed step's record holds the state the run stopped in, which no file
    holds when the step got part of the way; its ``note`` says so and names
    the last step written.
    """
    done = None
    for s in run["steps"]:
        s["written"] = s["status"] == "converged"
        if s["written"]:
            done = s
            continue
        on_disk = (f"solution.xdmf ends at step {done['step']} (load factor "
                   f"{done['load_factor']:g})" if done else "solution.xdmf holds no step")
        if done is not None and s["load_factor"] == done["load_factor"]:
            where = f"step {done['step']}'s, the last written"
        elif done is None and s["load_factor"] == 0.0:
            where = "the start"
        else:
            where = "the last converged part of this step, not written"
        at = "" if s.get("failed_at") is None else f" at load factor {s['failed_at']:g}"
        s["note"] = (f"the failed step ({s['status']}{at}): "
                     f"load_factor and the forces here are the state the run stopped in, "
                     f"at load factor {s['load_factor']:g} ({where}); {on_disk}")
    return run


def _contact_steps(record: RunRecord, name: str, frictional: bool) -> list[dict]:
    """One contact's numbers at each finished step (friction counts only with mu)."""
    return [
        {"step": s.step, "load_factor": s.load_factor,
         **{k: v for k, v in s.contacts.get(name, {}).items()
            if frictional or k not in _FRICTION_KEYS}}
        for s in record.steps
    ]


def _write_summary(comm: MPI.Comm, out: Path, scene: Scene, record: RunRecord,
                   used: dict[str, dict], notes: Sequence[str] = ()) -> dict:
    """Write summary.json (rank 0); a failed write stops every process alike."""
    summary = _summary(scene, record, used, notes)
    failure = None
    if comm.rank == 0:
        try:
            write_json(out / "summary.json", summary)
        except OSError as exc:
            failure = write_failure(exc, out / "summary.json")
    agree(comm, failure)
    return summary


#: What a run writes into its folder besides the index, the step files and the checkpoint.
RUN_FILES = ("summary.json", "deformed.png", "residuals.png", "friction.png")


def earlier_run(out: Path) -> int | None:
    """The finished load steps of an earlier run in ``out`` (None when it holds none).

    A run is known by its summary.json, its index (solution.xdmf), its step
    files or its checkpoint's ``latest.json``.
    """
    index = out / "solution.xdmf"
    steps = finished_steps(index)
    marks = (out / "summary.json", index, out / "checkpoint" / LATEST)
    if steps or step_files(index) or any(m.is_file() for m in marks):
        return len(steps)
    return None


def _replace_earlier_run(comm: MPI.Comm, out: Path) -> None:
    """Rank 0: say so when ``out`` holds an earlier run, and remove its summary and pictures.

    Its step files and checkpoint go with their writers (:class:`StepWriter`,
    :class:`CheckpointWriter`), which remove only the files they write:
    nothing else in ``out`` is touched.
    """
    if comm.rank != 0:
        return
    steps = earlier_run(out)
    if steps is None:
        return
    done = ("no finished load step" if steps == 0
            else f"{steps} load step{'s' if steps > 1 else ''}")
    print(f"fenics-contact: note: {out} held an earlier run ({done}); its results are replaced",
          file=sys.stderr, flush=True)
    renders = [p.name for p in out.glob("render_step_*.png")]  # `fenics-contact render`'s
    for name in (*RUN_FILES, *renders):
        try:
            (out / name).unlink(missing_ok=True)
        except OSError:  # unwritable: the run's first write names it
            pass


#: atol above this share of the force unit E h^(d-1) is too loose to mean converged.
LOOSE_ATOL = 1e-5


def scene_atol(scene: Scene, problem: ContactProblem) -> Scene:
    """The scene with atol following the forces when the scene does not give it.

    The residual is in force units: with a large E (steel in Pa: E h^(d-1)
    about 1e10) an absolute 1e-8 lies below the round-off of the forces and
    no step converges (a block on a plane, E = 2.1e11, was refused as
    cycling at 1e-6). Left out, atol is max(1e-8, 1e-12 E h^(d-1)); every
    shipped scene (E h^(d-1) <= 1e4) keeps 1e-8. The one place the default
    is resolved: :func:`scene_strategy` (so every route, ``run`` and the
    Python API alike) and :func:`run_scene` (its warnings and summary) read
    it here. Idempotent.
    """
    from fenics_contact.model.scaling import default_atol

    if scene.solver.atol_given:
        return scene
    return replace(scene, solver=replace(scene.solver, atol=default_atol(problem)))


#: Springs of a stabilised body carrying more than this share of its load are warned.
STABILISATION_SHARE = 1e-3


def warn_stabilisation(scene: Scene, problem: ContactProblem, path: RunRecord) -> None:
    """Warn where a stabilised body's springs carry a share of the load (collective).

    The load: the largest traction resultant, support reaction or contact
    force of the state the run ended in (:func:`~fenics_contact.model.springs.load_scale`).
    """
    from fenics_contact.model.springs import spring_loads
    from fenics_contact.scene.checks import SceneWarning

    if not path.steps:
        return
    for s in spring_loads(problem):
        if s.share > STABILISATION_SHARE:
            warnings.warn(SceneWarning(
                f"{scene.path.name}: [[body]] {s.body!r}: its stabilising springs carry "
                f"{s.force:.3g}, {s.share:.2%} of the load of the last step (the largest "
                "traction resultant, support reaction or contact force): they hold more than "
                "rigid motions; lower stabilise, or hold the body by a support."), stacklevel=2)


def _warn_loose_tolerance(scene: Scene, problem: ContactProblem) -> None:
    """Warn when atol (absolute, force units) is not small against the problem's forces.

    Newton's test is |R| <= max(atol, rtol |R_0|) with R in force units; the
    force unit of the problem is E h^(d-1) (h the contact facet size). With
    a soft material in stiff units, or micro-contact in SI units, a fixed
    atol = 1e-8 is no longer small against it and a run 'converges' early
    to a wrong answer (2D, E = 1e-9: the penalty method stops after one
    iteration at 30 times the right force).
    """
    from fenics_contact.model.scaling import force_scale
    from fenics_contact.scene.checks import SceneWarning

    unit = force_scale(problem)
    atol = scene.solver.atol
    if atol > LOOSE_ATOL * unit:
        warnings.warn(SceneWarning(
            f"{scene.path.name}: [solver] atol = {atol:g} is absolute (force units) and not "
            f"small against this problem's force unit E h^(d-1) = {unit:.3g}: Newton may stop "
            f"early with a wrong answer. Set atol to about {1e-10 * unit:.1g} "
            "(1e-10 E h^(d-1), h the contact facet size)."
        ), stacklevel=2)


def _warn_tight_tolerance(scene: Scene, problem: ContactProblem) -> None:
    """Warn when a given atol lies below the round-off of the residual (collective).

    The complementarity rows r g A are formed from coordinates: their
    round-off is eps r g_scale ||A||, and the residual was measured to stall
    at 0.1-0.5 of it (three bodies at E = 2e6, atol = 1e-10: 3-6e-10 for 50
    iterations, then max_iterations). Below that the run cannot converge.
    """
    from fenics_contact.model.scaling import (
        below_roundoff,
        contact_force_size,
        force_scale,
        suggested_atol,
    )
    from fenics_contact.scene.checks import SceneWarning

    atol = scene.solver.atol
    if not scene.solver.atol_given or not problem.contacts or not below_roundoff(problem, atol):
        return
    size = contact_force_size(problem)
    eps = float(np.finfo(float).eps)
    warnings.warn(SceneWarning(
        f"{scene.path.name}: [solver] atol = {atol:g} lies below the round-off of this "
        f"problem's residual, about {eps * size:.2g} (eps times its contact forces of size "
        f"r g ||A|| = {size:.3g}; E h^(d-1) = {force_scale(problem):.3g}): "
        f"Newton may stall above it and the step fail as max_iterations or cycling. Raise "
        f"atol to about {suggested_atol(problem):.1g} (or leave it out: the default follows E)."
    ), stacklevel=2)


@contextmanager
def _kept(notes: list[str]):
    """Keep the text of every SceneWarning issued inside in ``notes``, and issue it as usual."""
    from fenics_contact.scene.checks import SceneWarning

    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SceneWarning)
            yield
    finally:  # also when the scene is refused: its warnings came first
        for w in caught:
            if issubclass(w.category, SceneWarning):
                notes.append(str(w.message))
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def run_scene(
    scene: Scene,
    out: Path | str,
    *,
    comm: MPI.Comm = MPI.COMM_WORLD,
    on_step: Callable[[StepRecord], None] | None = None,
    on_residual: Callable[[int, float], None] | None = None,
    pictures: bool | None = None,
    resume: bool = False,
) -> RunOutcome:
    """Build and solve ``scene``; write DIR/solution.xdmf, summary.json and pictures.

    Each converged load step is written (fields, checkpoint, summary.json)
    at once, so a failing or stopped run leaves the completed ones on disk.
    Without ``resume``, an earlier run's files in ``out`` (its index, step
    files, checkpoint files, summary.json and pictures) are removed first,
    with one note on stderr; other files in ``out`` stay.
    ``resume`` continues from the checkpoint in ``out`` (after its last
    finished step); a checkpoint of another scene or process count raises
    :class:`~fenics_contact.output.checkpoint.CheckpointError`.
    """
    out = Path(out)
    run_identity = identity(scene, comm.size)
    marker = read_latest(out / "checkpoint", run_identity) if resume else None  # before building
    notes: list[str] = []
    with _kept(notes):
        problem = build_problem(scene, comm)
        scene = scene_atol(scene, problem)
        warn_slots_capped(problem)
        used = contact_settings(problem)  # before a strategy changes r
        strategy = scene_strategy(scene, problem, on_residual)  # warns of atol
    saved = restore(out / "checkpoint", problem, marker) if marker is not None else None
    if isinstance(strategy, Extrapolated) and saved is not None and saved.history:
        strategy.history = saved.history
        if isinstance(strategy, ActiveSetPredicted):
            strategy.gap_history = saved.gaps
    solver = strategy.inner if isinstance(strategy, Extrapolated) else strategy
    if isinstance(solver, AutoStrategy) and saved is not None:
        solver.r_cap = saved.r_cap
    record = start_record(strategy)
    record.steps = [StepRecord(**r) for r in saved.records] if saved is not None else []
    record.wall_s = sum(s.wall_s for s in record.steps)  # a resumed run counts its earlier part
    first = saved.step + 1 if saved is not None else 1
    if not resume:
        _replace_earlier_run(comm, out)
    # an old run's checkpoint goes before its step files: never one without the other
    checkpoint = CheckpointWriter(out / "checkpoint", problem, run_identity, fresh=not resume)
    writer = StepWriter(problem, out / "solution.xdmf", scene.fields, first_step=first)
    if comm.rank == 0:
        write_paraview_script(out / "solution.xdmf", scene.fields, scene.dimension)

    watch = OverlapWatch(problem)

    def finished(step: StepRecord) -> None:
        watch.step(step.step, step.load_factor)
        step.reactions = problem.support_reactions()
        for name, force in problem.stabilisation_forces().items():  # weak springs: a support
            step.reactions[f"stabilise {name}"] = force.tolist()
        step.reaction_total = problem.support_total()
        writer.write(step.load_factor)
        history = strategy.history if isinstance(strategy, Extrapolated) else []
        gaps = strategy.gap_history if isinstance(strategy, ActiveSetPredicted) else []
        checkpoint.write(step.step, [s.to_dict() for s in record.steps], history,
                         files=writer.written, gaps=gaps,
                         r_cap=solver.r_cap if isinstance(solver, AutoStrategy) else None)
        _write_summary(comm, out, scene, record, used, notes)
        if on_step is not None:
            on_step(step)

    try:
        path = solve_load_path(
            strategy, scene.solver.steps, max_cutbacks=scene.solver.max_cutbacks,
            on_step=finished, record=record, first_step=first,
        )
    except StopRequested as stop:
        record.status = "interrupted"
        done = sum(s.status == "converged" for s in record.steps)
        record.message = (f"{stop} after {done} finished load step{'s' if done != 1 else ''}; "
                          "continue with --resume")
        if comm.rank == 0:
            write_json(out / "summary.json", _summary(scene, record, used, notes))
        raise
    finally:
        writer.close()
    if path.steps and path.steps[-1].status != "converged":
        # the failed step's record holds the state the run stopped in (restored)
        path.steps[-1].reactions = problem.support_reactions()
        path.steps[-1].reaction_total = problem.support_total()
    with _kept(notes):
        warn_slot_overflow(problem)  # also when no step converged: it may be why
        warn_stabilisation(scene, problem, path)
    if any(s.status == "converged" for s in path.steps):
        # checks of the answer; with no load step finished the state is the start,
        # which the checks before the first step have described
        with _kept(notes):
            warn_untagged_penetration(scene, problem)
            warn_body_overlap(scene, problem, watch)
            warn_self_overlap(scene, problem)
            warn_unpaired_overlap(scene, problem)
            advise_striker(scene, problem)
            warn_pressure_scatter(scene, problem)
    summary = _write_summary(comm, out, scene, path, used, notes)
    if not finished_steps(out / "solution.xdmf"):  # no step on disk: nothing to open
        if comm.rank == 0:
            (out / SCRIPT).unlink(missing_ok=True)
        return RunOutcome(problem, path, summary, out)
    if scene.pictures if pictures is None else pictures:
        if path.steps and path.steps[-1].status != "converged":
            # the pictures show the last step on disk, not the failed step's partial state
            with _at_last_written_step(problem, out / "checkpoint", run_identity):
                draw_pictures(scene, problem, path, out, shown=_last_written(path))
        else:
            draw_pictures(scene, problem, path, out)
    return RunOutcome(problem, path, summary, out)


def _last_written(path: RunRecord) -> StepRecord | None:
    """The record of the last converged load step: the last one in solution.xdmf."""
    return next((s for s in reversed(path.steps) if s.status == "converged"), None)


@contextmanager
def _at_last_written_step(problem: ContactProblem, folder: Path, run_identity: dict):
    """Put ``problem`` at its last checkpoint (the last step written) inside; back after.

    A failed step stops at the last converged part of its increment, which
    no file holds. Its checkpoint gives the written step exactly (u, the
    multipliers, the load factor and the friction history); afterwards the
    problem is back in the state the run stopped in, whose u is its own
    committed state (the failed attempt started from it).
    """
    stopped = problem.snapshot()
    restore(folder, problem, read_latest(folder, run_identity))
    try:
        yield
    finally:
        problem.restore(stopped)
        problem.commit()


def scene_strategy(scene: Scene, problem: ContactProblem,
                   on_residual: Callable[[int, float], None] | None = None):
    """The strategy of the scene's [solver] on ``problem`` (method, linear solver, predictor).

    The stopping tolerance is the scene's atol as :func:`scene_atol` resolves
    it (left out: it follows E h^(d-1)), the one ``fenics-contact run`` uses;
    an atol too loose or below round-off for the problem's forces is warned.
    """
    scene = scene_atol(scene, problem)
    _warn_loose_tolerance(scene, problem)
    _warn_tight_tolerance(scene, problem)
    return make_strategy(
        scene.solver.method, problem, scene.solver,  # a SolverSettings with stepping keys
        linear=LinearSolverSettings(
            kind=scene.solver.linear_solver, forcing=scene.solver.forcing,
            reuse_preconditioner=scene.solver.reuse_preconditioner,
        ),
        observer=on_residual, predictor=scene.solver.predictor,
        contact_set=scene.solver.contact_set,
    )


def draw_pictures(scene: Scene, problem: ContactProblem, path: RunRecord, out: Path,
                  shown: StepRecord | None = None) -> None:
    """OUT/deformed.png, residuals.png and, with friction, friction.png of the problem's state.

    ``shown``: the record of the load step whose state the problem holds (a
    failed run's last written step); None: the state the path ended in (its
    last record). The titles name that step, its load factor and contact
    force, and a failed step beside it.
    """
    from fenics_contact.output.pictures import deformed_contact_picture
    from fenics_contact.output.plotting import step_residuals

    title = picture_title(scene.name, path, shown)
    deformed_contact_picture(problem, out / "deformed.png", title=title)
    if problem.comm.rank == 0 and path.steps:
        step_residuals(path.steps, out / "residuals.png", title=scene.name)
    if scene.frictional:
        from fenics_contact.output.friction_plot import friction_profile

        friction_profile(
            problem, out / "friction.png",  # type: ignore[arg-type]
            title=picture_title(f"{scene.name}, tangential traction", path, shown,
                                force=False),
        )


def picture_title(name: str, path: RunRecord, shown: StepRecord | None = None, *,
                  force: bool = True) -> str:
    """The title of a run's pictures: the step shown, its load factor and contact force.

    A failed run's pictures show its last written step (``shown``) and name
    the failed step on a second line; without one (no step written) they
    show the state the failed step stopped in and say so. ``force`` False
    leaves the contact force out (a narrow plot).
    """
    if not path.steps:
        return f"{name}: load factor 0 ({path.status})"
    last = path.steps[-1]
    shown = shown or last

    def state(s: StepRecord) -> str:
        return (f"step {s.step}, load factor {s.load_factor:g}"
                + (f", contact force {s.contact_force:.4g}" if force else ""))

    if last.status == "converged":
        return f"{name}: {state(last)} ({path.status})"
    failed = (f"step {last.step} {last.status} at load factor "
              f"{last.failed_at if last.failed_at is not None else last.load_factor:g}")
    if shown is last:
        return (f"{name}: {failed}; shown: the state it stopped in, load factor "
                f"{last.load_factor:g}"
                + (f", contact force {last.contact_force:.4g}" if force else "")
                + " (not written)")
    return f"{name}: {state(shown)}, the last step written\n({failed})"


__all__ = ["RUN_FILES", "RunOutcome", "SolveResult", "contact_settings", "draw_pictures",
           "earlier_run", "picture_title", "run_scene", "scene_strategy"]
