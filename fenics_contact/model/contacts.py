"""One contact of a problem: a candidate surface, its multiplier and its partner.

A :class:`Contact` is described first (its facets, its settings, optional
friction) and bound to a :class:`~.body.Solid` by the problem, which hands it
the problem's facet tags. Bound, it holds the contact submesh with the
multiplier ``lam`` (P1, <= 0 the pressure), its own parameter ``r`` and the
gap ``g`` to its partner as a UFL expression; a subclass says what the
partner is (:class:`~.obstacle_contact.ObstacleContact`, a rigid obstacle;
:class:`~.pairs.NodeToSegmentContact`, another deformable surface). Sign
conventions as in :mod:`.contact`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem, mesh

from mpi4py import MPI

from fenics_contact.model.contact import (
    ContactSettings,
    ContactSurface,
    augmented_lagrangian_energy,
    augmented_pressure,
    check_r,
    penalty_energy,
)
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.friction_terms import CoulombFriction
from fenics_contact.model.state import ContactState


class SlotUse(NamedTuple):
    """The target facets each striker node of a 2D mortar pair may see (its slots).

    ``wanted``: what a striker support overlaps where the surfaces first meet
    (chosen at the start); ``now`` and ``most``: the most target facets one
    striker node in contact overlapped, in the current state and in any
    converged state of the run (an iterate far from the answer may stretch
    a facet over many). Beyond ``slots`` the weighted gap leaves the rest of
    the support out.
    """

    pair: str
    slots: int
    wanted: int
    now: int
    most: int

class Contact:
    """A candidate contact surface of the solid against a partner, with optional friction.

    Args:
        facets: local facet indices of the candidate (striker) surface.
        settings: r, its scale and the quadrature.
        friction: Coulomb friction on this contact (None: frictionless).
        name: label in outputs.

    A subclass defines :meth:`_bind_partner` (the gap and the modulus of the
    r scale) and, for friction, :meth:`slip_increment`.
    """

    #: Whether lam is the contact pressure of the solution (the penalty method
    #: sets False through the problem): chooses the contact-force formula.
    multiplier_is_pressure = True
    #: Options of the just-in-time compilation of this contact's forms (None: defaults).
    jit_options: dict | None = None
    #: Whether a held displacement along a tangent makes the slip there data (a rigid
    #: partner): friction then treats held nodes (:class:`~.friction_terms.CoulombFriction`).
    held_slip_is_data = False

    def __init__(
        self,
        facets: np.ndarray,
        settings: ContactSettings,
        *,
        friction: FrictionSettings | None = None,
        name: str = "contact",
    ) -> None:
        given = np.asarray(facets)
        if given.size and (given.dtype == bool or not np.issubdtype(given.dtype, np.integer)):
            raise TypeError(
                f"Contact {name!r}: facets must be facet indices (integers, e.g. "
                f"tags.find(3) or mesh.locate_entities_boundary(...)), got {given.dtype} "
                f"values{' (a mask: use np.flatnonzero(mask))' if given.dtype == bool else ''}.")
        self.facets = np.unique(given.astype(np.int32))
        self.settings = settings
        self.friction_settings = friction
        self.friction: CoulombFriction | None = None
        self.name = name

    def facet_arguments(self) -> dict[str, np.ndarray]:
        """The facet index arrays this contact was given, by argument name."""
        return {"facets": self.facets}

    @property
    def frictional(self) -> bool:
        """Whether the contact carries Coulomb friction."""
        return self.friction_settings is not None

    # -- binding ------------------------------------------------------------------
    def bind(self, solid, tags: mesh.MeshTags, ids: tuple[int, ...],
             own_ids: tuple[int, ...] | None = None) -> None:
        """Build the surface, lam, r and the gap on ``solid`` (the problem calls this).

        Args:
            solid: the :class:`~.body.Solid` the surface belongs to.
            tags: the problem's facet tags.
            ids: the tag values of this contact's facets in ``tags``.
            own_ids: those of ``ids`` that no other surface integral reads (facets
                with this role only); default ``ids``.
        """
        if solid.degree > 1 and self.settings.quadrature == "nodal":
            raise ValueError(
                f"Contact {self.name!r}: quadrature = 'nodal' holds the facets' vertices only; "
                f"with displacement degree {solid.degree} the other nodes of a facet would pass "
                "through the partner unchecked (a pressed block's force came out 19 % low). "
                "Use ContactSettings(quadrature='gauss') with degree > 1, or degree = 1."
            )
        self.solid = solid
        self.domain = solid.domain
        self.comm = solid.comm
        self.gdim = solid.gdim
        self.surface = ContactSurface(
            self.domain, self.facets, self.settings.quadrature, tags=tags, ids=ids
        )
        #: The tag values whose facets carry this contact's integrals only.
        self.own_ids = tuple(ids) if own_ids is None else tuple(own_ids)
        self.Q = self.surface.Q
        self.lam = fem.Function(self.Q, name="contact_pressure")
        self.r = fem.Constant(self.domain, default_scalar_type(1.0))
        self.surface.jit_options = self.jit_options
        self.gap = self._bind_partner(solid)
        #: Each striker node's starting overlap (length, >= 0), allowed times
        #: :attr:`allowance` (1 at load factor 0, 0 from ``interference_until`` on).
        self.interference: fem.Function | None = None
        self.allowance = fem.Constant(self.domain, default_scalar_type(0.0))
        if self.settings.interference_until is not None:
            self.interference = fem.Function(self.Q, name="interference")
            self.gap = self.gap + self.allowance * self.interference
        self.set_r(self.settings.r, relative=self.settings.relative)
        self.pressure = augmented_pressure(self.gap, self.lam, self.r)
        if self.normal_mask is not None:
            self.pressure = self.normal_mask * self.pressure
        nodal = self.surface.nodal_integrand
        (self._gap_form, self._pressure_form, self._force_form,
         self._multiplier_force_form) = self.surface.compile([
            nodal(self.gap), nodal(self.pressure), -self.pressure * self.surface.ds,
            -self.lam * self.surface.ds])

    def bind_friction(self, u_prev: fem.Function) -> None:
        """Add the Coulomb terms (after :meth:`bind`; u_prev: the last converged u)."""
        if self.friction_settings is not None:
            self.friction = CoulombFriction(self, self.friction_settings, u_prev)

    def _bind_partner(self, solid) -> ufl.core.expr.Expr:
        """Set up the partner; return the gap g(u) (length, >= 0 open)."""
        raise NotImplementedError

    #: E of the r scale (stress); set by :meth:`_bind_partner`.
    modulus: float
    #: The node-to-segment search of a deformable pair; None against a rigid obstacle.
    pair = None
    #: 0 at the nodes whose gap a prescribed displacement fixes (they transmit no
    #: pressure; the support holds them), 1 elsewhere; None: every node is free.
    normal_mask: fem.Function | None = None

    # -- parameters and loads ----------------------------------------------------------
    @property
    def stiffness_scale(self) -> float:
        """E/h: the scale that makes r dimensionless (stress per length)."""
        return self.modulus / self.surface.h

    def set_r(self, r: float, *, relative: bool) -> None:
        """Set the penalty/augmentation parameter, relative to E/h or absolute."""
        check_r(r)
        self.r.value = r * self.stiffness_scale if relative else r

    def set_load(self, t: float) -> None:
        """Move the partner to load factor t (a moving obstacle); nothing by default."""

    # -- interference fits -------------------------------------------------------------
    def capture_interference(self) -> None:
        """Record each striker node's overlap in the current state (the start; collective).

        Only with ``interference_until``: the overlap is the negative part of
        the gap before any allowance.
        """
        if self.interference is None:
            return
        self.allowance.value = 0.0
        self.refresh()
        gap = self.surface.nodal(self._gap_form)
        self.interference.x.array[:] = 0.0
        self.interference.x.array[:gap.size] = np.maximum(-gap, 0.0)
        self.interference.x.scatter_forward()

    def ramp_interference(self, t: float) -> None:
        """The allowance at load factor t: 1 - t / interference_until, down to 0.

        Up to interference_until, the step that ends there included, the
        contact's friction is off (mu = 0): the closing fit stands for an
        assembly whose path the scene does not model, and its normal motion
        across faceted surfaces would read as slip. The load steps after it
        slip from the assembled state with the contact's mu (a step that
        starts before interference_until and ends after it closes the fit
        with friction on: let a step end there).
        """
        if self.interference is None:
            return
        until = float(self.settings.interference_until)  # type: ignore[arg-type]
        self.allowance.value = max(1.0 - t / until, 0.0)
        if self.friction is not None and self.friction_settings is not None:
            closing = t <= until * (1.0 + 1e-12)
            self.friction.mu.value = 0.0 if closing else self.friction_settings.mu

    @property
    def ramping(self) -> bool:
        """Whether part of the starting overlap is still allowed (the gap is shifted)."""
        return self.interference is not None and float(self.allowance.value) > 0.0

    def starting_overlap(self) -> np.ndarray | None:
        """Owned nodal starting overlaps (length) of an interference fit; None without one."""
        if self.interference is None:
            return None
        return np.array(self.interference.x.array[:self.interference.x.index_map.size_local])

    def refresh(self) -> bool:
        """Bring data that follow u up to date (a search); True when an assignment changed."""
        return False

    def commit_frame(self) -> None:
        """Move the reference of the slip forward after a converged increment."""

    def search_state(self) -> dict[str, np.ndarray]:
        """What the next search carries over from the last ones (local arrays; a checkpoint).

        Empty for a contact whose search keeps nothing from one search to the
        next (an obstacle; a mortar pair searches afresh each time).
        """
        return {}

    def restore_search_state(self, state: dict[str, np.ndarray]) -> None:
        """Put back a :meth:`search_state` (a resumed run; collective)."""

    def extras(self) -> list[fem.Function]:
        """Coefficients that are a selection of u (a deformable target's displacements)."""
        return []

    @property
    def transfer(self):
        """The search that refreshes :meth:`extras` and selects them from u (or None)."""
        return None

    def slip_increment(self, u_prev: fem.Function) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """(T, dg_t): the gdim x (d-1) tangent matrix and the slip increment (length)."""
        raise NotImplementedError

    def may_close(self, gaps: np.ndarray) -> np.ndarray:
        """Which open nodes a Newton step may set in contact (the exact contact set).

        True where the Jacobian holds the node's gap derivative while it is
        open (every node here). ``gaps``: the owned nodal gaps (length).
        """
        return np.ones(gaps.size, dtype=bool)

    def penetration(self) -> float | None:
        """Global depth inside the partner's actual surface when it differs from -min(g, 0)."""
        return None

    # -- UFL terms ------------------------------------------------------------------------
    def lagrangian(self) -> ufl.Form:
        """Int [min(lam + r g, 0)^2 - lam^2] / (2 r) ds (paper eq. 9).

        With a :attr:`normal_mask` m: [m min(lam + r g, 0)^2 - lam^2] / (2 r),
        so that lam = 0 at a masked node (a regular row) and it exerts nothing.
        """
        if self.normal_mask is None:
            return augmented_lagrangian_energy(self.gap, self.lam, self.r) * self.surface.ds
        m = self.normal_mask
        return ((m * ufl.min_value(self.lam + self.r * self.gap, 0) ** 2 - self.lam**2)
                / (2 * self.r) * self.surface.ds)

    def penalty(self) -> ufl.Form:
        """Int r/2 min(g, 0)^2 ds (paper eq. 7); times the :attr:`normal_mask` if any."""
        energy = penalty_energy(self.gap, self.r)
        if self.normal_mask is not None:
            energy = self.normal_mask * energy
        return energy * self.surface.ds

    def complementarity_residual(self) -> ufl.Form:
        """(min(lam + r g, 0) - lam) mu: zero when lam is the converged pressure."""
        mu = ufl.TestFunction(self.Q)
        return (self.pressure - self.lam) * mu * self.surface.ds

    # -- nodal values and diagnostics --------------------------------------------------------
    def nodal_pressure(self, lam: np.ndarray) -> np.ndarray:
        """Owned nodal contact pressure (<= 0, stress) of the current iterate.

        Multiplier strategies: the multiplier, min(lam, 0), with values
        below 1e-12 of the largest pressure, or below 1e-14 E, set to zero
        (the round-off of a linear solve at open nodes; the second also once
        every node has lifted off, when the largest is round-off itself).
        The transmitted min(lam + r g, 0) would
        carry the round-off r * eps * g of the gap, of the order of the
        pressure itself at r = 1e12 E/h. The penalty method, whose multiplier
        is zero, transmits r min(g, 0).
        """
        if not self.multiplier_is_pressure:
            return self.surface.nodal(self._pressure_form)
        pressure = np.minimum(lam, 0.0)
        peak = self.comm.allreduce(float(np.max(-pressure, initial=0.0)), op=MPI.MAX)
        pressure[pressure > -max(1e-12 * peak, 1e-14 * self.modulus)] = 0.0
        return pressure

    def note_converged(self) -> None:
        """Runs after each converged increment (default: nothing)."""

    def slot_use(self) -> SlotUse | None:
        """A 2D mortar pair's slots and how many target facets its nodes overlapped; else None."""
        return None

    def reported(self, values: np.ndarray) -> np.ndarray:
        """Owned nodal values as written and measured (pressure, traction, Coulomb limit).

        The nodal values themselves here; a discretisation whose multiplier
        is not a nodal force per area (the 2D mortar pair) reports that
        instead. ``values`` has one row per owned node (and any columns).
        """
        return values

    def contact_state(self) -> ContactState:
        """Nodal gaps, pressures, the active set and global summaries (fresh search).

        With a multiplier method the pressure is the multiplier (see
        :meth:`nodal_pressure`), so with the vertex rule the written field,
        the active set and the force agree at every r. With the Gauss rule
        lam is the L2 projection of the traction min(lam + r g, 0) on P1,
        which undershoots at the edge of the zone (tensile nodal values, a
        few per cent of the peak): the force -int lam ds is the traction's
        resultant, and the written field, clipped to min(lam, 0), integrates
        to up to a few per cent more. Where the partner's surface is not the
        discretisation's gap (two bodies) ``max_penetration`` is the depth
        inside the actual surface and ``constraint_penetration`` the former.
        """
        self.refresh()
        gap = self.surface.nodal(self._gap_form)
        lam = self.lam.x.array[: gap.size].copy()
        force_form = (self._multiplier_force_form if self.multiplier_is_pressure
                      else self._force_form)
        pressure = self.nodal_pressure(lam)
        state = ContactState.gathered(
            self.comm, gap, self.reported(pressure), lam, fem.assemble_scalar(force_form),
            active=pressure < 0.0,
        )
        # while an interference is ramped the actual surfaces overlap by design
        depth = None if self.ramping else self.penetration()
        if depth is not None:
            state = ContactState(**{**_fields(state), "max_penetration": depth,
                                    "constraint_penetration": state.max_penetration})
        if self.friction is not None:
            return self.friction.with_friction(state)
        return state

    def nodal_gap(self) -> np.ndarray:
        """Owned nodal gaps at the current u (fresh search; length, >= 0 open)."""
        self.refresh()
        return self.surface.nodal(self._gap_form)

    def active_pattern(self) -> bytes:
        """This rank's active set as bytes: lam + r g < 0, or with friction the node pattern.

        The pattern (:meth:`~.friction_terms.CoulombFriction.node_pattern`) is
        open/stick/slip and each slipping node's direction.
        """
        self.refresh()
        if self.friction is not None:
            return self.friction.node_pattern().tobytes()
        return np.packbits(self.surface.nodal(self._pressure_form) < 0.0).tobytes()

    def update_multiplier(self) -> None:
        """Uzawa update lam <- min(lam + r g, 0) at the nodes (paper eq. 10); friction too.

        Both multipliers are evaluated at the same iterate.
        """
        self.refresh()
        tau = None if self.friction is None else self.friction.nodal_traction()
        pressure = self.surface.nodal(self._pressure_form)
        self.lam.x.array[: pressure.size] = pressure
        self.lam.x.scatter_forward()
        if tau is not None:
            self.friction.set_lam_t(tau)

    def gap_origin(self) -> np.ndarray:
        """The point the gap's coordinates are measured from (length; the origin here)."""
        return np.zeros(self.gdim)

    def nodal_coordinates(self) -> np.ndarray:
        """Reference coordinates of the owned multiplier nodes, shape (n, 3)."""
        n = self.Q.dofmap.index_map.size_local
        return self.Q.tabulate_dof_coordinates()[:n]


def _fields(state: ContactState) -> dict:
    return {f: getattr(state, f) for f in ContactState.__dataclass_fields__}


__all__ = ["Contact"]
