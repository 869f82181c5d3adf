"""A contact surface of the solid against a rigid obstacle.

The gap is the obstacle's signed distance at the current position
x = X + u (:mod:`.obstacles`); the obstacle moves with the load factor,
by ``motion`` times t or along a piecewise-linear ``schedule``. With
friction the slip increment over the load step is

    dg_t = T^T [(x - x_prev) - (c - c_prev)],

T the tangents of the obstacle normal at x and c the obstacle's placement
(c_prev its value at the last converged step); see :mod:`.friction`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import ufl
from dolfinx import fem

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.contacts import Contact
from fenics_contact.model.friction import FrictionSettings, tangent_basis
from fenics_contact.model.obstacles import RigidObstacle


def obstacle_schedule(
    rows: Sequence[Sequence[float]] | None, gdim: int
) -> tuple[np.ndarray, np.ndarray] | None:
    """Validate a piecewise-linear obstacle schedule: rows (t, offset...), t from 0 to 1."""
    if rows is None:
        return None
    table = np.asarray(rows, dtype=float)
    if table.ndim != 2 or table.shape[1] != gdim + 1 or table.shape[0] < 2:
        raise ValueError(
            f"An obstacle schedule needs at least two rows of {gdim + 1} numbers "
            f"(load factor, then the {gdim} offset components); got shape {table.shape}."
        )
    times = table[:, 0]
    if not (np.all(np.isfinite(table)) and times[0] == 0.0 and times[-1] == 1.0
            and np.all(np.diff(times) > 0)):
        raise ValueError(
            f"Obstacle schedule load factors {times.tolist()} must be finite, strictly "
            "increasing, start at 0 and end at 1."
        )
    return times, table[:, 1:]


class ObstacleContact(Contact):
    """Candidate facets of the solid against a rigid obstacle.

    Args:
        obstacle: the obstacle (placed by Constants on the solid's mesh).
        facets: local indices of the candidate contact facets.
        settings: r, its scale and the quadrature.
        motion: obstacle displacement at load factor 1 (moved by t * motion).
        schedule: rows (t, offset...) of a piecewise-linear motion instead.
        friction: Coulomb friction (None: frictionless).
        body: the body whose law sets the r scale E/h (default: the first).
        name: label in outputs.
    """

    held_slip_is_data = True

    def __init__(
        self,
        obstacle: RigidObstacle,
        facets: np.ndarray,
        settings: ContactSettings,
        *,
        motion: Sequence[float] | None = None,
        schedule: Sequence[Sequence[float]] | None = None,
        friction: FrictionSettings | None = None,
        body: str | None = None,
        name: str = "obstacle",
    ) -> None:
        super().__init__(facets, settings, friction=friction, name=name)
        self.obstacle = obstacle
        gdim = obstacle.point.value.size
        self._motion = np.zeros(gdim) if motion is None else np.asarray(motion, float)
        self._schedule = obstacle_schedule(schedule, gdim)
        self._body = body

    def _bind_partner(self, solid) -> ufl.core.expr.Expr:
        law = solid.stiffest if self._body is None else solid.material_of(self._body)
        self.modulus = law.E
        x = ufl.SpatialCoordinate(solid.domain) + solid.u
        return self.obstacle.gap(x)

    def offset(self, t: float) -> np.ndarray:
        """Obstacle displacement at load factor t: t * motion, or the schedule interpolated."""
        if self._schedule is None:
            return t * self._motion
        times, offsets = self._schedule
        return np.array([np.interp(t, times, offsets[:, i]) for i in range(offsets.shape[1])])

    def gap_origin(self) -> np.ndarray:
        """The obstacle's reference point (length): the gap is measured from it."""
        return np.asarray(self.obstacle.point.value, float)

    def set_load(self, t: float) -> None:
        """Place the obstacle at load factor t."""
        self.obstacle.translate_to(self.offset(t))

    def slip_increment(self, u_prev: fem.Function) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """T from the obstacle normal; dg_t = T^T [(x - x_prev) - (c - c_prev)]."""
        self.c_prev = fem.Constant(self.domain, np.array(self.obstacle.point.value, dtype=float))
        X = ufl.SpatialCoordinate(self.domain)
        x = X + self.solid.u
        x_prev = X + u_prev
        tangents = tangent_basis(self.obstacle.normal_at(x), self.gdim)
        motion = self.obstacle.point - self.c_prev
        return tangents, tangents.T * ((x - x_prev) - motion)

    def commit_frame(self) -> None:
        """c_prev <- c."""
        if self.friction is not None:
            self.c_prev.value[:] = self.obstacle.point.value
