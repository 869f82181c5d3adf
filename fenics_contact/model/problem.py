"""A contact problem: a solid (bodies in one mesh) and a list of contacts.

The problem owns nothing but the composition: the displacement ``u`` and
the conditions belong to the :class:`~.body.Solid`, each contact
(:mod:`.obstacle_contact`, :mod:`.pairs`) owns its multiplier ``lam`` (P1
on its contact submesh), its parameter ``r`` and its friction. The problem
hands solvers :class:`~.variational_system.VariationalSystem` objects (UFL
residual blocks with their unknowns: u, every contact's lam, every frictional
contact's lam_t, then the deformable targets' extras; built by
:mod:`.residuals`) and never imports a solver itself. All loads are
proportional to one load factor ``t`` in [0, 1].

Solvers see one system and one set of answers (the state, the active
pattern, the multiplier update, the checks) whatever the contacts are; the
accessors that name one contact's objects (``lam``, ``surface``, ...) are
those of the first contact; the friction accessors are
:class:`~.problem_friction.FrictionalContacts`. This module also re-exports
the names callers take from it: the value types of :mod:`.variational_system`,
the body conditions of :mod:`.body` and the constructors of :mod:`.compositions`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import ufl
from dolfinx import fem

from fenics_contact.model.body import (
    Body,
    DetFMinimum,
    PathDisplacement,
    PrescribedDisplacement,
    Solid,
    SurfaceTraction,
    energy_quadrature_degree,
)
from fenics_contact.model.compositions import one_body_problem, two_body_problem
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.contacts import Contact
from fenics_contact.model.materials import Elastic
from fenics_contact.model.obstacle_contact import ObstacleContact
from fenics_contact.model.obstacles import RigidObstacle
from fenics_contact.model.problem_friction import FrictionalContacts
from fenics_contact.model.residuals import (
    complementarity_forms,
    contact_entity_maps,
    energy_system,
    lagrangian,
    penalty_energy,
)
from fenics_contact.model.state import ContactState, ProblemState, combined_state
from fenics_contact.model.tags import check_facet_indices, facet_roles, own_tag_values
from fenics_contact.model.variational_system import Transfers, VariationalSystem, Work


class ContactProblem(FrictionalContacts):
    """A solid and its contacts, proportional loading.

    Args:
        solid: the bodies, their laws and conditions.
        contacts: the contacts (unbound); each is bound to the solid here.
    """

    def __init__(self, solid: Solid, contacts: Sequence[Contact]) -> None:
        if not contacts:
            raise ValueError("A contact problem needs at least one contact.")
        names = [c.name for c in contacts]
        if len(set(names)) != len(names):
            raise ValueError(f"Contact names {names} repeat; give each contact its own name.")
        self.solid = solid
        self.contacts = list(contacts)
        self.domain = solid.domain
        self.comm = solid.comm
        self.gdim = solid.gdim
        self.V = solid.V
        self.u = solid.u
        self.bcs = solid.bcs
        self.load_factor = 0.0
        #: The load factor of the last :meth:`commit` (the start of the slip increment).
        self.committed_load_factor = 0.0
        for c in self.contacts:  # before any use of the facets
            for argument, facets in c.facet_arguments().items():
                check_facet_indices(self.domain, facets,
                                    f"{type(c).__name__} {c.name!r}: {argument}")
        groups = [c.facets for c in self.contacts] + [t.facets for t in solid.tractions]
        self.facet_tags, ids = facet_roles(self.domain, groups)
        for contact, tag_ids, own in zip(self.contacts, ids, own_tag_values(ids), strict=False):
            contact.bind(solid, self.facet_tags, tag_ids, own_ids=own)
        for contact in self.contacts:  # the overlaps an interference fit starts in
            contact.capture_interference()
            contact.ramp_interference(0.0)
        self.frictional = any(c.frictional for c in self.contacts)
        self.u_prev = fem.Function(self.V, name="displacement_prev") if self.frictional else None
        for contact in self.contacts:
            contact.bind_friction(self.u_prev)
        self.potential = solid.strain_energy()
        ds = ufl.Measure("ds", domain=self.domain, subdomain_data=self.facet_tags)
        external = solid.external_work(ds, ids[len(self.contacts):])
        if external is not None:
            self.potential -= external
        self._multiplier_is_pressure = True
        self._shared_nodes: int | None = None
        self._hold = None  # the rigid-motion check of converged states, built when first asked

    # -- the first contact's objects ------------------------------------------------
    @property
    def contact(self) -> Contact:
        """The first contact."""
        return self.contacts[0]

    @property
    def surface(self):
        """The first contact's surface (its h, quadrature and submesh)."""
        return self.contact.surface

    @property
    def settings(self) -> ContactSettings:
        """The first contact's settings."""
        return self.contact.settings

    @property
    def lam(self) -> fem.Function:
        """The multiplier of the only contact (several contacts: see :meth:`multipliers`)."""
        if len(self.contacts) != 1:
            raise AttributeError(
                f"The problem has {len(self.contacts)} contacts; read each one's lam from "
                "problem.contacts or all of them from problem.multipliers()."
            )
        return self.contact.lam

    @property
    def Q(self) -> fem.FunctionSpace:
        """The first contact's multiplier space."""
        return self.contact.Q

    @property
    def obstacle(self) -> RigidObstacle | None:
        """The first contact's rigid obstacle, None for a deformable pair."""
        return getattr(self.contact, "obstacle", None)

    @property
    def shared_contact_nodes(self) -> int:
        """Global number of body vertices on the surfaces of two or more contacts."""
        if len(self.contacts) < 2:
            return 0
        if self._shared_nodes is None:
            V = fem.functionspace(self.domain, ("Lagrange", 1))
            index_map = V.dofmap.index_map
            on_surface = []
            for c in self.contacts:  # the global vertices of each surface, on every rank
                local = index_map.local_to_global(c.surface.parent_dofs(V).astype(np.int32))
                on_surface.append(np.unique(np.concatenate(self.comm.allgather(local))))
            joined = np.concatenate(on_surface)
            self._shared_nodes = int(joined.size - np.unique(joined).size)
        return self._shared_nodes

    def obstacles(self) -> list[RigidObstacle]:
        """Every rigid obstacle the contacts press against, in the order of the contacts."""
        return [c.obstacle for c in self.contacts if isinstance(c, ObstacleContact)]

    @property
    def pair(self):
        """The first contact's node-to-segment pair, None against a rigid obstacle."""
        return getattr(self.contact, "pair", None)

    @property
    def material(self) -> Elastic:
        """The first body's law."""
        return self.solid.stiffest


    # -- unknowns ----------------------------------------------------------------------
    def normal_multipliers(self) -> list[fem.Function]:
        """Each contact's lam (<= 0, the pressure), in the order of the contacts."""
        return [c.lam for c in self.contacts]

    @property
    def multiplier_dofs(self) -> int:
        """Global number of multiplier unknowns: each contact's lam, and lam_t with friction."""
        return sum(c.surface.num_dofs for c in self.contacts) + sum(
            f.lam_t.function_space.dofmap.index_map.size_global
            * f.lam_t.function_space.dofmap.index_map_bs for f in self._frictions())

    def multipliers(self) -> list[fem.Function]:
        """Every multiplier: each contact's lam, then each frictional contact's lam_t."""
        return self.normal_multipliers() + [f.lam_t for f in self._frictions()]

    @property
    def multiplier_is_pressure(self) -> bool:
        """Whether lam is the pressure of the solution (False once the penalty method solves)."""
        return self._multiplier_is_pressure

    @multiplier_is_pressure.setter
    def multiplier_is_pressure(self, value: bool) -> None:
        self._multiplier_is_pressure = bool(value)
        for c in self.contacts:
            c.multiplier_is_pressure = bool(value)

    # -- parameters and loads -------------------------------------------------------------
    @property
    def stiffness_scale(self) -> float:
        """E/h of the first contact: the scale that makes r dimensionless (stress/length)."""
        return self.contact.stiffness_scale

    @property
    def h(self) -> float:
        """The smallest contact facet size over the contacts (length)."""
        return min(c.surface.h for c in self.contacts)

    @property
    def nodal_rule(self) -> bool:
        """Whether every contact enforces its conditions at the nodes (the default rule)."""
        return all(c.settings.quadrature == "nodal" for c in self.contacts)

    @property
    def entity_maps(self) -> list:
        """The entity maps of every contact submesh (for forms on them)."""
        return contact_entity_maps(self.contacts)

    def residual_roundoff(self) -> tuple[float, float, float]:
        """(floor, force size, atol to use) of the residual's round-off (force; collective).

        The floor FLOOR_FACTOR eps r g ||A|| below which the residual cannot
        fall, the size r g ||A|| of the forces it comes from, and an atol
        above it (:mod:`~fenics_contact.model.scaling`); zeros without contacts.
        """
        from fenics_contact.model.scaling import (
            contact_force_size,
            residual_floor,
            suggested_atol,
        )

        if not self.contacts:
            return 0.0, 0.0, 0.0
        return residual_floor(self), contact_force_size(self), suggested_atol(self)

    def r_ratios(self) -> list[float]:
        """Each contact's r over the first contact's r (1 for one contact)."""
        return [float(c.r.value) / self.r_absolute for c in self.contacts]

    def rescale_r(self, r: float) -> None:
        """Set the first contact's r to ``r`` (absolute); the others keep their ratio to it."""
        for c, ratio in zip(self.contacts, self.r_ratios(), strict=True):
            c.r.value = ratio * r

    def set_r(self, r: float, *, relative: bool) -> None:
        """Set every contact's r, relative to its own E/h or absolute (stress/length)."""
        for c in self.contacts:
            c.set_r(r, relative=relative)

    @property
    def r(self) -> fem.Constant:
        """The first contact's r (a Constant, stress per length)."""
        return self.contact.r

    @property
    def r_absolute(self) -> float:
        """The first contact's r in stress per length."""
        return float(self.contact.r.value)

    @property
    def r_relative(self) -> float:
        """The first contact's r divided by its E/h."""
        return self.r_absolute / self.stiffness_scale

    def set_load(self, t: float) -> None:
        """Apply the load factor t: prescribed values, tractions and obstacle motions."""
        self.load_factor = float(t)
        self.solid.set_load(t)
        for c in self.contacts:
            c.set_load(t)
            c.ramp_interference(t)

    def obstacle_offset(self, t: float) -> np.ndarray:
        """The first contact's obstacle displacement at load factor t."""
        return self.contact.offset(t)

    def refresh_search(self) -> None:
        """Bring data that follow u up to date (every deformable contact's search)."""
        for c in self.contacts:
            c.refresh()

    def commit(self) -> None:
        """Accept the converged increment: u_prev <- u and each contact's slip reference.

        When the penalty method solves the problem (``multiplier_is_pressure``
        False) the committed tangential traction is kept in lam_t (the
        regularised-stick history); AL methods already hold it there, and so
        does ``auto`` after a penalty warm start (it only borrows the system).
        """
        for c in self.contacts:
            c.note_converged()
        if not self.frictional:
            return
        if not self.multiplier_is_pressure:
            for f in self._friction():
                f.keep_penalty_traction()
        self.u_prev.x.array[:] = self.u.x.array
        self.committed_load_factor = self.load_factor
        for c in self.contacts:
            c.commit_frame()

    def restore_commit(self, committed_load_factor: float) -> None:
        """Rebuild the last commit's slip frames from a restored u_prev (a resumed run).

        The obstacles are placed at ``committed_load_factor`` while each
        contact takes its frame, then put back at the current load factor.
        """
        if not self.frictional:
            return
        t = self.load_factor
        self.set_load(committed_load_factor)
        for c in self.contacts:
            c.commit_frame()
        self.committed_load_factor = float(committed_load_factor)
        self.set_load(t)

    def search_states(self) -> list[dict[str, np.ndarray]]:
        """Each contact's search memory, in the order of the contacts (local arrays; a checkpoint).

        See :meth:`Contact.search_state <.contacts.Contact.search_state>`.
        """
        return [c.search_state() for c in self.contacts]

    def restore_search_states(self, states: list[dict[str, np.ndarray]]) -> None:
        """Put back :meth:`search_states` at the u they were taken at (a resumed run)."""
        if len(states) != len(self.contacts):
            raise ValueError(f"{len(states)} saved search states for {len(self.contacts)} "
                             "contacts.")
        for c, state in zip(self.contacts, states, strict=True):
            if state:
                c.restore_search_state(state)

    def snapshot(self) -> ProblemState:
        """Copy u, every multiplier and the load factor (see :meth:`restore`)."""
        return ProblemState(
            self.u.x.array.copy(),
            tuple(m.x.array.copy() for m in self.multipliers()),
            self.load_factor,
        )

    def restore(self, state: ProblemState, *, load: bool = True) -> None:
        """Put back a :meth:`snapshot`; ``load=False`` keeps the current load factor."""
        self.u.x.array[:] = state.u
        for m, values in zip(self.multipliers(), state.multipliers, strict=True):
            m.x.array[:] = values
        if load:
            self.set_load(state.load_factor)

    # -- systems handed to solvers ------------------------------------------------------------
    def _system(self, name: str, energy: ufl.Form, *, with_lam: bool,
                tangential: Callable | None = None) -> VariationalSystem:
        """Residual blocks of ``energy``, named ``name`` (+ "_friction" with friction).

        See :func:`~.residuals.energy_system`; ``tangential(friction)`` is the
        tangential traction of each frictional contact's work (force per area).
        """
        suffix = "_friction" if self.frictional else ""
        return energy_system(name + suffix, energy, self.u, self.bcs, self.contacts,
                             with_lam=with_lam, tangential=tangential,
                             supports=self.solid.record_support_residual)

    def augmented_system(self) -> VariationalSystem:
        """Alart-Curnier saddle point on (u, lam[, lam_t]): the GNRM system.

        The multiplier blocks are r dL/dlam = (min(lam + r g, 0) - lam) mu
        and (P(lam_t + r_t dg_t) - lam_t) . mu_t, in force units.
        """
        return self._system("augmented", lagrangian(self.potential, self.contacts),
                            with_lam=True, tangential=lambda f: f.traction_t)

    def primal_system(self) -> VariationalSystem:
        """Equilibrium in u with the multipliers held fixed (the Uzawa inner problem)."""
        return self._system("primal", lagrangian(self.potential, self.contacts),
                            with_lam=False, tangential=lambda f: f.traction_t)

    def penalty_system(self) -> VariationalSystem:
        """Penalty regularisation (paper eq. 7) in u only; friction by regularised stick.

        The disc radius is mu r max(-g, 0); lam_t holds the traction committed
        at the last converged step (updated by :meth:`commit`).
        """
        return self._system("penalty", penalty_energy(self.potential, self.contacts),
                            with_lam=False, tangential=lambda f: f.penalty_traction)

    def complementarity_residual(self) -> ufl.Form | list[ufl.Form]:
        """(min(lam + r g, 0) - lam) mu per contact, and the tangential ones (force units).

        One form for one frictionless contact, else a list.
        """
        forms = complementarity_forms(self.contacts)
        return forms[0] if len(forms) == 1 else forms

    # -- diagnostics ---------------------------------------------------------------------
    def contact_state(self) -> ContactState:
        """Nodal gaps, pressures, the active set and global summaries (fresh searches).

        One contact: its state (with friction, a FrictionalContactState);
        several: the contacts' states joined (:func:`~.state.combined_state`).
        """
        return combined_state([c.contact_state() for c in self.contacts])

    def contact_states(self) -> dict[str, ContactState]:
        """Each contact's state by name."""
        return {c.name: c.contact_state() for c in self.contacts}

    def active_signature(self) -> tuple[bytes, ...]:
        """A hashable fingerprint of the global active set (with friction: open/stick/slip)."""
        local = b"|".join(c.active_pattern() for c in self.contacts)
        return tuple(self.comm.allgather(local))

    def update_multiplier(self) -> None:
        """Uzawa update of every multiplier at the current iterate (paper eq. 10)."""
        for c in self.contacts:
            c.update_multiplier()

    def nodal_pressure(self, lam: np.ndarray) -> np.ndarray:
        """The first contact's owned nodal pressure for multiplier values ``lam``."""
        return self.contact.nodal_pressure(lam)

    def nodal_coordinates(self) -> np.ndarray:
        """Reference coordinates of the owned multiplier nodes of every contact, shape (n, 3)."""
        return np.concatenate([c.nodal_coordinates() for c in self.contacts])

    def stresses(self) -> list[tuple[ufl.core.expr.Expr, np.ndarray | None]]:
        """Each body's Cauchy stress (UFL) and its cells (None: every cell)."""
        return self.solid.stresses()

    def body_ids(self) -> fem.Function | None:
        """Cell-wise body index for the output; None for a single body."""
        return self.solid.body_ids()

    def reaction(self, facets: np.ndarray) -> np.ndarray:
        """Internal nodal force summed over the facets' nodes (see :meth:`Solid.reaction`)."""
        return self.solid.reaction(facets)

    def support_reactions(self) -> dict[str, list[float]]:
        """Each support's force on the bodies (see :meth:`Solid.support_reactions`)."""
        return self.solid.support_reactions()

    def support_total(self) -> list[float]:
        """All supports' force on the bodies, each held component once (see Solid)."""
        return self.solid.support_total()

    def prescribed_mismatch(self) -> float:
        """Largest |u - u_D| over the prescribed components (length, global)."""
        return self.solid.prescribed_mismatch()

    def min_det_F(self) -> DetFMinimum:
        """Smallest det F over the bodies (see :meth:`Solid.min_det_F`)."""
        return self.solid.min_det_F()

    def unheld_motion(self, gap_tol: float) -> list[tuple[str, str]]:
        """A rigid motion that the supports and the contacts closed in this state leave free.

        (body name, its part of the motion in words) per moving body; [] when
        every body is held. Closed: active or within ``gap_tol`` h of touching
        (see :meth:`~.holding.ContactHold.in_state`). Collective; the bodies'
        nodes are gathered on the first call. Not checked ([]) with
        displacements of degree > 1 (the rigid modes are set at the vertices).
        """
        if self.solid.degree != 1 or all(b.stabilise > 0.0 for b in self.solid.bodies):
            return []  # weak springs hold a stabilised body
        if self._hold is None:
            from fenics_contact.model.holding import ContactHold

            self._hold = ContactHold(self)
        return self._hold.in_state(gap_tol)

    def balls_passed_through(self) -> list[str]:
        """The contacts whose rigid ball has its centre inside the deformed body (collective).

        See :mod:`.passage`; [] with displacements of degree > 1.
        """
        if self.solid.degree != 1:
            return []
        from fenics_contact.model.passage import balls_passed_through

        return balls_passed_through(self.V, self.u, self.contacts)

    def stabilisation_forces(self) -> dict[str, np.ndarray]:
        """The force each stabilised body's springs put on it (collective; force)."""
        return {b.name: self.solid.stabilisation_force(b.name) for b in self.solid.bodies
                if b.stabilise > 0.0}

    def slot_uses(self) -> list:
        """Each 2D mortar pair's :class:`~.contacts.SlotUse` (collective)."""
        return [use for c in self.contacts if (use := c.slot_use()) is not None]

    def target_force(self) -> fem.Function:
        """Force the strikers put on their targets' vertices, summed over the pairs (force).

        Every two-body and self-contact pair adds its own (a body that is the
        target of one pair and the striker of another carries the first
        one's only: a striker's own nodes take their force as the multiplier).
        Zero where no pair has a target (everywhere without pairs).
        """
        pairs = [c for c in self.contacts if hasattr(c, "target_force")]
        total = fem.Function(self.V, name="target_contact_force")
        for contact in pairs:
            total.x.array[:] += contact.target_force().x.array
        total.x.scatter_forward()
        return total


__all__ = [
    "Body", "ContactProblem", "ContactState", "PathDisplacement", "PrescribedDisplacement",
    "ProblemState", "Solid", "SurfaceTraction", "Transfers", "VariationalSystem", "Work",
    "energy_quadrature_degree", "one_body_problem", "two_body_problem",
]
