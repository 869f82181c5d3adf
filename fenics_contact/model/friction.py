"""Coulomb friction with the Alart-Curnier augmented Lagrangian.

Quasi-static and incremental (Alart and Curnier 1991, the paper's reference [4]).
:class:`FrictionMixin` holds what every frictional problem shares; this module
applies it to rigid obstacles (:class:`FrictionalContactProblem`) and
:mod:`.pair_friction` to two deformable bodies. The formulas below are the
rigid ones; the deformable target only changes the slip and the frame.

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
from dolfinx import default_scalar_type, fem, mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSurface, assemble_local
from fenics_contact.model.problem import (
    ContactProblem,
    ContactState,
    ProblemState,
    VariationalSystem,
    Work,
)

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


def symmetry_planes(
    domain: mesh.Mesh, conditions: Sequence[object]
) -> list[tuple[np.ndarray, int]]:
    """(facets, axis) of each Dirichlet condition that is a symmetry plane (collective).

    A condition is one when it holds exactly one displacement component at 0
    (the others free) on facets that all lie in one plane normal to that
    component's axis, e.g. u_y = 0 on the face y = 0 of a half model.
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
            planes.append((facets, axis))
    return planes


def coulomb_projection(
    y: ufl.core.expr.Expr, rho: ufl.core.expr.Expr, eps: ufl.core.expr.Expr
) -> ufl.core.expr.Expr:
    """Projection of the tangential vector y onto the disc |tau| <= rho (rho >= 0).

    The norm is guarded, |y| ~ sqrt(y . y + eps^2), so that y = 0 gives no NaN
    in either branch or in their derivatives.
    """
    norm = ufl.sqrt(ufl.dot(y, y) + eps**2)
    return ufl.conditional(ufl.lt(norm, rho), 1.0, rho / norm) * y


def surface_extent(submesh: mesh.Mesh) -> float:
    """Diagonal of the bounding box of a (contact) submesh, global over ranks (length)."""
    x = submesh.geometry.x
    comm = submesh.comm
    low, high = np.min(x, axis=0, initial=np.inf), np.max(x, axis=0, initial=-np.inf)
    comm.Allreduce(MPI.IN_PLACE, low, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, high, op=MPI.MAX)
    return float(np.linalg.norm(high - low))


@dataclass(frozen=True)
class FrictionalProblemState(ProblemState):
    """A snapshot that also holds the tangential multiplier (stress)."""

    lam_t: np.ndarray = field(default_factory=lambda: np.zeros(0))


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


class FrictionMixin:
    """Coulomb friction on top of a contact problem (rigid obstacle or deformable pair).

    The host problem provides u, lam, r, the gap, the augmented pressure, the
    contact surface and the systems builder ``_system``; the subclass says
    how the slip increment and the tangent frame are measured
    (:meth:`_slip_increment`) and what else moves forward at :meth:`commit`
    (:meth:`_commit_frame`). This class holds the tangential multiplier
    lam_t, the last converged displacement u_prev, the projected traction,
    the frictional systems and the nodal diagnostics.
    """

    frictional = True
    domain: object
    comm: MPI.Comm
    surface: ContactSurface
    u: fem.Function
    lam: fem.Function
    Q: fem.FunctionSpace
    V: fem.FunctionSpace
    r: fem.Constant
    pressure: ufl.core.expr.Expr
    gap: ufl.core.expr.Expr

    def __init__(
        self, *args, mu: float, tangential_r_max: float | None = 2.0, **kwargs
    ) -> None:
        """Check mu and the cap, build the host problem, then the friction terms."""
        check_friction(mu, tangential_r_max)
        super().__init__(*args, **kwargs)
        self._init_friction(mu, tangential_r_max)

    def _init_friction(self, mu: float, tangential_r_max: float | None) -> None:
        """Create lam_t, u_prev, the slip, the projected traction and the nodal forms."""
        domain = self.domain
        gdim = domain.geometry.dim
        self.gdim = gdim
        self.mu = fem.Constant(domain, default_scalar_type(mu))
        self.eps = fem.Constant(domain, default_scalar_type(GUARD * self.material.E))
        if gdim == 2:
            self.Qt = self.Q
            self.lam_t = fem.Function(self.Qt, name="tangential_multiplier")
            lam_t = ufl.as_vector([self.lam_t])
        else:
            self.Qt = fem.functionspace(self.surface.submesh, ("Lagrange", 1, (gdim - 1,)))
            self.lam_t = fem.Function(self.Qt, name="tangential_multiplier")
            lam_t = self.lam_t
        self.u_prev = fem.Function(self.V, name="displacement_prev")
        self.tangents, self.slip = self._slip_increment()
        #: 1 per tangential component, 0 where a symmetry plane through the contact
        #: zone makes the traction's component across the plane vanish.
        self.symmetry_mask = fem.Function(self.Qt, name="symmetry_mask")
        self.symmetry_mask.x.array[:] = 1.0
        mask = ufl.as_vector([self.symmetry_mask]) if gdim == 2 else self.symmetry_mask
        #: Extent L of the candidate contact surface (length).
        self.contact_extent = surface_extent(self.surface.submesh)
        #: Tangential parameter r_t = min(r, r_t_cap), r_t_cap = tangential_r_max E/L
        #: (stress/length, E the modulus of the r scale); follows r when a strategy
        #: changes it.
        modulus = self.stiffness_scale * self.surface.h  # type: ignore[attr-defined]
        cap = (np.inf if tangential_r_max is None
               else tangential_r_max * modulus / self.contact_extent)
        self.r_t_cap = fem.Constant(domain, default_scalar_type(cap))
        self.r_t: ufl.core.expr.Expr = ufl.min_value(self.r, self.r_t_cap)
        self.trial_traction = lam_t + self.r_t * self.slip
        self.coulomb_radius = -self.mu * self.pressure
        self.traction_t = ufl.elem_mult(
            mask, coulomb_projection(self.trial_traction, self.coulomb_radius, self.eps)
        )
        self._lam_t_vector = lam_t
        # penalty: regularised stick on the committed traction, rho = mu r max(-g, 0)
        self._penalty_radius = -self.mu * ufl.min_value(self.r * self.gap, 0.0)
        self.penalty_traction = ufl.elem_mult(
            mask, coulomb_projection(self.trial_traction, self._penalty_radius, self.eps)
        )

        k = gdim - 1
        nodal = self.surface.nodal_form
        self._tau_forms = [nodal(self.traction_t[i]) for i in range(k)]
        self._pen_forms = [nodal(self.penalty_traction[i]) for i in range(k)]
        self._slip_forms = [nodal(self.slip[i]) for i in range(k)]
        self._y_forms = [nodal(self.trial_traction[i]) for i in range(k)]
        self._rho_form = nodal(self.coulomb_radius)
        self._global_forms = [
            [nodal(-(self.tangents * self.traction_t)[i]) for i in range(gdim)],
            [nodal((self.tangents * self.slip)[i]) for i in range(gdim)],
        ]
        force = self.tangents * self.traction_t
        self._tforce_forms = [
            fem.form(force[i] * self.surface.ds, entity_maps=self.surface.entity_maps)
            for i in range(gdim)
        ]
        self._tmag_form = fem.form(
            ufl.sqrt(ufl.dot(self.traction_t, self.traction_t)) * self.surface.ds,
            entity_maps=self.surface.entity_maps,
        )
        self.symmetry_constraints = self._constrain_symmetry_planes()

    def _constrain_symmetry_planes(self) -> int:
        """Zero the traction across every symmetry plane at the contact nodes it holds.

        A symmetry plane is a Dirichlet condition holding one displacement
        component at 0 on a plane of facets normal to that axis (see
        :func:`symmetry_planes`). At a contact node on it the slip across the
        plane vanishes identically, so a sticking node would leave the
        tangential multiplier's component across the plane undetermined (a
        singular Jacobian); by symmetry that traction component is zero, and
        :attr:`symmetry_mask` makes it so (residual row lam_t,k = 0, no force).
        The frame component along the plane's normal is found from the nodal
        tangents; a frame not aligned with the plane is refused. Returns the
        number of constrained (node, component) pairs (global).
        """
        conditions = [c for _, c, _ in self._bc_constants]  # type: ignore[attr-defined]
        planes = symmetry_planes(self.domain, conditions)
        if not planes:
            return 0
        fdim = self.domain.topology.dim - 1
        W = fem.functionspace(self.domain, ("Lagrange", 1))
        parent = self.surface.parent_dofs(W)
        n_owned = self.Q.dofmap.index_map.size_local
        k = self.gdim - 1
        self.refresh_search()  # type: ignore[attr-defined]
        frame = np.stack([
            np.column_stack([self.surface.nodal(self.surface.nodal_form(self.tangents[i, j]))
                             for j in range(k)])
            for i in range(self.gdim)
        ], axis=1)  # (owned nodes, gdim, d-1)
        count = 0
        for facets, axis in planes:
            held = fem.locate_dofs_topological(W, fdim, facets)
            nodes = np.flatnonzero(np.isin(parent[:n_owned], held))
            along = np.abs(frame[nodes, axis, :])
            j = np.argmax(along, axis=1) if nodes.size else np.zeros(0, int)
            worst = float(np.min(along[np.arange(nodes.size), j], initial=1.0))
            worst = self.comm.allreduce(worst, op=MPI.MIN)
            if worst < 1.0 - 1e-8:
                raise ValueError(
                    f"A symmetry plane (u_{'xyz'[axis]} = 0 on a plane normal to "
                    f"{'xyz'[axis]}) crosses the frictional contact surface where the contact "
                    f"normal is not in the plane (|t . e_{'xyz'[axis]}| = {worst:.3g}); a "
                    "symmetry cut needs the contact normal in the plane there."
                )
            self.symmetry_mask.x.array[nodes * k + j] = 0.0
            count += self.comm.allreduce(int(nodes.size), op=MPI.SUM)
        self.symmetry_mask.x.scatter_forward()
        return count

    def _slip_increment(self) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """(T, dg_t): the gdim x (d-1) tangent matrix and the slip increment (length)."""
        raise NotImplementedError

    def _commit_frame(self) -> None:
        """Move the reference of the slip forward with u_prev (obstacle, target)."""

    # -- state ----------------------------------------------------------------------
    @property
    def friction_coefficient(self) -> float:
        """The Coulomb coefficient mu (dimensionless)."""
        return float(self.mu.value)

    def commit(self) -> None:
        """Accept the converged increment: u_prev <- u and the reference of the slip.

        When the penalty method solves the problem (``multiplier_is_pressure``
        False) the committed tangential traction is kept in lam_t (the
        regularised-stick history); AL methods already hold it there, and so
        does ``auto`` after a penalty warm start (it only borrows the system).
        """
        if not self.multiplier_is_pressure:
            self._set_lam_t(self._nodal_components(self._pen_forms))
        self.u_prev.x.array[:] = self.u.x.array
        self._commit_frame()

    def snapshot(self) -> FrictionalProblemState:
        """Copy u, lam_n, lam_t and the load factor."""
        return FrictionalProblemState(
            self.u.x.array.copy(), self.lam.x.array.copy(), self.load_factor,
            self.lam_t.x.array.copy(),
        )

    def restore(self, state: ProblemState, *, load: bool = True) -> None:
        """Put back a :meth:`snapshot` (lam_t too when the snapshot holds it)."""
        super().restore(state, load=load)  # type: ignore[misc]
        if isinstance(state, FrictionalProblemState) and state.lam_t.size:
            self.lam_t.x.array[:] = state.lam_t

    @property
    def tangential_r(self) -> float:
        """The current tangential parameter r_t = min(r, cap) (stress per length)."""
        return min(self.r_absolute, float(self.r_t_cap.value))

    @property
    def tangential_cap(self) -> float:
        """The cap of r_t (stress per length; inf when r_t = r)."""
        return float(self.r_t_cap.value)

    def set_tangential_cap(self, cap: float) -> None:
        """Set the cap of r_t (absolute, stress per length; inf: r_t = r). No recompilation."""
        if not cap > 0:
            raise ValueError(f"The cap of r_t must be > 0 (stress per length), got {cap}.")
        self.r_t_cap.value = cap

    def lower_tangential_r(self, factor: float = 0.5) -> float:
        """Cap r_t at ``factor`` times its current value; return the new r_t (stress/length).

        The converged nodal answer does not depend on r_t; a smaller r_t
        keeps the stick/slip guess from flipping (see the module notes).
        """
        self.set_tangential_cap(factor * self.tangential_r)
        return self.tangential_r

    # -- systems -----------------------------------------------------------------------
    def _friction_work(self, traction: ufl.core.expr.Expr) -> Work:
        """(c, test) -> int traction . d(dg_t)/dc[test] ds, for u and every extra c.

        The body (and, for a deformable target, the target's vertices through
        the derivative with respect to w_k) receives the friction force.
        """

        def work(c: fem.Function, test: ufl.Argument) -> ufl.Form:
            return ufl.dot(traction, ufl.derivative(self.slip, c, test)) * self.surface.ds

        return work

    def _tangential_residual(self) -> ufl.Form:
        """(P(lam_t + r_t dg_t) - lam_t) . mu_t ds (force units)."""
        mu_t = ufl.TestFunction(self.Qt)
        mu_t = ufl.as_vector([mu_t]) if self.gdim == 2 else mu_t
        return ufl.dot(self.traction_t - self._lam_t_vector, mu_t) * self.surface.ds

    def augmented_system(self) -> VariationalSystem:
        """Newton on (u, lam_n, lam_t): the frictional GNRM system.

        Multiplier blocks: (min(lam_n + r g, 0) - lam_n) mu_n and
        (P(lam_t + r_t dg_t) - lam_t) . mu_t, both in force units.
        """
        return self._system(  # type: ignore[attr-defined]
            "augmented_friction", self._lagrangian(), with_lam=True,  # type: ignore[attr-defined]
            work=self._friction_work(self.traction_t),
            multipliers=[(self.lam_t, self._tangential_residual())],
        )

    def primal_system(self) -> VariationalSystem:
        """Equilibrium in u with lam_n and lam_t held fixed (Uzawa inner problem)."""
        return self._system(  # type: ignore[attr-defined]
            "primal_friction", self._lagrangian(), with_lam=False,  # type: ignore[attr-defined]
            work=self._friction_work(self.traction_t),
        )

    def penalty_system(self) -> VariationalSystem:
        """Penalty in u: normal r/2 min(g, 0)^2, tangential tau = P(lam_t + r_t dg_t).

        The disc radius is mu r max(-g, 0); lam_t holds the traction committed
        at the last converged step (regularised stick, updated by :meth:`commit`).
        """
        return self._system(  # type: ignore[attr-defined]
            "penalty_friction", self._penalty_energy(),  # type: ignore[attr-defined]
            with_lam=False, work=self._friction_work(self.penalty_traction),
        )

    def complementarity_residual(self) -> list[ufl.Form]:  # type: ignore[override]
        """Normal and tangential complementarity residuals (force units)."""
        return [super().complementarity_residual(), self._tangential_residual()]  # type: ignore[misc]

    # -- nodal values and diagnostics ------------------------------------------------------
    def _nodal_components(self, forms: Sequence[fem.Form]) -> np.ndarray:
        """Owned nodal values of a (d-1)-vector expression, shape (n, d-1)."""
        self.refresh_search()  # type: ignore[attr-defined]
        return np.column_stack([self.surface.nodal(f) for f in forms])

    def _set_lam_t(self, values: np.ndarray) -> None:
        n = values.shape[0]
        k = self.gdim - 1
        self.lam_t.x.array[: n * k] = values.reshape(-1)
        self.lam_t.x.scatter_forward()

    def update_multiplier(self) -> None:
        """Uzawa update of both multipliers, evaluated at the same iterate.

        lam_n <- min(lam_n + r g, 0) and lam_t <- P(lam_t + r_t dg_t).
        """
        tau = self._nodal_components(self._tau_forms)
        super().update_multiplier()  # type: ignore[misc]
        self._set_lam_t(tau)

    def node_states(self) -> np.ndarray:
        """Per owned node: 0 open (p_n = 0), 1 stick (|y| < rho), 2 slip."""
        y = self._nodal_components(self._y_forms)
        rho = self.surface.nodal(self._rho_form)
        eps = float(self.eps.value)
        norm = np.sqrt(np.sum(y**2, axis=1) + eps**2)
        state = np.full(rho.size, OPEN, dtype=np.int8)
        active = self.surface.nodal(self._pressure_form) < 0.0  # type: ignore[attr-defined]
        state[active] = np.where(norm[active] < rho[active], STICK, SLIP)
        return state

    def active_signature(self) -> tuple[bytes, ...]:
        """Fingerprint of the global open/stick/slip pattern."""
        return tuple(self.comm.allgather(self.node_states().tobytes()))

    def tangential_fields(self) -> tuple[np.ndarray, np.ndarray]:
        """Owned nodal vectors in global axes, shape (n, gdim) each.

        The tangential traction on the body -T tau (stress) and the slip
        increment T dg_t of the body relative to the obstacle or target (length).
        """
        traction, slip = (self._nodal_components(forms) for forms in self._global_forms)
        return traction, slip

    def tangential_force_vector(self) -> np.ndarray:
        """Global int T tau dA (force; per thickness in 2D): minus the friction on the body."""
        self.refresh_search()  # type: ignore[attr-defined]
        return np.array([
            self.comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM) for f in self._tforce_forms
        ])

    def contact_state(self) -> FrictionalContactState:
        """Normal diagnostics plus tangential traction, slip, Coulomb limit and node states."""
        base = super().contact_state()  # type: ignore[misc]
        states = self.node_states()
        comm = self.comm
        normal = {f: getattr(base, f) for f in base.__dataclass_fields__}
        return FrictionalContactState(**{
            **normal,
            "tangential_traction": self._nodal_components(self._tau_forms),
            "slip": self._nodal_components(self._slip_forms),
            "coulomb_limit": self.surface.nodal(self._rho_form),
            "node_state": states,
            "tangential_force": float(np.linalg.norm(self.tangential_force_vector())),
            "tangential_magnitude": comm.allreduce(
                fem.assemble_scalar(self._tmag_form), op=MPI.SUM
            ),
            "stick_count": comm.allreduce(int(np.sum(states == STICK)), op=MPI.SUM),
            "slip_count": comm.allreduce(int(np.sum(states == SLIP)), op=MPI.SUM),
        })

    def coulomb_violations(self) -> tuple[float, float, float]:
        """Worst nodal violations of the Coulomb conditions, global over ranks.

        Returns (largest |dg_t| at sticking nodes (length), largest
        |tau - lam_t| (stress), largest |lam_t| - rho (stress)); all zero at
        an exact nodal solution, whatever r and r_t. Only meaningful with the
        vertex rule (the conditions hold at the nodes).
        """
        slip = np.linalg.norm(self._nodal_components(self._slip_forms), axis=1)
        tau = self._nodal_components(self._tau_forms)
        lam_t = self.lam_t.x.array[: tau.size].reshape(tau.shape)
        rho = self.surface.nodal(self._rho_form)
        sticks = self.node_states() == STICK
        local = (
            float(np.max(slip[sticks], initial=0.0)),
            float(np.max(np.linalg.norm(tau - lam_t, axis=1), initial=0.0)),
            float(np.max(np.linalg.norm(lam_t, axis=1) - rho, initial=0.0)),
        )
        return tuple(self.comm.allreduce(v, op=MPI.MAX) for v in local)

    def complementarity_norms(self) -> tuple[float, float]:
        """Euclidean norms of the normal and tangential complementarity residuals (force)."""
        self.refresh_search()  # type: ignore[attr-defined]
        out = []
        for form in self.complementarity_residual():
            local = assemble_local(fem.form(form, entity_maps=self.surface.entity_maps))
            out.append(float(np.sqrt(self.comm.allreduce(float(local @ local), op=MPI.SUM))))
        return out[0], out[1]


class FrictionalContactProblem(FrictionMixin, ContactProblem):
    """A body against a rigid obstacle with Coulomb friction of coefficient ``mu``.

    Adds the tangential multiplier ``lam_t`` (P1 on the contact submesh,
    d-1 components), the last converged displacement ``u_prev`` and obstacle
    placement ``c_prev``; :meth:`commit` moves them forward after each
    converged increment. ``tangential_r_max`` caps the tangential parameter
    r_t = min(r, tangential_r_max E/L), L the extent of the candidate contact
    surface (None: r_t = r). Other arguments as :class:`ContactProblem`.
    """

    def _slip_increment(self) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """T from the obstacle normal; dg_t = T^T [(x - x_prev) - (c - c_prev)]."""
        self.c_prev = fem.Constant(self.domain, np.array(self.obstacle.point.value, dtype=float))
        X = ufl.SpatialCoordinate(self.domain)
        x = X + self.u
        x_prev = X + self.u_prev
        tangents = tangent_basis(self.obstacle.normal_at(x), self.gdim)
        motion = self.obstacle.point - self.c_prev
        return tangents, tangents.T * ((x - x_prev) - motion)

    def _commit_frame(self) -> None:
        """c_prev <- c."""
        self.c_prev.value[:] = self.obstacle.point.value
