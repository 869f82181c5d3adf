"""Coulomb friction with the Alart-Curnier augmented Lagrangian.

Quasi-static and incremental (Alart and Curnier 1991, the paper's reference [4]).
:class:`CoulombFriction` adds the frictional terms to one contact of a
problem; the contact says how the slip increment and the tangent frame are
measured (:meth:`~.contacts.Contact.slip_increment`). The formulas below are
the rigid obstacle's (:mod:`.obstacle_contact`); a deformable target
(:mod:`.pairs`) only changes the slip and the frame.

Signs. The normal part is the frictionless one: the augmented pressure
p_n = min(lam_n + r g, 0) <= 0 and the body receives the traction -p_n n
(n the obstacle's unit normal pointing to the body, the gradient of the gap).
The tangential multiplier lam_t lives on the same P1 contact submesh: one
component in 2D (tangent t = (n_y, -n_x)), two in 3D (an orthonormal basis
built from n without branches on the sign of n_z). With T the gdim x (d-1)
matrix of tangents, the slip increment over the load step is

    dg_t = T^T [(x - x_prev) - (c - c_prev)],

x = X + u, x_prev = X + u_prev (the last converged displacement) and c the
obstacle's placement (c_prev its value at the last converged step). The
augmented tangential traction y = lam_t + r_t dg_t is projected onto the
Coulomb disc of radius rho = -mu p_n >= 0:

    tau = P(y) = y                if |y| < rho   (stick)
               = rho y / |y|      otherwise      (slip, or open when rho = 0).

The momentum residual gains + int tau . d(dg_t)[v] ds, so the body receives
the traction -T tau, which opposes the slip; lam_n and lam_t are thus the
components, in the frame (n, T), of the traction the body exerts on the
obstacle. The multiplier residual is (tau - lam_t) . mu_t ds (force units,
like the normal one): stick gives dg_t = 0 with |lam_t| <= rho, slip gives
|lam_t| = rho with dg_t along lam_t. With the vertex rule these conditions
hold at the nodes whatever r, r_t > 0, so the converged answer depends on
neither.

The tangential parameter is r_t = min(r, tangential_r_max E/L), with L
the extent of the candidate contact surface (diagonal of its bounding box,
reference configuration) and tangential_r_max = 2 by default (Alart and
Curnier keep separate normal and tangential parameters). What bounds r_t is
the tangential stiffness of the body (about E/L per unit area for a
contact zone of size L), not that of one element (E/h): measured on the
sliding block (G/H = E/L = 1000), GNRM converges for r_t = 1 ... 3 E/L on
every mesh from 20x10 to 160x80 and cycles at the first sliding step for
r_t = 4 E/L on 40x20 ... 160x80 (a large r_t makes y the slip of the
current iterate, so the stick/slip guess flips sign between iterates); a
cap of 0.1 E/h grew with refinement past that limit. Below about 0.7 E/L
(fine meshes) it can cycle at partial slip too. :meth:`lower_tangential_r`
halves r_t (a Constant: no recompilation) when a strategy sees the
pattern cycle.

Friction has no potential: the residuals are written directly and the
(unsymmetric) Jacobian is ``ufl.derivative`` of them. The norm |y| is guarded
as sqrt(y . y + eps^2) with eps = 1e-12 E, far below any traction of
interest, so that a node at exactly zero slip gives no NaN in either branch
of the conditional (FFCx evaluates both). With mu = 0 the disc has radius 0,
tau = 0 identically and so do its derivatives: the frictionless system
plus a decoupled lam_t = 0 block.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem, mesh

from mpi4py import MPI

from fenics_contact.model.state import ContactState

#: Guard of the tangential norm relative to E (stress units: eps = GUARD * E).
GUARD = 1e-12

#: Node states of the stick/slip output.
OPEN, STICK, SLIP = 0, 1, 2


def tangent_basis(n: ufl.core.expr.Expr, gdim: int) -> ufl.core.expr.Expr:
    """Matrix T (gdim x (gdim-1)) of unit tangents orthogonal to the unit normal n.

    2D: t = (n_y, -n_x). 3D: the branchless orthonormal basis of Duff et al.
    (2017), s = sign(n_z) with s = 1 at n_z = 0, a = -1/(s + n_z),
    b = n_x n_y a, t1 = (1 + s n_x^2 a, s b, -s n_x), t2 = (b, s + n_y^2 a, -n_y).
    """
    if gdim == 2:
        return ufl.as_matrix([[n[1]], [-n[0]]])
    s = ufl.conditional(ufl.ge(n[2], 0.0), 1.0, -1.0)
    a = -1.0 / (s + n[2])
    b = n[0] * n[1] * a
    t1 = [1.0 + s * n[0] ** 2 * a, s * b, -s * n[0]]
    t2 = [b, s + n[1] ** 2 * a, -n[1]]
    return ufl.as_matrix([[t1[i], t2[i]] for i in range(3)])


def tangent_basis_value(n: np.ndarray) -> np.ndarray:
    """:func:`tangent_basis` in numpy for unit normals of shape (m, 3): shape (m, 3, 2)."""
    s = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (s + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t1 = np.column_stack([1.0 + s * n[:, 0] ** 2 * a, s * b, -s * n[:, 0]])
    t2 = np.column_stack([b, s + n[:, 1] ** 2 * a, -n[:, 1]])
    return np.stack([t1, t2], axis=2)


def symmetry_planes(
    domain: mesh.Mesh, conditions: Sequence[object]
) -> list[tuple[np.ndarray, int]]:
    """(facets, axis) of each Dirichlet condition that is a symmetry plane (collective).

    A condition is one when it holds exactly one displacement component at 0
    (the others free) on facets that all lie in one plane normal to that
    component's axis, e.g. u_y = 0 on the face y = 0 of a half model.
    Conditions on the same plane (one per body of a half model, tagged
    apart) are one plane: their facets are joined.
    """
    x = domain.geometry.x
    fdim = domain.topology.dim - 1
    comm = domain.comm
    span = comm.allreduce(float(np.ptp(x, axis=0).max(initial=0.0)) if x.size else 0.0,
                          op=MPI.MAX) or 1.0
    planes = []
    for condition in conditions:
        if getattr(condition, "path", ()):
            continue
        value = condition.value  # type: ignore[attr-defined]
        held = [i for i, v in enumerate(value) if v is not None]
        if len(held) != 1 or value[held[0]] != 0.0:
            continue
        axis = held[0]
        facets = np.asarray(condition.facets, dtype=np.int32)  # type: ignore[attr-defined]
        nodes = mesh.entities_to_geometry(domain, fdim, facets).ravel() if facets.size else []
        coords = x[nodes, axis] if len(nodes) else np.zeros(0)
        lo = comm.allreduce(float(np.min(coords, initial=np.inf)), op=MPI.MIN)
        hi = comm.allreduce(float(np.max(coords, initial=-np.inf)), op=MPI.MAX)
        if np.isfinite(lo) and hi - lo <= 1e-12 * span:
            planes.append((facets, axis, lo))
    joined: list[tuple[np.ndarray, int, float]] = []
    for facets, axis, where in planes:
        same = next((k for k, (_, a, w) in enumerate(joined)
                     if a == axis and abs(w - where) <= 1e-12 * span), None)
        if same is None:
            joined.append((facets, axis, where))
        else:
            joined[same] = (np.union1d(joined[same][0], facets).astype(np.int32), axis, where)
    return [(facets, axis) for facets, axis, _ in joined]


def held_components(conditions: Sequence[object]) -> list[tuple[np.ndarray, int, str]]:
    """(facets, axis, name) of every displacement component a Dirichlet condition holds.

    ``name``: the condition's name, or its value where it has none.
    """
    out = []
    for condition in conditions:
        value = condition.value  # type: ignore[attr-defined]
        path = getattr(condition, "path", ())
        axes = range(len(path[0]) - 1) if path else [i for i, v in enumerate(value)
                                                      if v is not None]
        facets = np.asarray(condition.facets, dtype=np.int32)  # type: ignore[attr-defined]
        name = getattr(condition, "name", "") or str(list(value))
        out += [(facets, int(a), name) for a in axes]
    return out


def plane_axes(V: fem.FunctionSpace, planes: list[tuple[np.ndarray, int]],
               ) -> tuple[fem.Function, fem.Function] | None:
    """Nodal data of the symmetry planes for a pair's tangent frame (None without planes).

    Returns (keep, axis), two functions of the vector P1 space ``V``: ``keep``
    is 1 but for the component across each plane at the nodes on it (0), and
    ``axis`` is the unit normal of the first plane through a node (0 at nodes
    on none). See :func:`symmetric_frame`.
    """
    if not planes:
        return None
    keep, axis = fem.Function(V, name="plane_keep"), fem.Function(V, name="plane_axis")
    keep.x.array[:] = 1.0
    gdim = V.mesh.geometry.dim
    fdim = V.mesh.topology.dim - 1
    first = np.zeros(keep.x.array.size // gdim, dtype=bool)
    for facets, a in planes:
        blocks = fem.locate_dofs_topological(V, fdim, facets)
        keep.x.array[blocks * gdim + a] = 0.0
        fresh = blocks[~first[blocks]]
        axis.x.array[fresh * gdim + a] = 1.0
        first[blocks] = True
    keep.x.scatter_forward()
    axis.x.scatter_forward()
    return keep, axis


def symmetric_frame(n: ufl.core.expr.Expr, gdim: int,
                    planes: tuple[fem.Function, fem.Function] | None) -> ufl.core.expr.Expr:
    """The tangents of ``n`` (:func:`tangent_basis`), exact at nodes on symmetry planes.

    The normal of a symmetric surface lies in each symmetry plane through it,
    but a faceted target's does not quite (its facets lie on one side of the
    plane). At a node on a plane the frame is built from n with its
    components across the planes removed, and in 3D its first tangent is the
    plane's normal e_a (the second n x e_a), so that the traction across the
    plane is one frame component, which the symmetry constrains to zero.
    Elsewhere it is :func:`tangent_basis` of n. ``planes``: :func:`plane_axes`.
    """
    if planes is None:
        return tangent_basis(n, gdim)
    keep, e = planes
    m = ufl.elem_mult(keep, n)
    n_in = m / ufl.max_value(ufl.sqrt(ufl.dot(m, m)), 1e-300)
    if gdim == 2:
        return tangent_basis(n_in, gdim)
    on = ufl.dot(e, e)  # 1 at nodes on a plane, 0 elsewhere
    second = ufl.cross(n_in, e)
    in_plane = ufl.as_matrix([[e[i], second[i]] for i in range(3)])
    return on * in_plane + (1.0 - on) * tangent_basis(n_in, gdim)


def coulomb_projection(
    y: ufl.core.expr.Expr, rho: ufl.core.expr.Expr, eps: ufl.core.expr.Expr
) -> ufl.core.expr.Expr:
    """Projection of the tangential vector y onto the disc |tau| <= rho (rho >= 0).

    The norm is guarded, |y| ~ sqrt(y . y + eps^2), so that y = 0 gives no NaN
    in either branch or in their derivatives. A node sticks when the guarded
    norm is below rho by more than eps (:func:`sticks`).
    """
    norm = ufl.sqrt(ufl.dot(y, y) + eps**2)
    return ufl.conditional(ufl.lt(norm + eps, rho), 1.0, rho / norm) * y


def sticks(y: np.ndarray, rho: np.ndarray, eps: float) -> np.ndarray:
    """Whether nodes with trial tractions y (n, d-1) and radii rho (n,) stick.

    The rule of :func:`coulomb_projection`: sqrt(|y|^2 + eps^2) + eps < rho.
    The margin eps settles the tie |y| = rho, where every node that slipped
    in the last step starts the next one (its slip increment is 0 there, so
    y = lam_t and |lam_t| = rho up to round-off): the node slips, whatever
    the round-off (which depends on the number of processes).
    """
    return np.sqrt(np.sum(y**2, axis=1) + eps**2) + eps < rho


def surface_extent(submesh: mesh.Mesh) -> float:
    """Diagonal of the bounding box of a (contact) submesh, global over ranks (length)."""
    x = submesh.geometry.x
    comm = submesh.comm
    low, high = np.min(x, axis=0, initial=np.inf), np.max(x, axis=0, initial=-np.inf)
    comm.Allreduce(MPI.IN_PLACE, low, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, high, op=MPI.MAX)
    return float(np.linalg.norm(high - low))


@dataclass(frozen=True)
class FrictionalContactState(ContactState):
    """Nodal contact diagnostics with the tangential part.

    Attributes:
        tangential_traction: nodal tau (owned nodes, shape (n, d-1), stress):
            the tangential traction the body exerts on the obstacle in the
            frame T; the body receives -T tau.
        slip: nodal slip increment dg_t over the load step (shape (n, d-1), length).
        coulomb_limit: nodal disc radius rho = -mu p_n (stress).
        node_state: 0 open, 1 stick, 2 slip, per owned node.
        tangential_force: global |int T tau dA| (force; per thickness in 2D).
        tangential_magnitude: global int |tau| dA (force): each node's traction
            in its own frame, so mu times the normal force where every node slips,
            whatever the tilt of the contact surface.
        stick_count: global number of sticking contact nodes.
        slip_count: global number of slipping contact nodes.
    """

    tangential_traction: np.ndarray = field(default_factory=lambda: np.zeros((0, 1)))
    slip: np.ndarray = field(default_factory=lambda: np.zeros((0, 1)))
    coulomb_limit: np.ndarray = field(default_factory=lambda: np.zeros(0))
    node_state: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int8))
    tangential_magnitude: float = 0.0

    def summary(self) -> dict[str, float | int]:
        """The normal summary plus ``tangential_magnitude`` (for a step's record)."""
        return {**super().summary(), "tangential_magnitude": self.tangential_magnitude}


def check_friction(mu: float, tangential_r_max: float | None) -> None:
    """Raise ValueError naming a bad friction coefficient or tangential cap."""
    if not (np.isfinite(mu) and mu >= 0):
        raise ValueError(
            f"The friction coefficient mu must be finite and >= 0, got mu = {mu}; "
            "use 0 for frictionless contact, typical values are 0.1 to 1."
        )
    if tangential_r_max is not None and not (
        np.isfinite(tangential_r_max) and tangential_r_max > 0
    ):
        raise ValueError(
            f"tangential_r_max must be finite and > 0 (relative to E/L, L the extent of "
            f"the contact surface), got {tangential_r_max}; None makes r_t = r."
        )


@dataclass(frozen=True)
class FrictionSettings:
    """Coulomb friction of one contact.

    Attributes:
        mu: the friction coefficient (dimensionless, >= 0).
        tangential_r_max: cap of the tangential parameter, r_t = min(r,
            tangential_r_max E/L) with L the extent of the candidate contact
            surface; None makes r_t = r.
    """

    mu: float
    tangential_r_max: float | None = 2.0

    def __post_init__(self) -> None:
        check_friction(self.mu, self.tangential_r_max)


