"""Stability at the extremes: a grid of hard cases, every one ending with a status.

Each case is a scene with one knob at an extreme (``fenics-contact stability
SCENE... --r ...`` runs given scenes at given r; the project's own grid of
extremes, r from 1e-8 to 1e12 E/h, E from 1e-3 to 1e12, nu to 0.4999, steps,
starts, meshes, friction and pairs, is ``benchmarks/robustness/stability_grid.py``).

Besides status, iterations and forces, a run records its friction
coefficient, F_t / (mu N) at the last step, and, from :func:`run_grid`, how
far its answer (N, F_t, rms displacement) is from the reference answer of
the same scene: GNRM at r = 1 E/h (``auto`` there when GNRM fails). A
"converged" run whose answer is off by more than :data:`REFERENCE_RTOL` is
a false convergence: its ``outcome`` is :data:`OFF_REFERENCE` (with the
deviation in tables), drawn in its own colour. Where the stopping tolerance
is a sizeable share of the reference's contact force (:data:`LOOSE_ATOL_SHARE`;
at huge r the round-off floor), :func:`loose_tolerances` names it.

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
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from mpi4py import MPI

from fenics_contact.model.scaling import DEFAULT_FORCE_RTOL, scaled_atol
from fenics_contact.output.io import write_json
from fenics_contact.scene.spec import Scene
from fenics_contact.solvers import STRATEGIES, make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings, Status
from fenics_contact.solvers.stepping import RunRecord, StepRecord, solve_load_path, start_record
from fenics_contact.sweeps.cases import Case, build_case, case_steps
from fenics_contact.sweeps.coulomb import coulomb_ratio, coulomb_terms

#: Methods the stability grid runs by default.
METHODS = tuple(STRATEGIES)

#: Extra statuses of a run besides the solver statuses: an exception (with
#: its message in ``CaseRecord.message``) and non-finite outputs.
ERROR = Status.ERROR.value
NONFINITE = "nonfinite"
#: Methods tried in turn, at r = 1 E/h, for the reference answer of a scene.
REFERENCE_METHODS = ("gnrm", "auto")
#: Largest relative deviation from the reference answer that counts as reaching it.
REFERENCE_RTOL = 1e-6
#: Outcome of a converged run that does not reach the reference within REFERENCE_RTOL.
OFF_REFERENCE = "converged, off the reference"
#: Stopping tolerances above this share of the reference's contact force are named.
LOOSE_ATOL_SHARE = 1e-2


@dataclass(frozen=True)
class StabilityCase:
    """One extreme: a scene (with one knob at an extreme) and r relative to E/h."""

    name: str
    group: str
    scene: Case
    r: float = 1.0

    @property
    def steps(self) -> int:
        """Load steps of the scene."""
        return case_steps(self.scene)


def scene_cases(
    scenes: Sequence[Scene], r_values: Sequence[float] = (1.0,), group: str = "scene"
) -> list[StabilityCase]:
    """Every scene at every r (relative to E/h): cases named ``<scene>-r<r>``."""
    return [StabilityCase(f"{scene.name}-r{r:g}", group, scene, r)
            for scene in scenes for r in r_values]


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
    #: Coulomb coefficient (None without friction; the first frictional contact's).
    mu: float | None = None
    #: Each frictional contact's mu by name (F_t / (mu N) is taken over them).
    mus: dict[str, float] = field(default_factory=dict)
    #: Where the reference answer came from ("gnrm r=1"; empty: none).
    reference: str = ""
    #: Largest relative deviation of N, F_t (both relative to the reference N)
    #: and u_rms from the reference answer (None: no reference or not converged).
    reference_deviation: float | None = None
    #: The reference's normal contact force (force; None: no reference).
    reference_force: float | None = None

    @property
    def tangential_force(self) -> float:
        """Tangential contact force at the last step attempted (force)."""
        return self.steps[-1].tangential_force if self.steps else 0.0

    @property
    def tangential_magnitude(self) -> float | None:
        """F_t of ft_ratio: int |t| dA over the frictional contacts at the last step (force).

        None without friction.
        """
        if not self.mus or not self.steps:
            return None
        return coulomb_terms(self.steps[-1], self.mus)[0]

    @property
    def mu_normal_force(self) -> float | None:
        """The mu N of ft_ratio: sum of mu_c N_c over the frictional contacts (force).

        None without friction.
        """
        if not self.mus or not self.steps:
            return None
        return coulomb_terms(self.steps[-1], self.mus)[1]

    @property
    def ft_ratio(self) -> float | None:
        """F_t / (mu N) at the last step attempted over the frictional contacts (1: full slip).

        None without friction or load. Each frictional contact counts with its own mu;
        frictionless ones (a wall) are left out (:func:`~.coulomb.coulomb_ratio`).
        """
        if not self.mus or not self.steps:
            return None
        ratio = coulomb_ratio(self.steps[-1], self.mus)
        return None if math.isnan(ratio) else ratio

    @property
    def atol_share(self) -> float | None:
        """The stopping tolerance over the reference's contact force (None: no reference force)."""
        if not self.reference_force:
            return None
        return self.atol / abs(self.reference_force)

    @property
    def outcome(self) -> str:
        """The status, or :data:`OFF_REFERENCE` for a converged run that missed the reference."""
        if self.converged and self.reference_reached is False:
            return OFF_REFERENCE
        return self.status

    def outcome_text(self) -> str:
        """The outcome in words, with the deviation from the reference when off it."""
        if self.outcome != OFF_REFERENCE:
            return self.outcome
        return f"{OFF_REFERENCE} by {self.reference_deviation:.1e}"

    @property
    def reference_reached(self) -> bool | None:
        """Converged to the reference answer within REFERENCE_RTOL (None: no reference)."""
        if not self.reference:
            return None
        return self.reference_deviation is not None and (
            self.reference_deviation <= REFERENCE_RTOL
        )

    def row(self) -> dict[str, object]:
        """Flat row; the reference deviation instead of the ``error`` column."""
        d = super().row()
        d.pop("error")
        d.update(tangential_force=self.tangential_force,
                 tangential_magnitude=self.tangential_magnitude,
                 mu_normal_force=self.mu_normal_force, ft_ratio=self.ft_ratio,
                 reference_reached=self.reference_reached, outcome=self.outcome_text(),
                 atol_share=self.atol_share)
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
    contact_set: str = "sign",
    out: Path | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> CaseRecord:
    """Run one method on one case; never raises for a solver or model failure.

    ``contact_set``: how each Newton step chooses its contact set ("sign",
    the paper's GNRM, or "exact", a scene's default; see make_strategy).
    """
    scene = case.scene
    record = CaseRecord(
        status=ERROR, method=method, r_relative=case.r, r_absolute=0.0, case=case.name,
        group=case.group,
        E=float(scene.E) if isinstance(scene, Scene) else 0.0,
        nu=float(scene.nu) if isinstance(scene, Scene) else 0.0,
        load_steps=case.steps,
    )
    steps_file = None if out is None else out / "cases" / f"{case.name}__{method}.json"
    start = time.perf_counter()

    def keep(_: StepRecord) -> None:
        if steps_file is not None:
            write_json(steps_file, {"case": case.name, "method": method,
                                    "steps": [s.to_dict() for s in record.steps]})

    try:
        problem = build_case(scene, case.r, True, None, comm)
        record.mu = problem.friction_coefficient if problem.frictional else None
        record.mus = problem.friction_coefficients() if problem.frictional else {}
        atol = scaled_atol(problem, force_rtol)
        strategy = make_strategy(
            method, problem, SolverSettings(atol=atol, max_iterations=max_iterations),
            contact_set=contact_set,
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
    return {k: getattr(record, k)
            for k in ("case", "group", "E", "nu", "load_steps", "mu", "mus")}


def deviation(record: CaseRecord, reference: CaseRecord) -> float | None:
    """Largest relative deviation of N, F_t and u_rms from ``reference`` (None: not converged).

    Forces are measured against the reference N (at least its stopping
    tolerance, for a case without contact), u_rms against its own reference.
    """
    if not record.converged:
        return None
    force_scale = max(abs(reference.contact_force), reference.atol, 1e-300)
    u_scale = max(reference.u_rms, 1e-300)
    return max(abs(record.contact_force - reference.contact_force) / force_scale,
               abs(record.tangential_force - reference.tangential_force) / force_scale,
               abs(record.u_rms - reference.u_rms) / u_scale)


def _reference_runs(
    case: StabilityCase, out: Path | None, **options: float
) -> dict[str, CaseRecord]:
    """REFERENCE_METHODS at r = 1 E/h on the case's scene, in turn until one converges.

    The runs of a case at r = 1 E/h are its own runs and write their step records.
    """
    runs = {}
    for method in REFERENCE_METHODS:
        runs[method] = run_case(replace(case, r=1.0), method,
                                out=out if case.r == 1.0 else None, **options)
        if runs[method].converged:
            break
    return runs


def run_grid(
    cases: Sequence[StabilityCase],
    methods: Sequence[str],
    *,
    out: Path | None = None,
    progress: Callable[[CaseRecord], None] | None = None,
    reference: bool = True,
    **options: float,
) -> list[CaseRecord]:
    """Run every method on every case; ``options`` go to :func:`run_case`.

    With ``reference``, each record gets its deviation from the reference
    answer of its scene (:data:`REFERENCE_METHODS` at r = 1 E/h, run once per
    scene; a case at r = 1 E/h that first needs the reference keeps those
    runs as its own runs of these methods).
    """
    records = []
    references: dict[str, tuple[str, dict[str, CaseRecord]]] = {}
    for case in cases:
        owner, runs, ref = "", {}, None
        if reference:
            key = repr(case.scene)
            if key not in references:
                references[key] = (case.name, _reference_runs(case, out, **options))
            owner, runs = references[key]
            ref = next((r for r in runs.values() if r.converged), None)
        for method in methods:
            own = case.r == 1.0 and owner == case.name and method in runs
            record = runs[method] if own else run_case(case, method, out=out, **options)
            if ref is not None:
                record.reference = f"{ref.method} r=1"
                record.reference_deviation = deviation(record, ref)
                record.reference_force = ref.contact_force
            records.append(record)
            if progress is not None:
                progress(record)
    return records


def loose_tolerances(records: Sequence[CaseRecord]) -> list[str]:
    """One line per case whose stopping tolerance exceeds LOOSE_ATOL_SHARE of the contact force.

    Such a tolerance lets a run stop that far from the answer (at huge r the
    round-off floor sets it): the atol, the reference's force and the share.
    """
    lines = {}
    for rec in records:
        share = rec.atol_share
        if share is not None and share > LOOSE_ATOL_SHARE:
            lines[rec.case] = (f"{rec.case}: atol = {rec.atol:.3g} is {100 * share:.0f} % of the "
                               f"reference's contact force {abs(rec.reference_force):.3g}")
    return list(lines.values())
