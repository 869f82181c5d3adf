"""A prescribed striker node against one facet of a deformable body (node-to-segment, 2D).

The paper's Example 1 contact element: a striker node whose position x_s(t)
is prescribed, and a target facet with vertices a, b on the deformable body.
The normal gap is the node-to-segment gap

    g = (x_s - x_a) . n,   n = perp(x_b - x_a) / |x_b - x_a|,

with x_a, x_b the current positions (X + u) of the facet's vertices and n
its outward unit normal. g is nonlinear in u: the facet rotates and
stretches. Sign conventions as everywhere: g >= 0 open, lam <= 0.

How the gap is written in UFL, on the target facet itself. On a straight
facet of a P1/Q1 element, x(X) = X + u(X) is linear along the facet, so its
derivative along the reference edge vector T = X_b - X_a is the constant
current edge vector, (I + grad u) T = x_b - x_a, and the vertex a is found
from any point of the facet as x_a = x - s (x_b - x_a), s = (X - X_a).T/|T|^2.
The gap is therefore one UFL expression of u, constant along the facet, and
``ufl.derivative`` gives its consistent linearisation, facet rotation
included (no hand-written tangent). The contact term is a point term: its
density is divided by the facet's reference length L and integrated with a
one-point rule, so int (.) / L ds is the value at the striker.

The multiplier is one scalar per contact element: a DG0 function on the
submesh made of the target facet (force per unit thickness, <= 0). The
projection of the striker is not clipped to the facet (the gap is to the
facet's line): the striker must stay between a and b, which
:meth:`StrikerOnFacetProblem.contact_point` lets a caller check.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import default_scalar_type, fem, mesh

from fenics_contact.model.contact import (
    CONTACT_TAG,
    ContactSettings,
    assemble_local,
    augmented_lagrangian_energy,
    augmented_pressure,
    check_r,
    penalty_energy,
)
from fenics_contact.model.materials import Elastic
from fenics_contact.model.problem import (
    Body,
    ContactState,
    PrescribedDisplacement,
    ProblemState,
    Solid,
    VariationalSystem,
)


def node_to_segment_gap(
    x_s: ufl.core.expr.Expr, x_a: ufl.core.expr.Expr, x_b: ufl.core.expr.Expr
) -> ufl.core.expr.Expr:
    """Normal gap (length) of the point x_s to the line through x_a, x_b (2D).

    The normal perp(x_b - x_a) = (-t_y, t_x)/|t| points to the left of a -> b;
    order the vertices so that it points out of the body.
    """
    t = x_b - x_a
    n = ufl.as_vector((-t[1], t[0])) / ufl.sqrt(ufl.dot(t, t))
    return ufl.dot(x_s - x_a, n)


@dataclass
class TargetSurface:
    """The target facet's submesh, its multiplier space and the point measure."""

    #: The point measure sits at the striker node: the nodal rule.
    quadrature = "nodal"

    submesh: mesh.Mesh
    Q: fem.FunctionSpace
    ds: ufl.Measure
    entity_maps: list
    length: float

    @property
    def h(self) -> float:
        """Size of the target facet (length): the scale of the Signorini test."""
        return self.length

    @property
    def num_dofs(self) -> int:
        """Global number of multiplier degrees of freedom (one: the striker's force)."""
        return self.Q.dofmap.index_map.size_global


def _oriented_vertices(domain: mesh.Mesh, facet: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reference vertices (a, b) of the facet, ordered so perp(b - a) points out of the body.

    The facet may live on one rank only; every rank gets the coordinates.
    """
    tdim = domain.topology.dim
    n_global = domain.comm.allreduce(int(facet.size))
    if n_global != 1:
        raise ValueError(
            f"The target must be exactly one facet of the mesh, got {n_global}; "
            "pass the index of one boundary facet (an empty array on the other ranks)."
        )
    domain.topology.create_connectivity(tdim - 1, tdim)
    domain.topology.create_connectivity(tdim - 1, 0)
    found = None
    if facet.size:
        nodes = mesh.entities_to_geometry(domain, tdim - 1, facet)[0]
        a, b = domain.geometry.x[nodes, :2]
        cell = domain.topology.connectivity(tdim - 1, tdim).links(int(facet[0]))[0]
        cell_nodes = mesh.entities_to_geometry(domain, tdim, np.array([cell], np.int32))[0]
        centre = domain.geometry.x[cell_nodes, :2].mean(axis=0)
        t = b - a
        if np.dot(np.array([-t[1], t[0]]), 0.5 * (a + b) - centre) < 0:
            a, b = b, a
        found = (a.copy(), b.copy())
    return next(v for v in domain.comm.allgather(found) if v is not None)


class StrikerOnFacetProblem:
    """One deformable body, one prescribed striker node, one target facet.

    Exposes the system methods of :class:`fenics_contact.model.problem.ContactProblem`
    (``augmented_system``, ``primal_system``, ``penalty_system``,
    ``complementarity_residual``, ``contact_state``, ``active_signature``,
    ``update_multiplier``, ``set_load``, ``set_r``), so every strategy of
    :mod:`fenics_contact.solvers` runs on it.

    Args:
        domain: the body (2D).
        material: its strain energy.
        target_facet: the target facet (local index array with one entry on
            the rank that owns it, empty elsewhere).
        striker_start: striker position at load factor 0 (length).
        striker_motion: striker displacement at load factor 1 (length).
        settings: r (absolute, or relative to E/L with L the facet length).
        prescribed: Dirichlet conditions, proportional to the load factor.
        energy_quadrature_degree: quadrature degree of the strain energy
            (2 on quadrilaterals: 2 x 2 Gauss, the full integration of the
            paper's code).
    """

    #: No friction; lam is the striker's force.
    frictional = False
    multiplier_is_pressure = True

    def __init__(
        self,
        domain: mesh.Mesh,
        material: Elastic,
        target_facet: np.ndarray,
        striker_start: Sequence[float],
        striker_motion: Sequence[float],
        settings: ContactSettings,
        *,
        prescribed: Sequence[PrescribedDisplacement] = (),
        energy_quadrature_degree: int = 2,
    ) -> None:
        if domain.topology.dim != 2 or domain.geometry.dim != 2:
            raise ValueError("The node-to-segment striker problem is 2D; give a 2D mesh.")
        if domain.geometry.cmaps[0].degree != 1:
            raise ValueError(
                f"The target facet must be straight, but the mesh geometry has degree "
                f"{domain.geometry.cmaps[0].degree}; use an affine (degree 1) mesh."
            )
        for name, value in (("striker_start", striker_start), ("striker_motion", striker_motion)):
            if len(value) != 2:
                raise ValueError(f"{name} = {tuple(value)} needs two coordinates (x, y).")
        self.domain = domain
        self.comm = domain.comm
        self.material = material
        self.settings = settings
        fdim = 1
        facet = np.asarray(target_facet, np.int32)
        x_a, x_b = _oriented_vertices(domain, facet)
        self.reference_vertices = (x_a, x_b)
        length = float(np.linalg.norm(x_b - x_a))
        self._start = np.asarray(striker_start, float)
        self._motion = np.asarray(striker_motion, float)

        self.solid = Solid(domain, [Body("body", None, material)], prescribed=prescribed,
                           quadrature_degree=energy_quadrature_degree)
        self.V = self.solid.V
        self.u = self.solid.u
        self.bcs = self.solid.bcs
        tags = mesh.meshtags(domain, fdim, facet, np.full(facet.size, CONTACT_TAG, np.int32))
        submesh, entity_map, _, _ = mesh.create_submesh(domain, fdim, facet)
        Q = fem.functionspace(submesh, ("DG", 0))
        ds = ufl.Measure(
            "ds", domain=domain, subdomain_data=tags, subdomain_id=CONTACT_TAG,
            metadata={"quadrature_degree": 1},
        )
        self.surface = TargetSurface(submesh, Q, ds, [entity_map], length)
        self.Q = Q
        self.lam = fem.Function(Q, name="contact_force")
        self.r = fem.Constant(domain, default_scalar_type(1.0))
        self.set_r(settings.r, relative=settings.relative)
        self.load_factor = 0.0
        self.striker = fem.Constant(domain, self._start.copy())

        # the gap at the striker, from u on the target facet
        X = ufl.SpatialCoordinate(domain)
        Xa = fem.Constant(domain, x_a)
        T = fem.Constant(domain, x_b - x_a)
        edge = (ufl.Identity(2) + ufl.grad(self.u)) * T  # current x_b - x_a
        s = ufl.dot(X - Xa, T) / ufl.dot(T, T)
        xa = X + self.u - s * edge
        self.gap = node_to_segment_gap(self.striker, xa, xa + edge)
        self.contact_parameter = ufl.dot(self.striker - xa, edge) / ufl.dot(edge, edge)
        self.pressure = augmented_pressure(self.gap, self.lam, self.r)
        self._inv_length = fem.Constant(domain, default_scalar_type(1.0 / length))

        self.potential = self.solid.strain_energy()

        mu = ufl.TestFunction(Q)
        self._mu = mu
        maps = self.surface.entity_maps
        self._weights = assemble_local(fem.form(self.at_striker(mu), entity_maps=maps))
        self._gap_form = fem.form(self.at_striker(self.gap * mu), entity_maps=maps)
        self._pressure_form = fem.form(self.at_striker(self.pressure * mu), entity_maps=maps)
        self._xi_form = fem.form(self.at_striker(self.contact_parameter * mu), entity_maps=maps)

    def at_striker(self, density: ufl.core.expr.Expr) -> ufl.Form:
        """The point term: int density / L ds over the target facet, one-point rule.

        Exact for the densities used here, which are constant along the facet.
        """
        return density * self._inv_length * self.surface.ds

    # -- parameters and loads -------------------------------------------------
    @property
    def stiffness_scale(self) -> float:
        """E/L with L the target facet's length: the scale of relative r."""
        return self.material.E / self.surface.length

    def set_load(self, t: float) -> None:
        """Move the striker to start + t motion and scale the prescribed values."""
        self.load_factor = float(t)
        self.striker.value[:] = self._start + t * self._motion
        self.solid.set_load(t)

    @property
    def h(self) -> float:
        """The target facet's length: the length scale of the checks."""
        return self.surface.h

    #: The point measure sits at the striker node.
    nodal_rule = True
    #: One contact: no node is shared between contacts.
    shared_contact_nodes = 0
    name = "striker"

    @property
    def contacts(self) -> list[StrikerOnFacetProblem]:
        """The one contact: the problem itself (its surface, state and comm)."""
        return [self]

    @property
    def entity_maps(self) -> list:
        """The target facet submesh's entity map."""
        return self.surface.entity_maps

    @property
    def multiplier_dofs(self) -> int:
        """One: the striker's force."""
        return self.surface.num_dofs

    def rescale_r(self, r: float) -> None:
        """Set r (absolute, force per length: one contact)."""
        self.r.value = r

    def set_r(self, r: float, *, relative: bool) -> None:
        """Set r, relative to E/L or absolute (stress per length)."""
        check_r(r)
        self.r.value = r * self.stiffness_scale if relative else r

    @property
    def r_absolute(self) -> float:
        """R in stress per length."""
        return float(self.r.value)

    @property
    def r_relative(self) -> float:
        """R divided by E/L."""
        return self.r_absolute / self.stiffness_scale

    def commit(self) -> None:
        """Accept the converged state (nothing history-dependent here)."""

    def multipliers(self) -> list[fem.Function]:
        """The striker's contact force."""
        return [self.lam]

    normal_multipliers = multipliers

    def snapshot(self) -> ProblemState:
        """Copy u, lam and the load factor."""
        return ProblemState(self.u.x.array.copy(), (self.lam.x.array.copy(),), self.load_factor)

    def restore(self, state: ProblemState, *, load: bool = True) -> None:
        """Put back a :meth:`snapshot`; ``load=False`` keeps the current load factor."""
        self.u.x.array[:] = state.u
        self.lam.x.array[:] = state.multipliers[0]
        if load:
            self.set_load(state.load_factor)

    def prescribed_mismatch(self) -> float:
        """Largest |u - u_D| over the prescribed components (length, global)."""
        return self.solid.prescribed_mismatch()

    def balls_passed_through(self) -> list[str]:
        """No rigid ball here: [] (see ContactProblem.balls_passed_through)."""
        return []

    def unheld_motion(self, gap_tol: float) -> list[tuple[str, str]]:
        """A rigid motion of the body that its supports leave free ([] when they hold it).

        The striker, one prescribed point on one facet, is not counted (the
        paper's Example 1 is clamped on two faces); ``gap_tol`` is unused.
        See :meth:`fenics_contact.model.problem.ContactProblem.unheld_motion`.
        """
        from fenics_contact.model.rigid import free_rigid_motions

        conditions = [(p.facets, p.at(1.0)) for p in self.solid.prescribed]
        return [("body", m) for m in free_rigid_motions(self.domain, conditions)]

    def residual_roundoff(self) -> tuple[float, float, float]:
        """Not measured here: zeros (see ContactProblem.residual_roundoff)."""
        return 0.0, 0.0, 0.0

    def stabilisation_forces(self) -> dict[str, np.ndarray]:
        """No stabilised body here: {} (see ContactProblem.stabilisation_forces)."""
        return {}

    def min_det_F(self):
        """Smallest det F over the body."""
        return self.solid.min_det_F()

    # -- systems handed to solvers -------------------------------------------
    def _lagrangian(self) -> ufl.Form:
        return self.potential + self.at_striker(
            augmented_lagrangian_energy(self.gap, self.lam, self.r)
        )

    def augmented_system(self) -> VariationalSystem:
        """Alart-Curnier saddle point on (u, lam), the GNRM system.

        The multiplier block is r dL/dlam = min(lam + r g, 0) - lam (force).
        """
        v = ufl.TestFunction(self.V)
        lagrangian = self._lagrangian()
        return VariationalSystem(
            "striker_augmented",
            [ufl.derivative(lagrangian, self.u, v),
             self.r * ufl.derivative(lagrangian, self.lam, self._mu)],
            [self.u, self.lam], self.bcs, self.surface.entity_maps,
        )

    def primal_system(self) -> VariationalSystem:
        """Equilibrium in u with lam held fixed (the Uzawa inner problem)."""
        v = ufl.TestFunction(self.V)
        return VariationalSystem(
            "striker_primal", [ufl.derivative(self._lagrangian(), self.u, v)], [self.u],
            self.bcs, self.surface.entity_maps,
        )

    def penalty_system(self) -> VariationalSystem:
        """Penalty (paper eq. 7) at the striker: Pi + r/2 min(g, 0)^2, u only."""
        v = ufl.TestFunction(self.V)
        energy = self.potential + self.at_striker(penalty_energy(self.gap, self.r))
        return VariationalSystem(
            "striker_penalty", [ufl.derivative(energy, self.u, v)], [self.u], self.bcs,
            self.surface.entity_maps,
        )

    def complementarity_residual(self) -> ufl.Form:
        """(min(lam + r g, 0) - lam) mu at the striker (force)."""
        return self.at_striker((self.pressure - self.lam) * self._mu)

    # -- diagnostics -----------------------------------------------------------
    def _values(self, compiled: fem.Form) -> np.ndarray:
        return assemble_local(compiled) / self._weights

    def contact_point(self) -> np.ndarray:
        """Parameter xi of the striker's projection on the current facet (0 at a, 1 at b)."""
        return self._values(self._xi_form)

    def contact_state(self) -> ContactState:
        """Gap, transmitted force min(lam + r g, 0) (<= 0, per unit thickness) and summaries."""
        gap = self._values(self._gap_form)
        pressure = self._values(self._pressure_form)
        return ContactState.gathered(
            self.comm, gap, pressure, self.lam.x.array[: gap.size].copy(), float(-pressure.sum())
        )

    def contact_states(self) -> dict[str, ContactState]:
        """The one contact's state by name."""
        return {self.name: self.contact_state()}

    def active_signature(self) -> tuple[bytes, ...]:
        """Whether the striker transmits a force (lam + r g < 0), gathered over ranks."""
        active = self._values(self._pressure_form) < 0.0
        return tuple(self.comm.allgather(np.packbits(active).tobytes()))

    def update_multiplier(self) -> None:
        """Uzawa update lam <- min(lam + r g, 0) (paper eq. 10)."""
        pressure = self._values(self._pressure_form)
        self.lam.x.array[: pressure.size] = pressure
        self.lam.x.scatter_forward()
