"""A contact problem: a solid (bodies in one mesh) and a list of contacts.

The problem owns nothing but the composition: the displacement ``u`` and
the conditions belong to the :class:`~.body.Solid`, each contact
(:mod:`.obstacle_contact`, :mod:`.pairs`) owns its multiplier ``lam`` (P1
on its contact submesh), its parameter ``r`` and its friction. The problem
hands solvers :class:`VariationalSystem` objects (UFL residual blocks with
their unknowns: u, every contact's lam, every frictional contact's lam_t,
then the deformable targets' extras) and never imports a solver itself. All
loads are proportional to one load factor ``t`` in [0, 1].

Solvers see one system and one set of answers (the state, the active
pattern, the multiplier update, the checks) whatever the contacts are; the
accessors that name one contact's objects (``lam``, ``surface``, ...) are
those of the first contact.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
from dolfinx import fem, mesh

from fenics_contact.model.body import (
    Body,
    DetFMinimum,
    PathDisplacement,
    PrescribedDisplacement,
    Solid,
    SurfaceTraction,
    energy_quadrature_degree,
)
from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.contacts import Contact
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import Elastic
from fenics_contact.model.obstacle_contact import ObstacleContact
from fenics_contact.model.obstacles import RigidObstacle
from fenics_contact.model.state import ContactState, ProblemState, combined_state
from fenics_contact.model.tags import facet_roles

#: A non-potential residual term: (coefficient, test function) -> form (or None).
Work = Callable[[fem.Function, ufl.Argument], ufl.Form]


@dataclass
class VariationalSystem:
    """Residual blocks F_i(unknowns; tests) = 0 and what a solver needs to compile them.

    Systems with deformable targets add ``extras``: coefficients (the target
    vertex displacements w_k) that are a selection of ``unknowns[0]``
    (w_k = S_k u), with one more residual block each after the unknowns'
    blocks; ``transfer`` refreshes them (search) and names the selected
    blocks (``sources()``, ``version``). A solver condenses them away
    (solvers/condensed.py).
    """

    name: str
    residuals: list[ufl.Form]
    unknowns: list[fem.Function]
    bcs: list[fem.DirichletBC]
    entity_maps: list = field(default_factory=list)
    extras: list[fem.Function] = field(default_factory=list)
    transfer: object | None = None


class Transfers:
    """The searches of several deformable contacts seen as one (refresh, version, sources)."""

    def __init__(self, transfers: Sequence[object]) -> None:
        self.transfers = list(transfers)

    def refresh(self) -> bool:
        """Refresh every search; True when some assignment changed."""
        changed = [t.refresh() for t in self.transfers]
        return any(changed)

    @property
    def version(self) -> int:
        """Grows whenever some search changes an assignment."""
        return sum(t.version for t in self.transfers)

    def sources(self) -> list[np.ndarray]:
        """Every contact's selections, in the order of the systems' extras."""
        return [s for t in self.transfers for s in t.sources()]


class ContactProblem:
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
        groups = [c.facets for c in self.contacts] + [t.facets for t in solid.tractions]
        self.facet_tags, ids = facet_roles(self.domain, groups)
        for contact, tag_ids in zip(self.contacts, ids, strict=False):
            contact.bind(solid, self.facet_tags, tag_ids)
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

    def _friction(self):
        frictional = [c.friction for c in self.contacts if c.friction is not None]
        if not frictional:
            raise AttributeError("The problem has no frictional contact.")
        return frictional

    @property
    def lam_t(self) -> fem.Function:
        """The first frictional contact's tangential multiplier."""
        return self._friction()[0].lam_t

    @property
    def mu(self) -> fem.Constant:
        """The first frictional contact's friction coefficient (a Constant)."""
        return self._friction()[0].mu

    @property
    def friction_coefficient(self) -> float:
        """The first frictional contact's mu (dimensionless)."""
        return float(self.mu.value)

    @property
    def contact_extent(self) -> float:
        """Extent L of the first frictional contact's surface (length)."""
        return self._friction()[0].contact_extent

    @property
    def symmetry_constraints(self) -> int:
        """Tangential components held at 0 by symmetry planes, over every contact."""
        return sum(f.symmetry_constraints for f in self._friction())

    # -- unknowns ----------------------------------------------------------------------
    def normal_multipliers(self) -> list[fem.Function]:
        """Each contact's lam (<= 0, the pressure), in the order of the contacts."""
        return [c.lam for c in self.contacts]

    @property
    def multiplier_dofs(self) -> int:
        """Global number of normal multiplier degrees of freedom over the contacts."""
        return sum(c.surface.num_dofs for c in self.contacts)

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
        return [m for c in self.contacts for m in c.surface.entity_maps]

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
        """Residual blocks from an energy plus the friction work.

        The residual of u (and of each extra coefficient c) is
        dE/dc[test] + sum over frictional contacts of tau . d(dg_t)/dc[test],
        tau = ``tangential(friction)``; with ``with_lam`` every contact's
        multiplier block r dE/dlam[mu] (force units) follows u, then every
        frictional contact's tangential block, before the extras' blocks.
        """
        frictions = [c.friction for c in self.contacts if c.friction is not None]

        def residual(c: fem.Function) -> ufl.Form:
            test = ufl.TestFunction(c.function_space)
            form = ufl.derivative(energy, c, test)
            if tangential is not None:
                for f in frictions:
                    form += f.work(tangential(f), c, test)
            return form

        residuals = [residual(self.u)]
        unknowns = [self.u]
        if with_lam:
            for c in self.contacts:
                residuals.append(c.r * ufl.derivative(energy, c.lam, ufl.TestFunction(c.Q)))
                unknowns.append(c.lam)
            for f in frictions:
                residuals.append(f.tangential_residual())
                unknowns.append(f.lam_t)
        extras = [w for c in self.contacts for w in c.extras()]
        residuals += [residual(w) for w in extras]
        transfers = [c.transfer for c in self.contacts if c.transfer is not None]
        transfer = None
        if extras:
            transfer = transfers[0] if len(transfers) == 1 else Transfers(transfers)
        return VariationalSystem(name, residuals, unknowns, self.bcs, self.entity_maps,
                                 extras=extras, transfer=transfer)

    def _lagrangian(self) -> ufl.Form:
        """Pi + sum over the contacts of int AL density ds (paper eq. 9)."""
        form = self.potential
        for c in self.contacts:
            form = form + c.lagrangian()
        return form

    def _penalty_energy(self) -> ufl.Form:
        """Pi + sum over the contacts of int r/2 min(g, 0)^2 ds (paper eq. 7)."""
        form = self.potential
        for c in self.contacts:
            form = form + c.penalty()
        return form

    def _suffix(self) -> str:
        return "_friction" if self.frictional else ""

    def augmented_system(self) -> VariationalSystem:
        """Alart-Curnier saddle point on (u, lam[, lam_t]): the GNRM system.

        The multiplier blocks are r dL/dlam = (min(lam + r g, 0) - lam) mu
        and (P(lam_t + r_t dg_t) - lam_t) . mu_t, in force units.
        """
        return self._system("augmented" + self._suffix(), self._lagrangian(), with_lam=True,
                            tangential=lambda f: f.traction_t)

    def primal_system(self) -> VariationalSystem:
        """Equilibrium in u with the multipliers held fixed (the Uzawa inner problem)."""
        return self._system("primal" + self._suffix(), self._lagrangian(), with_lam=False,
                            tangential=lambda f: f.traction_t)

    def penalty_system(self) -> VariationalSystem:
        """Penalty regularisation (paper eq. 7) in u only; friction by regularised stick.

        The disc radius is mu r max(-g, 0); lam_t holds the traction committed
        at the last converged step (updated by :meth:`commit`).
        """
        return self._system("penalty" + self._suffix(), self._penalty_energy(), with_lam=False,
                            tangential=lambda f: f.penalty_traction)

    def complementarity_residual(self) -> ufl.Form | list[ufl.Form]:
        """(min(lam + r g, 0) - lam) mu per contact, and the tangential ones (force units).

        One form for one frictionless contact, else a list.
        """
        forms = [c.complementarity_residual() for c in self.contacts]
        forms += [f.tangential_residual() for f in self._frictions()]
        return forms[0] if len(forms) == 1 else forms

    def _frictions(self) -> list:
        return [c.friction for c in self.contacts if c.friction is not None]

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

    def laws(self) -> list[tuple[Elastic, np.ndarray | None]]:
        """Each body's law and its cells (None: every cell)."""
        return self.solid.laws()

    def body_ids(self) -> fem.Function | None:
        """Cell-wise body index for the output; None for a single body."""
        return self.solid.body_ids()

    def reaction(self, facets: np.ndarray) -> np.ndarray:
        """Internal nodal force summed over the facets' nodes (see :meth:`Solid.reaction`)."""
        return self.solid.reaction(facets)

    def prescribed_mismatch(self) -> float:
        """Largest |u - u_D| over the prescribed components (length, global)."""
        return self.solid.prescribed_mismatch()

    def min_det_F(self) -> DetFMinimum:
        """Smallest det F over the bodies (see :meth:`Solid.min_det_F`)."""
        return self.solid.min_det_F()

    def target_force(self) -> fem.Function:
        """Force the first contact's striker puts on its target's vertices (pairs only)."""
        return self.contact.target_force()

    # -- friction over every frictional contact ----------------------------------------------
    @property
    def tangential_r(self) -> float:
        """The first frictional contact's r_t (stress per length)."""
        return self._friction()[0].tangential_r

    @property
    def tangential_cap(self) -> float:
        """The first frictional contact's cap of r_t (stress per length)."""
        return self._friction()[0].tangential_cap

    def set_tangential_cap(self, cap: float) -> None:
        """Set the cap of r_t of every frictional contact (absolute, stress per length)."""
        for f in self._friction():
            f.set_tangential_cap(cap)

    def lower_tangential_r(self, factor: float = 0.5) -> float:
        """Cap r_t at ``factor`` times its current value on every frictional contact.

        The converged nodal answer does not depend on r_t; a smaller r_t keeps
        the stick/slip guess from flipping (see :mod:`.friction`). Returns the
        first frictional contact's new r_t (stress per length).
        """
        for f in self._friction():
            f.set_tangential_cap(factor * f.tangential_r)
        return self.tangential_r

    def tangential_fields(self) -> tuple[np.ndarray, np.ndarray]:
        """Owned nodal tangential traction on the body and slip, global axes (joined)."""
        pairs = [f.tangential_fields() for f in self._friction()]
        return (np.concatenate([p[0] for p in pairs]), np.concatenate([p[1] for p in pairs]))

    def tangential_force_vector(self) -> np.ndarray:
        """Sum over the frictional contacts of int T tau dA (force): minus the friction."""
        return sum(f.tangential_force_vector() for f in self._friction())

    def node_states(self) -> np.ndarray:
        """Per owned node of the frictional contacts: 0 open, 1 stick, 2 slip."""
        return np.concatenate([f.node_states() for f in self._friction()])

    def coulomb_violations(self) -> tuple[float, float, float]:
        """Worst nodal violations of the Coulomb conditions over every frictional contact."""
        worst = [f.coulomb_violations() for f in self._friction()]
        return tuple(max(w[i] for w in worst) for i in range(3))

    def complementarity_norms(self) -> tuple[float, float]:
        """Euclidean norms of the normal and tangential complementarity residuals (force)."""
        squares = [f.complementarity_squares() for f in self._friction()]
        return (float(np.sqrt(sum(s[0] for s in squares))),
                float(np.sqrt(sum(s[1] for s in squares))))


# -- the two common compositions ---------------------------------------------------------------
def one_body_problem(
    domain: mesh.Mesh,
    material: Elastic,
    obstacle: RigidObstacle,
    contact_facets: np.ndarray,
    settings: ContactSettings,
    *,
    prescribed: Sequence[PrescribedDisplacement] = (),
    tractions: Sequence[SurfaceTraction] = (),
    obstacle_motion: Sequence[float] | None = None,
    obstacle_schedule: Sequence[Sequence[float]] | None = None,
    degree: int = 1,
    friction: FrictionSettings | None = None,
) -> ContactProblem:
    """One deformable body (every cell) against one rigid obstacle."""
    solid = Solid(domain, [Body("body", None, material)], prescribed=prescribed,
                  tractions=tractions, degree=degree)
    contact = ObstacleContact(obstacle, contact_facets, settings, motion=obstacle_motion,
                              schedule=obstacle_schedule, friction=friction)
    return ContactProblem(solid, [contact])


def two_body_problem(
    domain: mesh.Mesh,
    cell_tags: mesh.MeshTags,
    bodies: Sequence[Body],
    striker_facets: np.ndarray,
    target_facets: np.ndarray,
    settings: ContactSettings,
    *,
    striker: str | None = None,
    target: str | None = None,
    prescribed: Sequence[PrescribedDisplacement] = (),
    tractions: Sequence[SurfaceTraction] = (),
    degree: int = 1,
    friction: FrictionSettings | None = None,
    name: str = "pair",
) -> ContactProblem:
    """Bodies of one mesh with one node-to-segment pair (striker against target)."""
    from fenics_contact.model.pairs import NodeToSegmentContact

    solid = Solid(domain, bodies, cell_tags, prescribed=prescribed, tractions=tractions,
                  degree=degree)
    contact = NodeToSegmentContact(striker_facets, target_facets, settings, striker=striker,
                                   target=target, friction=friction, name=name)
    return ContactProblem(solid, [contact])


__all__ = [
    "Body", "ContactProblem", "ContactState", "PathDisplacement", "PrescribedDisplacement",
    "ProblemState", "Solid", "SurfaceTraction", "Transfers", "VariationalSystem", "Work",
    "energy_quadrature_degree", "one_body_problem", "two_body_problem",
]
