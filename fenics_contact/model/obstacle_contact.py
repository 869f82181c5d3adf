"""A contact surface of the solid against a rigid obstacle.

The gap is the obstacle's signed distance at the current position
x = X + u (:mod:`.obstacles`); the obstacle moves with the load factor,
by ``motion`` times t or along a piecewise-linear ``schedule``. With
friction the slip increment over the load step is

    dg_t = T^T [p(x) - p(x_prev + c - c_prev)],

T the tangents of the obstacle normal at x, p the obstacle's closest point
and c its placement (c_prev its value at the last converged step); on a
plane this is T^T [(x - x_prev) - (c - c_prev)]; see :mod:`.friction`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import ufl
from dolfinx import fem

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.contacts import Contact
from fenics_contact.model.friction import FrictionSettings, symmetric_frame
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


def obstacle_offset(motion: np.ndarray, schedule: tuple[np.ndarray, np.ndarray] | None,
                    t: float) -> np.ndarray:
    """An obstacle's displacement at load factor t (length).

    ``t * motion``, or the validated ``schedule`` (:func:`obstacle_schedule`)
    interpolated.
    """
    if schedule is None:
        return t * np.asarray(motion, float)
    times, offsets = schedule
    return np.array([np.interp(t, times, offsets[:, i]) for i in range(offsets.shape[1])])


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
        if self.settings.quadrature == "nodal":
            self.normal_mask = self._held_normal_mask(solid)
        return self.obstacle.gap(x)

    def _held_normal_mask(self, solid) -> fem.Function | None:
        """0 at the nodes whose motion along the obstacle's normal is prescribed.

        The gap of such a node is data (the held components span the
        normal at its reference position: a clamped node, or a node held in
        y on a plane of normal y). In contact the Alart-Curnier row r g = 0
        of that node would have no derivative (a zero Jacobian row: the
        linear solve fails); its pressure is not determined by the contact
        at all but shared with the support, which takes it whole here. None
        when no node is so held (collective).
        """
        from fenics_contact.model.friction import held_components

        domain = solid.domain
        fdim = domain.topology.dim - 1
        W = fem.functionspace(domain, ("Lagrange", 1))
        parent = self.surface.parent_dofs(W)
        n_owned = self.Q.dofmap.index_map.size_local
        held = np.zeros((parent.size, self.gdim), dtype=bool)
        for facets, axis, _ in held_components(solid.prescribed):
            held[np.isin(parent, fem.locate_dofs_topological(W, fdim, facets)), axis] = True
        X = self.Q.tabulate_dof_coordinates()[:n_owned, : self.gdim]
        normal = self.obstacle.normal_value(X)
        spanned = np.sum(np.where(held[:n_owned], normal, 0.0) ** 2, axis=1) >= 1.0 - 1e-8
        if not self.comm.allreduce(int(np.sum(spanned)), op=MPI.SUM):
            return None
        mask = fem.Function(self.Q, name="normal_mask")
        mask.x.array[:] = 1.0
        mask.x.array[:n_owned] = np.where(spanned, 0.0, 1.0)
        mask.x.scatter_forward()
        #: Nodes whose gap a prescribed displacement fixes (global count).
        self.held_nodes = self.comm.allreduce(int(np.sum(spanned)), op=MPI.SUM)
        return mask

    def offset(self, t: float) -> np.ndarray:
        """Obstacle displacement at load factor t: t * motion, or the schedule interpolated."""
        return obstacle_offset(self._motion, self._schedule, t)

    def gap_origin(self) -> np.ndarray:
        """The obstacle's reference point (length): the gap is measured from it."""
        return np.asarray(self.obstacle.point.value, float)

    def set_load(self, t: float) -> None:
        """Place the obstacle at load factor t."""
        self.obstacle.translate_to(self.offset(t))

    def slip_increment(self, u_prev: fem.Function) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """T from the obstacle normal; dg_t = T^T [p(x) - p(x_prev + c - c_prev)].

        p(y) = y - g(y) n(y) is the closest point of the obstacle in its
        current placement; p(x_prev + c - c_prev) is where the node's previous
        closest point has moved with the obstacle. On a plane this is T^T
        [(x - x_prev) - (c - c_prev)]. On a curved obstacle it leaves out the
        node's approach along the normal: the derivative of the frame T then
        acts on a chord of the obstacle (second order in the step) instead of
        on that approach, which gave a node entering contact a friction force
        that the reported traction did not hold (a half cylinder: 0.17 % of the
        support's reaction).
        """
        self.c_prev = fem.Constant(self.domain, np.array(self.obstacle.point.value, dtype=float))
        X = ufl.SpatialCoordinate(self.domain)
        x = X + self.solid.u
        x_prev = X + u_prev
        tangents = symmetric_frame(self.obstacle.normal_at(x), self.gdim, self._held_axes())
        motion = self.obstacle.point - self.c_prev

        def closest(y: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
            return y - self.obstacle.gap(y) * self.obstacle.normal_at(y)

        return tangents, tangents.T * (closest(x) - closest(x_prev + motion))

    def _held_axes(self) -> tuple[fem.Function, fem.Function] | None:
        """The frame's data at nodes held along a tangent that Duff's basis misses (3D).

        At a node held along an axis e_a in the obstacle's tangent plane (at
        load 0) where neither of Duff's tangents is e_a, the frame becomes
        (e_a, n x e_a) (:func:`~.friction.symmetric_frame`), so that the held
        slip is one frame component, which :mod:`.friction_terms` treats.
        Elsewhere, and where Duff's basis already has e_a (a symmetry plane
        through the axis of a ball or a plane), the frame is Duff's. None when
        no node needs it (collective): the forms are then unchanged. A node
        held along the normal keeps no friction (its gap is data:
        :meth:`_held_normal_mask`); one held obliquely is refused when the
        friction terms are built.
        """
        from fenics_contact.model.friction import held_components, tangent_basis_value

        if self.gdim != 3:
            return None  # one tangent: a held axis across the normal is that tangent
        V = self.solid.V
        fdim = V.mesh.topology.dim - 1
        X = V.tabulate_dof_coordinates()
        keep, axis = fem.Function(V, name="frame_keep"), fem.Function(V, name="frame_axis")
        keep.x.array[:] = 1.0
        e = axis.x.array.reshape(-1, 3)
        for facets, a, _ in held_components(self.solid.prescribed):
            blocks = fem.locate_dofs_topological(V, fdim, facets)
            normal = self.obstacle.normal_value(X[blocks])
            across = np.abs(normal[:, a]) < 1e-8
            duff = np.max(np.abs(tangent_basis_value(normal)[:, a, :]), axis=1) >= 1.0 - 1e-8
            pick = blocks[across & ~duff & ~np.any(e[blocks] != 0.0, axis=1)]
            e[pick, a] = 1.0
        if not self.comm.allreduce(int(np.count_nonzero(e)), op=MPI.SUM):
            return None
        axis.x.scatter_forward()
        return keep, axis

    def reference_normals(self) -> np.ndarray:
        """The obstacle's unit normal at each owned multiplier node, load 0, shape (n, gdim)."""
        n = self.Q.dofmap.index_map.size_local
        return self.obstacle.normal_value(self.Q.tabulate_dof_coordinates()[:n, : self.gdim])

    def commit_frame(self) -> None:
        """c_prev <- c."""
        if self.friction is not None:
            self.c_prev.value[:] = self.obstacle.point.value
