"""The Coulomb terms of one contact: tangential multiplier, projected traction, checks.

The formulas and sign conventions are those of :mod:`.friction`. A
:class:`CoulombFriction` is built by its contact once the contact is bound
(surface, lam, r, gap and pressure exist); the contact supplies the tangent
frame and the slip increment (:meth:`~.contacts.Contact.slip_increment`)
and the problem the last converged displacement ``u_prev``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem

from mpi4py import MPI

from fenics_contact.model.contact import assemble_local
from fenics_contact.model.friction import (
    GUARD,
    OPEN,
    SLIP,
    STICK,
    FrictionalContactState,
    FrictionSettings,
    coulomb_projection,
    held_components,
    sticks,
    surface_extent,
    symmetry_planes,
)
from fenics_contact.model.state import ContactState

#: A held node's slip along its held tangent counts as prescribed motion above this
#: fraction of the contact surface's extent (below: the support holds it still).
HELD_SLIP_FLOOR = 1e-12


class CoulombFriction:
    """Coulomb friction on one contact (rigid obstacle or deformable target).

    Holds the tangential multiplier lam_t (P1 on the contact submesh, d-1
    components), the projected traction tau = P(lam_t + r_t dg_t), the
    regularised-stick traction of the penalty method, the residual terms and
    the nodal diagnostics.

    Args:
        contact: the bound contact (see :class:`~.contacts.Contact`).
        settings: mu and the cap of r_t.
        u_prev: the last converged displacement, shared by the problem.
    """

    def __init__(self, contact, settings: FrictionSettings, u_prev: fem.Function) -> None:
        self.contact = contact
        surface = contact.surface
        domain = contact.domain
        gdim = contact.gdim
        self.gdim = gdim
        self.comm = contact.comm
        self.surface = surface
        self.u_prev = u_prev
        self.mu = fem.Constant(domain, default_scalar_type(settings.mu))
        self.eps = fem.Constant(domain, default_scalar_type(GUARD * contact.modulus))
        if gdim == 2:
            self.Qt = contact.Q
            self.lam_t = fem.Function(self.Qt, name="tangential_multiplier")
            lam_t = ufl.as_vector([self.lam_t])
        else:
            self.Qt = fem.functionspace(surface.submesh, ("Lagrange", 1, (gdim - 1,)))
            self.lam_t = fem.Function(self.Qt, name="tangential_multiplier")
            lam_t = self.lam_t
        self.tangents, self.slip = contact.slip_increment(u_prev)
        #: 1 per tangential component, 0 where a symmetry plane through the contact
        #: zone makes the traction's component across the plane vanish.
        self.symmetry_mask = fem.Function(self.Qt, name="symmetry_mask")
        self.symmetry_mask.x.array[:] = 1.0
        mask = ufl.as_vector([self.symmetry_mask]) if gdim == 2 else self.symmetry_mask
        #: Extent L of the candidate contact surface (length).
        self.contact_extent = surface_extent(surface.submesh)
        #: Tangential parameter r_t = min(r, r_t_cap), r_t_cap = tangential_r_max E/L
        #: (stress/length, E the modulus of the r scale); follows r when a strategy
        #: changes it.
        cap = (np.inf if settings.tangential_r_max is None
               else settings.tangential_r_max * contact.modulus / self.contact_extent)
        self.r_t_cap = fem.Constant(domain, default_scalar_type(cap))
        self.r_t: ufl.core.expr.Expr = ufl.min_value(contact.r, self.r_t_cap)
        self.trial_traction = lam_t + self.r_t * self.slip
        self.coulomb_radius = -self.mu * contact.pressure
        #: 1 on each frame component along which a prescribed displacement holds the
        #: node (rigid obstacles only, where the slip there is then data; 0 elsewhere).
        self.held = fem.Function(self.Qt, name="held_tangent")
        held = ufl.as_vector([self.held]) if gdim == 2 else self.held
        self._prescribed_slip = ufl.dot(ufl.elem_mult(held, self.slip), self.slip)
        self._slip_floor = fem.Constant(
            domain, default_scalar_type((HELD_SLIP_FLOOR * self.contact_extent) ** 2))
        self._mask = mask
        self.traction_t = self._projected(self.coulomb_radius)
        self._lam_t_vector = lam_t
        # penalty: regularised stick on the committed traction, rho = mu r max(-g, 0)
        self._penalty_radius = -self.mu * ufl.min_value(contact.r * contact.gap, 0.0)
        self.penalty_traction = self._projected(self._penalty_radius)

        k = gdim - 1
        nodal = surface.nodal_integrand
        force = self.tangents * self.traction_t
        # The reported tangential traction of a multiplier strategy: the converged
        # multiplier lam_t (= tau at convergence), free of the round-off r eps g that
        # the Coulomb radius -mu min(lam + r g, 0) carries at a huge user r.
        multiplier = self._projected(None, lam_t)
        (self._tau_forms, self._pen_forms, self._slip_forms, self._y_forms, self._rho_form,
         self._global_forms, self._tforce_forms, self._tmag_form, self._multiplier_forms,
         self._multiplier_force_forms, self._multiplier_mag_form,
         self._prescribed_slip_form) = surface.compile([
            [nodal(self.traction_t[i]) for i in range(k)],
            [nodal(self.penalty_traction[i]) for i in range(k)],
            [nodal(self.slip[i]) for i in range(k)],
            [nodal(self.trial_traction[i]) for i in range(k)],
            nodal(self.coulomb_radius),
            [[nodal(-(self.tangents * self.traction_t)[i]) for i in range(gdim)],
             [nodal((self.tangents * self.slip)[i]) for i in range(gdim)]],
            [force[i] * surface.ds for i in range(gdim)],
            ufl.sqrt(ufl.dot(self.traction_t, self.traction_t)) * surface.ds,
            [[nodal(multiplier[i]) for i in range(k)],
             [nodal(-(self.tangents * multiplier)[i]) for i in range(gdim)]],
            [(self.tangents * multiplier)[i] * surface.ds for i in range(gdim)],
            ufl.sqrt(ufl.dot(multiplier, multiplier)) * surface.ds,
            nodal(self._prescribed_slip) if self._slip_is_data else None,
        ])
        self.symmetry_constraints = self._constrain_symmetry_planes()

    @property
    def _slip_is_data(self) -> bool:
        """Whether the slip along a held tangent is data (a rigid partner) at this contact."""
        return bool(getattr(self.contact, "held_slip_is_data", False))

    def _projected(self, rho: ufl.core.expr.Expr | None,
                   lam_t: ufl.core.expr.Expr | None = None) -> ufl.core.expr.Expr:
        """The Coulomb projection P(y) on the disc of radius ``rho``, held tangents treated.

        Where a symmetry plane holds the node the traction across it is zero
        (:attr:`symmetry_mask`). Against a rigid obstacle a prescribed
        displacement along a tangent makes that slip data: zero, and the
        traction along the held tangent is left to the support (masked), or
        not zero, and the node cannot stick (the stick branch would be a
        zero Jacobian row), so it slides: tau = rho y / |y| whatever |y|.
        With ``lam_t`` instead of ``rho``: the multiplier under the same rule
        (what the outputs report).
        """
        y = self.trial_traction
        if lam_t is None:
            standard = ufl.elem_mult(self._mask, coulomb_projection(y, rho, self.eps))
            sliding = rho / ufl.sqrt(ufl.dot(y, y) + self.eps**2) * y
        else:
            standard, sliding = ufl.elem_mult(self._mask, lam_t), lam_t
        if not self._slip_is_data:
            return standard
        forced = ufl.conditional(ufl.gt(self._prescribed_slip, self._slip_floor), 1.0, 0.0)
        return forced * sliding + (1.0 - forced) * standard

    def _constrain_symmetry_planes(self) -> int:
        """Mask the traction along held tangents at the contact nodes (symmetry planes).

        A symmetry plane is a Dirichlet condition holding one displacement
        component at 0 on a plane of facets normal to that axis (see
        :func:`~.friction.symmetry_planes`). At a contact node on it the slip
        across the plane vanishes identically, so a sticking node would leave
        the tangential multiplier's component across the plane undetermined
        (a singular Jacobian); by symmetry that traction component is zero,
        and :attr:`symmetry_mask` makes it so (residual row lam_t,k = 0, no
        force). The frame component along the plane's normal is found from
        the nodal tangents; a frame not aligned with the plane is refused.

        Against a rigid obstacle every held displacement component along a
        tangent of the frame is treated alike, whatever its value, and also
        marked in :attr:`held`: where the obstacle moves along it the node
        slides (:meth:`_projected`). Returns the number of constrained
        (node, component) pairs (global).
        """
        domain = self.contact.domain
        holds = [(facets, axis, None) for facets, axis
                 in symmetry_planes(domain, self.contact.solid.prescribed)]
        if self._slip_is_data:
            holds += held_components(self.contact.solid.prescribed)
        if not self.comm.allreduce(len(holds), op=MPI.MAX):
            return 0
        fdim = domain.topology.dim - 1
        W = fem.functionspace(domain, ("Lagrange", 1))
        parent = self.surface.parent_dofs(W)
        n_owned = self.contact.Q.dofmap.index_map.size_local
        k = self.gdim - 1
        self.contact.refresh()
        compiled = self.surface.compile([
            [self.surface.nodal_integrand(self.tangents[i, j]) for j in range(k)]
            for i in range(self.gdim)])
        frame = np.stack([
            np.column_stack([self.surface.nodal(compiled[i][j]) for j in range(k)])
            for i in range(self.gdim)
        ], axis=1)  # (owned nodes, gdim, d-1)
        constrained = np.zeros((n_owned, k), dtype=bool)
        across = np.zeros((n_owned, self.gdim), dtype=bool)
        symmetric_rows = np.zeros((n_owned, k), dtype=bool)
        mask = self.contact.normal_mask
        free_gap = np.ones(n_owned, bool) if mask is None else mask.x.array[:n_owned] > 0.5
        for facets, axis, name in holds:
            symmetric = name is None
            held = fem.locate_dofs_topological(W, fdim, facets)
            if symmetric and not self._plane_cuts_partner(W, held):
                continue  # a roller on one body of a pair: the slip across it is free
            nodes = np.flatnonzero(np.isin(parent[:n_owned], held))
            along = np.abs(frame[nodes, axis, :])
            j = np.argmax(along, axis=1) if nodes.size else np.zeros(0, int)
            aligned = along[np.arange(nodes.size), j] >= 1.0 - 1e-8
            if not symmetric:
                self._refuse_oblique_hold(nodes[free_gap[nodes]], axis, name)
            if symmetric:
                cosines = along[np.arange(nodes.size), j]
                k_worst = int(np.argmin(cosines)) if nodes.size else -1
                local = float(cosines[k_worst]) if nodes.size else 1.0
                where = (self.contact.nodal_coordinates()[nodes[k_worst], : self.gdim]
                         if nodes.size else np.zeros(self.gdim))
                worst, rank = self.comm.allreduce((local, self.comm.rank), op=MPI.MINLOC)
                where = self.comm.bcast(where, root=rank)
                if worst < 1.0 - 1e-8:
                    at = ", ".join(f"{c:.4g}" for c in where)
                    raise ValueError(
                        f"A symmetry plane (u_{'xyz'[axis]} = 0 on a plane normal to "
                        f"{'xyz'[axis]}) crosses the frictional contact surface where the "
                        f"contact's frame is not aligned with it (|t . e_{'xyz'[axis]}| = "
                        f"{worst:.3g} at the contact node ({at}), a frame taken from the "
                        "nearest facet of the partner at the start); a symmetry cut needs "
                        "the contact normal in the plane there. If that node is far from "
                        "its partner and never touches, end the contact's facet tag before "
                        "the plane; otherwise model the whole body across the plane.")
            # a held axis across the frame leaves the slip free along the tangents: no
            # zero Jacobian row, nothing to treat
            constrained[nodes[aligned], j[aligned]] = True
            if symmetric and not self._slip_is_data:
                # (against a rigid obstacle a held node the obstacle drags slides: its
                # traction is mu p, and reported as it is)
                across[nodes[aligned], axis] = True
                symmetric_rows[nodes[aligned], j[aligned]] = True
        #: Owned nodes' global axes and frame components across a symmetry plane: the
        #: traction there is zero by symmetry, also as reported (a mortar pair's nodal
        #: means would let a neighbour's traction in).
        self.across_symmetry = (across, symmetric_rows)
        self.symmetry_mask.x.array[: n_owned * k] = np.where(constrained.reshape(-1), 0.0, 1.0)
        self.symmetry_mask.x.scatter_forward()
        if self._slip_is_data:
            self.held.x.array[: n_owned * k] = constrained.reshape(-1).astype(float)
            self.held.x.scatter_forward()
        return self.comm.allreduce(int(np.sum(constrained)), op=MPI.SUM)

    def _plane_cuts_partner(self, W: fem.FunctionSpace, held: np.ndarray) -> bool:
        """Whether a symmetry plane's held nodes include the partner surface's (collective).

        Against a rigid obstacle, always. On a pair the plane is one only when
        it cuts both bodies: a roller that holds the striker's body alone
        (an axis held on one body of a stack) leaves the slip across it free,
        the target point moving, so the node's traction there is no more zero
        by symmetry than anywhere else.
        """
        target = getattr(self.contact, "target_facets", None)
        if target is None:
            return True
        fdim = self.contact.domain.topology.dim - 1
        partner = fem.locate_dofs_topological(W, fdim, np.asarray(target, np.int32))
        return bool(self.comm.allreduce(bool(np.isin(partner, held).any()), op=MPI.LOR))

    def _refuse_oblique_hold(self, nodes: np.ndarray, axis: int, name: str) -> None:
        """Refuse a held axis that is neither along nor across the obstacle's normal.

        There the held direction mixes the normal and a tangent: the node has
        fewer free components than the contact has rows (normal and stick),
        and a sticking node gives the linear solve a singular matrix at once
        (collective). Measured with the normal at load 0 at ``nodes`` (those
        whose gap is free).
        """
        along = np.abs(self.contact.reference_normals()[nodes, axis])
        oblique = (along > 1e-8) & (along < 1.0 - 1e-8)
        count = self.comm.allreduce(int(np.sum(oblique)), op=MPI.SUM)
        if not count:
            return
        X = self.contact.nodal_coordinates()[nodes[oblique]][:, : self.gdim]
        where = self.comm.allgather(X[0].tolist() if X.shape[0] else None)
        point = next(p for p in where if p is not None)
        raise ValueError(
            f"The support {name!r} holds u_{'xyz'[axis]} at {count} node(s) of the frictional "
            f"contact {self.contact.name!r} where the obstacle's normal is neither along nor "
            f"across {'xyz'[axis]} (e.g. at {np.round(point, 6).tolist()}): a sticking node "
            "there has more contact conditions than free components, and the first linear "
            "solve fails. A symmetry plane holds the component normal to its face (value = "
            "[0.0, \"free\", ...] on the face x = 0); otherwise leave these nodes out of the "
            "contact's facets, or hold the face along the contact's normal or tangent.")

    # -- the tangential parameter --------------------------------------------------------
    @property
    def tangential_r(self) -> float:
        """The current tangential parameter r_t = min(r, cap) (stress per length)."""
        return min(float(self.contact.r.value), float(self.r_t_cap.value))

    @property
    def tangential_cap(self) -> float:
        """The cap of r_t (stress per length; inf when r_t = r)."""
        return float(self.r_t_cap.value)

    def set_tangential_cap(self, cap: float) -> None:
        """Set the cap of r_t (absolute, stress per length; inf: r_t = r). No recompilation."""
        if not cap > 0:
            raise ValueError(f"The cap of r_t must be > 0 (stress per length), got {cap}.")
        self.r_t_cap.value = cap

    # -- residual terms ---------------------------------------------------------------------
    def work(self, traction: ufl.core.expr.Expr, c: fem.Function,
             test: ufl.Argument) -> ufl.Form:
        """Int traction . d(dg_t)/dc[test] ds: the friction force on u or on an extra c.

        The body (and, for a deformable target, the target's vertices through
        the derivative with respect to w_k) receives the friction force.
        """
        return ufl.dot(traction, ufl.derivative(self.slip, c, test)) * self.surface.ds

    def tangential_residual(self) -> ufl.Form:
        """(P(lam_t + r_t dg_t) - lam_t) . mu_t ds (force units)."""
        mu_t = ufl.TestFunction(self.Qt)
        mu_t = ufl.as_vector([mu_t]) if self.gdim == 2 else mu_t
        return ufl.dot(self.traction_t - self._lam_t_vector, mu_t) * self.surface.ds

    # -- nodal values --------------------------------------------------------------------------
    def _nodal_components(self, forms: Sequence[fem.Form]) -> np.ndarray:
        """Owned nodal values of a (d-1)-vector expression, shape (n, d-1)."""
        self.contact.refresh()
        return np.column_stack([self.surface.nodal(f) for f in forms])

    def nodal_slip(self) -> np.ndarray:
        """Owned nodal slip increment dg_t since the last commit, shape (n, d-1) (length)."""
        return self._nodal_components(self._slip_forms)

    def nodal_traction(self) -> np.ndarray:
        """Owned nodal tau = P(lam_t + r_t dg_t), shape (n, d-1) (stress)."""
        return self._nodal_components(self._tau_forms)

    def set_lam_t(self, values: np.ndarray) -> None:
        """Set the owned nodal lam_t (shape (n, d-1)) and update the ghosts."""
        n = values.shape[0]
        self.lam_t.x.array[: n * (self.gdim - 1)] = values.reshape(-1)
        self.lam_t.x.scatter_forward()

    def keep_penalty_traction(self) -> None:
        """lam_t <- the regularised-stick traction of the penalty method (its history)."""
        self.set_lam_t(self._nodal_components(self._pen_forms))

    @property
    def _reports_multipliers(self) -> bool:
        """Whether the outputs read the multipliers (not the penalty method's tractions)."""
        return bool(self.contact.multiplier_is_pressure)

    def _pressure_and_radius(self) -> tuple[np.ndarray, np.ndarray]:
        """Owned nodal pressure (<= 0) and Coulomb radius rho = -mu p (stress), as reported."""
        if self._reports_multipliers:
            rho_form = self.surface.nodal(self._rho_form)
            lam = self.contact.lam.x.array[: rho_form.size].copy()
            pressure = self.contact.nodal_pressure(lam)
            return pressure, -float(self.mu.value) * pressure
        return (self.surface.nodal(self.contact._pressure_form),
                self.surface.nodal(self._rho_form))

    def node_states(self) -> np.ndarray:
        """Per owned node: 0 open (p_n = 0), 1 stick (:func:`~.friction.sticks`), 2 slip."""
        return self._states_and_trial()[0]

    def node_pattern(self) -> np.ndarray:
        """:meth:`node_states` with each slipping node's direction (int8, per owned node).

        A slipping node adds 4 << k where component k of its trial traction
        y = lam_t + r_t dg_t is positive: an iteration that flips slip
        directions (a 2-cycle between two Coulomb projections) changes the
        pattern although no node changes state.
        """
        state, y = self._states_and_trial()
        code = state.copy()
        slip = state == SLIP
        for k in range(y.shape[1]):
            code[slip] += np.int8(4 << k) * (y[slip, k] > 0.0).astype(np.int8)
        return code

    def _states_and_trial(self) -> tuple[np.ndarray, np.ndarray]:
        y = self._nodal_components(self._y_forms)
        pressure, rho = self._pressure_and_radius()
        stick = sticks(y, rho, float(self.eps.value))
        state = np.full(rho.size, OPEN, dtype=np.int8)
        active = pressure < 0.0
        if self._slip_is_data:
            # a held node that the obstacle drags along its held tangent slides
            stick &= ~(self.surface.nodal(self._prescribed_slip_form)
                       > float(self._slip_floor.value))
        state[active] = np.where(stick[active], STICK, SLIP)
        return state, y

    def tangential_fields(self) -> tuple[np.ndarray, np.ndarray]:
        """Owned nodal vectors in global axes, shape (n, gdim) each.

        The tangential traction on the body -T tau (stress) and the slip
        increment T dg_t of the body relative to the obstacle or target (length).
        """
        traction_forms = (self._multiplier_forms[1] if self._reports_multipliers
                          else self._global_forms[0])
        return (self._reported_traction(self._nodal_components(traction_forms)),
                self._nodal_components(self._global_forms[1]))

    def _reported_traction(self, values: np.ndarray, frame: bool = False) -> np.ndarray:
        """The contact's reported nodal traction, zero across symmetry planes.

        ``values``: (n, gdim) in global axes, or (n, d - 1) frame components
        (``frame``).
        """
        out = np.array(self.contact.reported(values), copy=True).reshape(values.shape)
        masks = getattr(self, "across_symmetry", None)
        if masks is not None and out.size:
            mask = masks[1] if frame else masks[0]
            out.reshape(out.shape[0], -1)[mask[: out.shape[0]].reshape(out.shape[0], -1)] = 0.0
        return out

    def tangential_force_vector(self) -> np.ndarray:
        """Global int T tau dA (force; per thickness in 2D): minus the friction on the body."""
        self.contact.refresh()
        forms = (self._multiplier_force_forms if self._reports_multipliers
                 else self._tforce_forms)
        return np.array([
            self.comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM) for f in forms
        ])

    def with_friction(self, base: ContactState) -> FrictionalContactState:
        """The normal diagnostics ``base`` plus tangential traction, slip, limit and states."""
        states = self.node_states()
        comm = self.comm
        normal = {f: getattr(base, f) for f in ContactState.__dataclass_fields__}
        multipliers = self._reports_multipliers
        return FrictionalContactState(**{
            **normal,
            "tangential_traction": self._reported_traction(self._nodal_components(
                self._multiplier_forms[0] if multipliers else self._tau_forms), frame=True),
            "slip": self._nodal_components(self._slip_forms),
            "coulomb_limit": self.contact.reported(self._pressure_and_radius()[1]),
            "node_state": states,
            "tangential_force": float(np.linalg.norm(self.tangential_force_vector())),
            "tangential_magnitude": comm.allreduce(fem.assemble_scalar(
                self._multiplier_mag_form if multipliers else self._tmag_form), op=MPI.SUM
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

    def complementarity_squares(self) -> tuple[float, float]:
        """Global squared norms of the normal and tangential complementarity residuals."""
        self.contact.refresh()
        out = []
        for form in (self.contact.complementarity_residual(), self.tangential_residual()):
            local = assemble_local(fem.form(form, entity_maps=self.surface.entity_maps,
                                            jit_options=self.contact.jit_options))
            out.append(self.comm.allreduce(float(local @ local), op=MPI.SUM))
        return out[0], out[1]
