"""Stability at the extremes: a grid of hard cases, every one ending with a status.

Each case is a scene (:mod:`fenics_contact.verification.bench_scenes`) with one knob at
an extreme: r from 1e-8 to 1e12 E/h (on the bar and on the Hertz cylinder),
E from 1e-3 to 1e12 (displacement loading: forces scale with E), nu up to
0.4999, 1/10/100 load steps, an initial penetration, grazing start, no
contact, full contact, a very coarse and a fine mesh; and the sliding block
with Coulomb friction (groups ``friction``: mu from 0 to 10 and a load
reversal at r = 1 E/h; ``friction-r``: r from 1e-8 to 1e12 E/h at mu = 0.3,
with the default r_t = min(r, 2 E/L), L the contact surface extent, and with
r_t = r).

The stopping test is the same for every method and meaningful for any E:
atol = max(force_rtol * E h^(d-1), round-off floor at r)
(:func:`fenics_contact.model.scaling.scaled_atol`). A run never raises: an
exception becomes the status ``error`` with its message, and non-finite
outputs the status ``nonfinite``. The step records of every run are written
to ``<out>/cases/<case>__<method>.json`` after each converged step, so a
failed step keeps the completed ones on disk.
"""

from __future__ import annotations

import math
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.scaling import DEFAULT_FORCE_RTOL, scaled_atol
from fenics_contact.output.io import write_json
from fenics_contact.solvers import STRATEGIES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import RunRecord, StepRecord, solve_load_path, start_record
from fenics_contact.verification.bench_scenes import BarScene, BlockScene, HertzScene
from fenics_contact.verification.friction_scenes import REVERSAL, SlidingBlock
from fenics_contact.verification.two_body_examples import IroningShort, TwoCylinders

#: Methods the stability grid runs by default.
METHODS = tuple(STRATEGIES)

#: Extra statuses of a run besides the solver statuses: an exception (with
#: its message in ``CaseRecord.message``) and non-finite outputs.
ERROR = Status.ERROR.value
NONFINITE = "nonfinite"


@dataclass(frozen=True)
class StabilityCase:
    """One extreme: a scene, r relative to E/h and the number of load steps."""

    name: str
    group: str
    scene: object
    r: float = 1.0

    @property
    def steps(self) -> int:
        """Load steps of the scene."""
        return int(self.scene.steps)


def full_grid() -> list[StabilityCase]:
    """Every case of the stability study."""
    cases = [
        StabilityCase(f"{name}-r1e{e}", "r", scene, 10.0**e)
        for name, scene in (("bar", BarScene()), ("hertz", HertzScene()))
        for e in range(-8, 13, 2)
    ]
    cases += [StabilityCase(f"bar-E1e{e}", "E", BarScene(E=10.0**e)) for e in (-3, 0, 3, 6, 9, 12)]
    cases += [
        StabilityCase(f"bar-nu{nu:g}", "nu", BarScene(nu=nu)) for nu in (0.0, 0.3, 0.49, 0.4999)
    ]
    cases += [StabilityCase(f"bar-steps{n}", "steps", BarScene(steps=n)) for n in (1, 10, 100)]
    cases += [
        StabilityCase("bar-penetrating", "start", BarScene(end_gap=-0.02)),
        StabilityCase("bar-grazing", "start", BarScene(end_gap=0.0)),
        StabilityCase("hertz-grazing", "start", HertzScene()),
        StabilityCase("bar-no-contact", "start", BarScene(end_gap=1.0)),
        StabilityCase("block-full-contact", "start", BlockScene()),
        StabilityCase("bar-coarse-3x1", "mesh", BarScene(nx=3, ny=1)),
        StabilityCase("bar-fine-48x16", "mesh", BarScene(nx=48, ny=16, law="neo-hookean")),
        StabilityCase("bar-fine-48x16-svk", "mesh", BarScene(nx=48, ny=16)),
    ]
    # Two deformable bodies: r, stiffness ratio, grazing start (the cylinders
    # touch at one point at t = 0) and large sliding.
    cases += [
        StabilityCase(f"two-cyl-r1e{e}", "two-body-r", TwoCylinders(), 10.0**e)
        for e in range(-8, 13, 4)
    ]
    cases += [
        StabilityCase(f"two-cyl-stiffness1e{e}", "two-body-stiffness",
                      TwoCylinders(stiffness_ratio=10.0**e))
        for e in (-3, 0, 3)
    ]
    cases += [StabilityCase("ironing-short", "two-body-sliding", IroningShort())]
    return cases + friction_grid()


def friction_grid() -> list[StabilityCase]:
    """The sliding block with Coulomb friction: mu 0 ... 10, r extremes, a load reversal."""
    cases = [
        StabilityCase(f"slide-mu{mu:g}", "friction", SlidingBlock(mu=mu), 1.0)
        for mu in (0.0, 0.1, 0.3, 1.0, 10.0)
    ]
    cases += [
        StabilityCase(f"slide-r1e{e}", "friction-r", SlidingBlock(), 10.0**e)
        for e in range(-8, 13, 4)
    ]
    cases += [
        StabilityCase(f"slide-rt=r-r1e{e}", "friction-r", SlidingBlock(tangential_r_max=None),
                      10.0**e)
        for e in (0, 4)
    ]
    cases += [StabilityCase("slide-reversal", "friction", SlidingBlock(schedule=REVERSAL), 1.0)]
    return cases


def select(cases: Sequence[StabilityCase], names: Sequence[str] | None) -> list[StabilityCase]:
    """Cases whose name or group is in ``names`` (all when None)."""
    if not names:
        return list(cases)
    wanted = set(names)
    chosen = [c for c in cases if c.name in wanted or c.group in wanted]
    known = {c.name for c in cases} | {c.group for c in cases}
    unknown = sorted(wanted - known)
    if unknown:
        raise ValueError(
            f"Unknown stability case(s) {', '.join(unknown)}; groups: "
            f"{', '.join(sorted({c.group for c in cases}))}; e.g. {cases[0].name}."
        )
    return chosen


@dataclass
class CaseRecord(RunRecord):
    """Outcome of one (case, method) run: the run record plus the case; every number finite."""

    case: str = ""
    group: str = ""
    E: float = 0.0
    nu: float = 0.0
    load_steps: int = 0
    max_abs_u: float = 0.0
    atol: float = 0.0
    #: Root mean square of the nodal displacement components (length): a
    #: displacement measure to compare with a reference (max |u| is often
    #: the prescribed value).
    u_rms: float = 0.0

    def row(self) -> dict[str, object]:
        """Flat row; no ``error`` column (the grid has no reference solutions)."""
        d = super().row()
        d.pop("error")
        return d


def _finite(*values: float) -> bool:
    return all(math.isfinite(v) for v in values)


def run_case(
    case: StabilityCase,
    method: str,
    *,
    max_iterations: int = 100,
    max_cutbacks: int = 0,
    force_rtol: float = DEFAULT_FORCE_RTOL,
    out: Path | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> CaseRecord:
    """Run one method on one case; never raises for a solver or model failure."""
    scene = case.scene
    record = CaseRecord(
        status=ERROR, method=method, r_relative=case.r, r_absolute=0.0, case=case.name,
        group=case.group,
        E=float(getattr(scene, "E", 0.0)), nu=float(getattr(scene, "nu", 0.0)),
        load_steps=case.steps,
    )
    steps_file = None if out is None else out / "cases" / f"{case.name}__{method}.json"
    start = time.perf_counter()

    def keep(_: StepRecord) -> None:
        if steps_file is not None:
            write_json(steps_file, {"case": case.name, "method": method,
                                    "steps": [s.to_dict() for s in record.steps]})

    try:
        problem = scene.build(ContactSettings(r=case.r, relative=True), comm)
        atol = scaled_atol(problem, force_rtol)
        strategy = make_strategy(
            method, problem, SolverSettings(atol=atol, max_iterations=max_iterations)
        )
        record = CaseRecord(
            **{**vars(start_record(strategy)), **_case_fields(record)}, atol=atol
        )
        solve_load_path(
            strategy, case.steps, max_cutbacks=max_cutbacks, on_step=keep, record=record
        )
        local_u = float(np.max(np.abs(problem.u.x.array), initial=0.0))
        record.max_abs_u = comm.allreduce(local_u, op=MPI.MAX)
        n_owned = problem.V.dofmap.index_map.size_local * problem.V.dofmap.index_map_bs
        owned = problem.u.x.array[:n_owned]
        total = comm.allreduce(float(np.dot(owned, owned)), op=MPI.SUM)
        record.u_rms = math.sqrt(total / max(comm.allreduce(n_owned, op=MPI.SUM), 1))
        if not _finite(record.max_abs_u, record.u_rms, record.max_penetration,
                       record.contact_force):
            record.status = NONFINITE
            record.max_abs_u = record.u_rms = 0.0
            for step in record.steps:
                step.max_penetration = step.contact_force = 0.0
    except Exception as exc:
        record.status = ERROR
        record.message = f"{type(exc).__name__}: {exc}".splitlines()[0][:200]
        if comm.rank == 0:
            traceback.print_exc()
    record.wall_s = time.perf_counter() - start
    if steps_file is not None:
        write_json(steps_file, {"case": case.name, "method": method, "status": record.status,
                                "steps": [s.to_dict() for s in record.steps]})
    return record


def _case_fields(record: CaseRecord) -> dict[str, object]:
    """The case's own fields of a record (not the run's)."""
    return {k: getattr(record, k) for k in ("case", "group", "E", "nu", "load_steps")}


def run_grid(
    cases: Sequence[StabilityCase],
    methods: Sequence[str],
    *,
    out: Path | None = None,
    progress: Callable[[CaseRecord], None] | None = None,
    **options: float,
) -> list[CaseRecord]:
    """Run every method on every case; ``options`` go to :func:`run_case`."""
    records = []
    for case in cases:
        for method in methods:
            record = run_case(case, method, out=out, **options)
            records.append(record)
            if progress is not None:
                progress(record)
    return records
