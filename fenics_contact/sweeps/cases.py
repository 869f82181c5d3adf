"""What a sweep runs: a scene, at any r and quadrature, or a problem a scene cannot state.

Every case of the sweeps is a validated :class:`~fenics_contact.scene.spec.Scene`,
built with r (relative to E/h, or absolute) put on every contact. The one
exception the project keeps is the paper's Example 1 (a striker node moved
along a prescribed path onto one element): a :class:`CustomProblem` with its
own builder.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings, Quadrature
from fenics_contact.model.problem import ContactProblem
from fenics_contact.scene.build import build_problem
from fenics_contact.scene.spec import Scene
from fenics_contact.scene.variants import with_contact_settings

#: A scalar a study reads off a solved problem (e.g. a corner displacement).
Probe = Callable[[ContactProblem], float]


class CustomProblem(Protocol):
    """A problem no scene states: its load steps and a builder."""

    steps: int

    def build(self, settings: ContactSettings, comm: MPI.Comm = ...) -> ContactProblem:
        """Create the problem with these contact settings."""
        ...


Case = Scene | CustomProblem


def build_case(
    case: Case, r: float, relative: bool, quadrature: Quadrature | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> ContactProblem:
    """The case's problem with r on every contact (``quadrature`` None: each contact's own)."""
    if isinstance(case, Scene):
        return build_problem(with_contact_settings(case, r, relative, quadrature), comm)
    return case.build(ContactSettings(r=r, relative=relative, quadrature=quadrature or "nodal"),
                      comm)


def case_steps(case: Case) -> int:
    """Load steps of the case."""
    return case.solver.steps if isinstance(case, Scene) else int(case.steps)


def case_name(case: Case) -> str:
    """The case's name (the scene's, or the custom problem's class)."""
    return case.name if isinstance(case, Scene) else type(case).__name__
