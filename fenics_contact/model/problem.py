"""A hyperelastic body against a rigid obstacle: unknowns, loads and UFL forms.

The problem owns the displacement ``u`` (vector P-k on the body), the
multiplier ``lam`` (P1 on the contact submesh), the load factor and the
parameter ``r``; it hands solvers :class:`VariationalSystem` objects (UFL
residual blocks with their unknowns) and never imports a solver itself.
All loads are proportional to one load factor ``t`` in [0, 1].
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import ufl
import ufl.algorithms
from dolfinx import default_scalar_type, fem, mesh

from mpi4py import MPI

from fenics_contact.model.contact import (
    CONTACT_TAG,
    ContactSettings,
    ContactSurface,
    augmented_lagrangian_energy,
    augmented_pressure,
    check_r,
    penalty_energy,
)
from fenics_contact.model.materials import Elastic
from fenics_contact.model.obstacles import RigidObstacle


@dataclass(frozen=True)
class PrescribedDisplacement:
    """Displacement imposed on facets, proportional to the load factor.

    Attributes:
        facets: facet indices (local) where the condition holds.
        value: final displacement per component (length units); ``None``
            leaves that component free.
    """

    facets: np.ndarray
    value: tuple[float | None, ...]

    def at(self, t: float) -> tuple[float | None, ...]:
        """Displacement per component at load factor t (None: free)."""
        return tuple(None if v is None else t * float(v) for v in self.value)


@dataclass(frozen=True)
class PathDisplacement(PrescribedDisplacement):
    """A prescribed displacement along a piecewise-linear path in the load factor.

    Attributes:
        path: knots (t, u_1, ..., u_d), t increasing from 0 to 1 (length units);
            every component is prescribed and ``value`` (the end point) is unused.
    """

    path: tuple[tuple[float, ...], ...] = ()

    def at(self, t: float) -> tuple[float | None, ...]:
        """Displacement at load factor t (linear between knots)."""
        knots = np.asarray(self.path, float)
        return tuple(float(np.interp(t, knots[:, 0], knots[:, 1 + i]))
                     for i in range(knots.shape[1] - 1))


@dataclass(frozen=True)
class SurfaceTraction:
    """Traction on facets per unit reference area, proportional to the load factor."""

    facets: np.ndarray
    value: tuple[float, ...]


def _schedule(
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


def energy_quadrature_degree(psi: ufl.core.expr.Expr, u: fem.Function, degree: int) -> int:
    """Quadrature degree for the strain energy and its derivatives.

    UFL's estimate for the tangent, capped at 2 (degree + 1): exact for
    linear elasticity and St. Venant-Kirchhoff on simplices and for linear
    elasticity on quadrilaterals/hexahedra, and it keeps non-polynomial
    laws (neo-Hookean: estimate 17 on hexahedra) affordable.
    """
    v = ufl.TestFunction(u.function_space)
    tangent = ufl.derivative(ufl.derivative(psi * ufl.dx, u, v), u)
    integrand = ufl.algorithms.expand_derivatives(tangent).integrals()[0].integrand()
    estimate = ufl.algorithms.estimate_total_polynomial_degree(integrand)
    return int(min(estimate, 2 * (degree + 1)))


#: A non-potential residual term: (coefficient, test function) -> form (or None).
Work = Callable[[fem.Function, ufl.Argument], ufl.Form]

#: Facet tag of the first traction; the i-th traction has TRACTION_TAG0 + i.
TRACTION_TAG0 = 100


def _facet_tags(
    domain: mesh.Mesh, contact_facets: np.ndarray, tractions: Sequence[SurfaceTraction]
) -> mesh.MeshTags:
    """One facet tag set for every ``ds``: contact facets and each traction's facets."""
    fdim = domain.topology.dim - 1
    groups = [(np.unique(np.asarray(contact_facets, np.int32)), CONTACT_TAG)] + [
        (np.asarray(t.facets, np.int32), TRACTION_TAG0 + i) for i, t in enumerate(tractions)
    ]
    facets = np.concatenate([f for f, _ in groups])
    values = np.concatenate([np.full(f.size, tag, np.int32) for f, tag in groups])
    if np.unique(facets).size != facets.size:
        raise ValueError(
            "A facet is listed twice among the contact surface and the tractions; "
            "give each facet one role."
        )
    order = np.argsort(facets)
    return mesh.meshtags(domain, fdim, facets[order], values[order])


@dataclass
class VariationalSystem:
    """Residual blocks F_i(unknowns; tests) = 0 and what a solver needs to compile them.

    Two-body systems add ``extras``: coefficients (the target vertex
    displacements w_k) that are a selection of ``unknowns[0]`` (w_k = S_k u),
    with one more residual block each after the unknowns' blocks; ``transfer``
    refreshes them (search) and names the selected blocks (``sources()``,
    ``version``). A solver condenses them away (solvers/condensed.py).
    """

    name: str
    residuals: list[ufl.Form]
    unknowns: list[fem.Function]
    bcs: list[fem.DirichletBC]
    entity_maps: list = field(default_factory=list)
    extras: list[fem.Function] = field(default_factory=list)
    transfer: object | None = None


@dataclass(frozen=True)
class ProblemState:
    """A copy of the unknowns and the load factor, for undoing a failed increment.

    Attributes:
        u: displacement dof values (owned and ghost), length.
        lam: multiplier dof values (owned and ghost), stress.
        load_factor: the load factor the state belongs to.
    """

    u: np.ndarray
    lam: np.ndarray
    load_factor: float


@dataclass(frozen=True)
class ContactState:
    """Nodal contact diagnostics at the current iterate.

    Attributes:
        gap: nodal gaps at the owned multiplier nodes (length).
        pressure: nodal contact pressure (<= 0, stress): the multiplier for
            multiplier strategies, r min(g, 0) for the penalty method.
        multiplier: nodal multiplier lam.
        active_count: global number of nodes with a pressure < 0.
        max_penetration: global max of -min(g, 0) (length).
        contact_force: global normal force -int p dA on the reference surface
            (force; per unit thickness in 2D). Multiplier strategies report
            -int lam dA: at convergence lam = p, and lam does not carry the
            round-off of r g that p carries at huge r (at r = 1e12 E/h a gap
            of 1e-15 makes r g of order one). The penalty method, whose
            multiplier is zero, reports -int r min(g, 0) dA.
        constraint_penetration: two deformable bodies: the max penetration by
            the discretisation's own gap (to the plane of each node's assigned
            facet), while ``max_penetration`` is the depth inside the actual
            target surface; None where the two are one (rigid obstacles).
        tangential_force: global |int T tau dA| (force); 0 without friction.
        stick_count: global number of sticking contact nodes (0 without friction).
        slip_count: global number of slipping contact nodes (0 without friction).
    """

    gap: np.ndarray
    pressure: np.ndarray
    multiplier: np.ndarray
    active: np.ndarray
    active_count: int
    max_penetration: float
    contact_force: float
    constraint_penetration: float | None = None
    tangential_force: float = 0.0
    stick_count: int = 0
    slip_count: int = 0

    @classmethod
    def gathered(
        cls,
        comm: MPI.Comm,
        gap: np.ndarray,
        pressure: np.ndarray,
        multiplier: np.ndarray,
        local_force: float,
    ) -> ContactState:
        """The state from this rank's nodal values, with the summaries reduced over ``comm``.

        Args:
            comm: communicator of the problem.
            gap: owned nodal gaps (length).
            pressure: owned nodal pressure (<= 0, stress); active where < 0.
            multiplier: owned nodal multipliers.
            local_force: this rank's share of the contact force (force).
        """
        active = pressure < 0.0
        return cls(
            gap=gap,
            pressure=pressure,
            multiplier=multiplier,
            active=active,
            active_count=comm.allreduce(int(active.sum()), op=MPI.SUM),
            max_penetration=comm.allreduce(
                float(np.max(-np.minimum(gap, 0.0), initial=0.0)) + 0.0, op=MPI.MAX
            ),
            contact_force=comm.allreduce(local_force, op=MPI.SUM),
        )


@dataclass(frozen=True)
class DetFMinimum:
    """Smallest det F = det(I + grad u) over the body's quadrature points.

    Attributes:
        value: the global minimum (1 undeformed, <= 0 inverted).
        where: reference coordinates of the midpoint of the cell holding it
            (length; 3 entries, z = 0 in 2D).
    """

    value: float
    where: tuple[float, float, float]



class ProblemBase:
    """What every contact problem shares: r, Dirichlet conditions, snapshots.

    A subclass sets ``domain``, ``V``, ``u``, ``lam``, ``r`` (a Constant),
    ``load_factor`` and ``stiffness_scale``, and defines ``set_load``.
    """

    domain: mesh.Mesh
    V: fem.FunctionSpace
    u: fem.Function
    lam: fem.Function
    r: fem.Constant
    load_factor: float
    bcs: list[fem.DirichletBC]
    _bc_constants: list[tuple[fem.Constant, PrescribedDisplacement, int]]
    #: Whether the contact carries Coulomb friction (a tangential multiplier lam_t,
    #: the Coulomb checks, r_t); solvers read this instead of probing the problem.
    frictional = False

    @property
    def stiffness_scale(self) -> float:
        """The scale that makes r dimensionless (stress per length)."""
        raise NotImplementedError

    def set_load(self, t: float) -> None:
        """Apply the load factor t."""
        raise NotImplementedError

    def commit(self) -> None:
        """Accept the current state as converged (history-dependent terms; none here)."""

    def set_r(self, r: float, *, relative: bool) -> None:
        """Set the penalty/augmentation parameter, relative to E/h or absolute."""
        check_r(r)
        self.r.value = r * self.stiffness_scale if relative else r

    @property
    def r_absolute(self) -> float:
        """R in stress per length."""
        return float(self.r.value)

    @property
    def r_relative(self) -> float:
        """R divided by E/h."""
        return self.r_absolute / self.stiffness_scale

    def _dirichlet(self, prescribed: Sequence[PrescribedDisplacement]) -> list[fem.DirichletBC]:
        """One Dirichlet condition per prescribed component, valued by :meth:`_apply_prescribed`."""
        fdim = self.domain.topology.dim - 1
        self._bc_constants = []
        bcs = []
        for condition in prescribed:
            components = condition.at(1.0)
            if len(components) != self.domain.geometry.dim:
                raise ValueError(
                    f"Prescribed displacement {condition.value} needs one entry per "
                    f"component ({self.domain.geometry.dim}); use None for a free one."
                )
            for i, value in enumerate(components):
                if value is None:
                    continue
                Vi = self.V.sub(i)
                dofs = fem.locate_dofs_topological(Vi, fdim, condition.facets)
                const = fem.Constant(self.domain, default_scalar_type(0.0))
                self._bc_constants.append((const, condition, i))
                bcs.append(fem.dirichletbc(const, dofs, Vi))
        return bcs

    def _apply_prescribed(self, t: float) -> None:
        """Set every prescribed component to its value at load factor t."""
        for const, condition, i in self._bc_constants:
            const.value = condition.at(t)[i]

    def prescribed_mismatch(self) -> float:
        """Largest |u - u_D| over the prescribed components at the current load factor (length).

        Global over ranks. Zero once a Newton step has been taken at this load
        factor (the Dirichlet rows are linear); the increment of the
        prescribed values before the first step of a load step.
        """
        local = 0.0
        for (const, _, _), bc in zip(self._bc_constants, self.bcs, strict=True):
            dofs, n_owned = bc.dof_indices()
            values = self.u.x.array[dofs[:n_owned]]
            local = max(local, float(np.max(np.abs(values - float(const.value)), initial=0.0)))
        return self.comm.allreduce(local, op=MPI.MAX)

    def min_det_F(self) -> DetFMinimum:
        """Smallest det F over the body (quadrature points of degree 2, all ranks).

        The points are those of a degree-2 rule on the cell, where the strain
        energy is integrated; one compiled expression per problem.
        """
        if not hasattr(self, "_det_expr"):
            import basix

            cell = self.domain.basix_cell()
            points, _ = basix.make_quadrature(cell, 2)
            F = ufl.Identity(self.domain.geometry.dim) + ufl.grad(self.u)
            self._det_expr = fem.Expression(ufl.det(F), points)
            self._det_cells = np.arange(
                self.domain.topology.index_map(self.domain.topology.dim).size_local,
                dtype=np.int32,
            )
        if self._det_cells.size:
            values = self._det_expr.eval(self.domain, self._det_cells)
            per_cell = values.reshape(self._det_cells.size, -1).min(axis=1)
        else:  # a rank without cells
            per_cell = np.zeros(0)
        if per_cell.size:
            worst = int(np.argmin(per_cell))
            local = float(per_cell[worst])
            where = mesh.compute_midpoints(
                self.domain, self.domain.topology.dim, self._det_cells[worst : worst + 1]
            )[0]
        else:
            local, where = np.inf, np.zeros(3)
        if not np.isfinite(local):
            local = -np.inf if np.isnan(local) else local
        value, rank = self.comm.allreduce((local, self.comm.rank), op=MPI.MINLOC)
        where = self.comm.bcast(np.asarray(where, float), root=rank)
        return DetFMinimum(float(value), (float(where[0]), float(where[1]), float(where[2])))


    def snapshot(self) -> ProblemState:
        """Copy the unknowns and the load factor (see :meth:`restore`)."""
        return ProblemState(self.u.x.array.copy(), self.lam.x.array.copy(), self.load_factor)

    def restore(self, state: ProblemState, *, load: bool = True) -> None:
        """Put back a :meth:`snapshot`; ``load=False`` keeps the current load factor."""
        self.u.x.array[:] = state.u
        self.lam.x.array[:] = state.lam
        if load:
            self.set_load(state.load_factor)



class ContactProblem(ProblemBase):
    """One deformable body, one rigid obstacle, proportional loading."""

    #: Whether lam is the contact pressure of the solution (the penalty method
    #: sets False): chooses the contact-force formula.
    multiplier_is_pressure = True

    def __init__(
        self,
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
    ) -> None:
        gdim = domain.geometry.dim
        if domain.topology.dim != gdim:
            raise ValueError(
                f"The body mesh is {domain.topology.dim}D in {gdim}D space; "
                "use a mesh whose topological and geometric dimensions agree."
            )
        self.domain = domain
        self.comm = domain.comm
        self.material = material
        self.obstacle = obstacle
        self._unknowns(settings, contact_facets, tractions, degree)

        self._motion = (
            np.zeros(gdim) if obstacle_motion is None else np.asarray(obstacle_motion, float)
        )
        self._schedule = _schedule(obstacle_schedule, gdim)
        self.bcs = self._dirichlet(prescribed)
        self._traction_constants: list[tuple[fem.Constant, np.ndarray]] = []
        external = self._external_work(tractions)

        x = ufl.SpatialCoordinate(domain) + self.u
        self.gap = obstacle.gap(x)
        self.pressure = augmented_pressure(self.gap, self.lam, self.r)
        psi = material.strain_energy(self.u)
        dx = ufl.Measure(
            "dx", domain=domain,
            metadata={"quadrature_degree": energy_quadrature_degree(psi, self.u, degree)},
        )
        self.potential = psi * dx
        if external is not None:
            self.potential -= external

        self._diagnostic_forms()

    # -- parameters and loads -------------------------------------------------
    @property
    def stiffness_scale(self) -> float:
        """E/h: the scale that makes r dimensionless (stress per length)."""
        return self.material.E / self.surface.h

    def set_load(self, t: float) -> None:
        """Apply the load factor t: prescribed values, tractions and obstacle motion."""
        self.load_factor = float(t)
        self._apply_prescribed(t)
        for const, value in self._traction_constants:
            const.value[:] = t * value
        self.obstacle.translate_to(self.obstacle_offset(t))

    def obstacle_offset(self, t: float) -> np.ndarray:
        """Obstacle displacement at load factor t: t * motion, or the schedule interpolated."""
        if self._schedule is None:
            return t * self._motion
        times, offsets = self._schedule
        return np.array([np.interp(t, times, offsets[:, i]) for i in range(offsets.shape[1])])

    def refresh_search(self) -> None:
        """Bring data that follow u up to date (two bodies: the search); none here."""

    def _unknowns(
        self,
        settings: ContactSettings,
        contact_facets: np.ndarray,
        tractions: Sequence[SurfaceTraction],
        degree: int,
    ) -> None:
        """Displacement space and u, the contact submesh with lam, and r (load factor 0)."""
        domain = self.domain
        self.settings = settings
        self.V = fem.functionspace(domain, ("Lagrange", degree, (domain.geometry.dim,)))
        self.u = fem.Function(self.V, name="displacement")
        self.facet_tags = _facet_tags(domain, contact_facets, tractions)
        self.surface = ContactSurface(
            domain, contact_facets, settings.quadrature, tags=self.facet_tags
        )
        self.Q = self.surface.Q
        self.lam = fem.Function(self.Q, name="contact_pressure")
        self.r = fem.Constant(domain, default_scalar_type(1.0))
        self.set_r(settings.r, relative=settings.relative)
        self.load_factor = 0.0

    def _diagnostic_forms(self) -> None:
        """Nodal gap and pressure, and the normal contact force by p_n and by lam."""
        self._gap_form = self.surface.nodal_form(self.gap)
        self._pressure_form = self.surface.nodal_form(self.pressure)
        self._force_form = fem.form(
            -self.pressure * self.surface.ds, entity_maps=self.surface.entity_maps
        )
        self._multiplier_force_form = fem.form(
            -self.lam * self.surface.ds, entity_maps=self.surface.entity_maps
        )

    def _external_work(self, tractions: Sequence[SurfaceTraction]) -> ufl.Form | None:
        if not tractions:
            return None
        ds = ufl.Measure("ds", domain=self.domain, subdomain_data=self.facet_tags)
        work = 0
        for i, traction in enumerate(tractions):
            if len(traction.value) != self.domain.geometry.dim:
                raise ValueError(
                    f"Traction {traction.value} needs {self.domain.geometry.dim} components."
                )
            const = fem.Constant(self.domain, np.zeros(self.domain.geometry.dim))
            self._traction_constants.append((const, np.asarray(traction.value, float)))
            work += ufl.dot(const, self.u) * ds(TRACTION_TAG0 + i)
        return work

    # -- systems handed to solvers -------------------------------------------
    def _extra_unknowns(self) -> list[fem.Function]:
        """Coefficients that are a selection of u (two bodies: target displacements)."""
        return []

    def _system(
        self,
        name: str,
        energy: ufl.Form,
        *,
        with_lam: bool,
        work: Work | None = None,
        multipliers: Sequence[tuple[fem.Function, ufl.Form]] = (),
    ) -> VariationalSystem:
        """Residual blocks from an energy plus non-potential terms.

        The residual of u (and of each extra coefficient c, see
        :meth:`_extra_unknowns`) is dE/dc[test] + work(c, test); with
        ``with_lam`` the multiplier block r dE/dlam[mu] (force units) follows
        u; ``multipliers`` appends further unknowns with their residuals
        (e.g. the tangential multiplier), before the extras' blocks.
        """

        def residual(c: fem.Function) -> ufl.Form:
            test = ufl.TestFunction(c.function_space)
            form = ufl.derivative(energy, c, test)
            extra = None if work is None else work(c, test)
            return form if extra is None else form + extra

        residuals = [residual(self.u)]
        unknowns = [self.u]
        if with_lam:
            residuals.append(self.r * ufl.derivative(energy, self.lam, ufl.TestFunction(self.Q)))
            unknowns.append(self.lam)
        for function, form in multipliers:
            residuals.append(form)
            unknowns.append(function)
        extras = self._extra_unknowns()
        residuals += [residual(c) for c in extras]
        return VariationalSystem(
            name, residuals, unknowns, self.bcs, self.surface.entity_maps,
            extras=extras, transfer=getattr(self, "pair", None) if extras else None,
        )

    def _lagrangian(self) -> ufl.Form:
        """Pi + int AL density ds (paper eq. 9)."""
        return self.potential + augmented_lagrangian_energy(
            self.gap, self.lam, self.r
        ) * self.surface.ds

    def _penalty_energy(self) -> ufl.Form:
        """Pi + int r/2 min(g, 0)^2 ds (paper eq. 7)."""
        return self.potential + penalty_energy(self.gap, self.r) * self.surface.ds

    def augmented_system(self) -> VariationalSystem:
        """Alart-Curnier saddle point on (u, lam): the GNRM system.

        The multiplier block is r dL/dlam = (min(lam + r g, 0) - lam) mu,
        the complementarity residual in force units.
        """
        return self._system("augmented", self._lagrangian(), with_lam=True)

    def primal_system(self) -> VariationalSystem:
        """Equilibrium in u with lam held fixed (the Uzawa inner problem)."""
        return self._system("primal", self._lagrangian(), with_lam=False)

    def penalty_system(self) -> VariationalSystem:
        """Penalty regularisation (paper eq. 7) in u only."""
        return self._system("penalty", self._penalty_energy(), with_lam=False)

    def complementarity_residual(self) -> ufl.Form:
        """(min(lam + r g, 0) - lam) mu: zero when lam is the converged pressure."""
        mu = ufl.TestFunction(self.Q)
        return (self.pressure - self.lam) * mu * self.surface.ds

    # -- diagnostics -----------------------------------------------------------
    def contact_state(self) -> ContactState:
        """Nodal gaps, pressures, the active set and global summaries.

        With a multiplier method the pressure is the multiplier (see
        :meth:`nodal_pressure`), so the written field, the active set and the
        force agree at every r.
        """
        gap = self.surface.nodal(self._gap_form)
        lam = self.lam.x.array[: gap.size].copy()
        return ContactState.gathered(
            self.comm, gap, self.nodal_pressure(lam), lam,
            fem.assemble_scalar(self._contact_force_form()),
        )

    def nodal_pressure(self, lam: np.ndarray) -> np.ndarray:
        """Owned nodal contact pressure (<= 0, stress) of the current iterate.

        Multiplier strategies: the multiplier, min(lam, 0), with values
        below 1e-12 of the largest pressure set to zero (the round-off of a
        linear solve at open nodes). The transmitted min(lam + r g, 0) would
        carry the round-off r * eps * g of the gap, of the order of the
        pressure itself at r = 1e12 E/h. The penalty method, whose multiplier
        is zero, transmits r min(g, 0).
        """
        if not self.multiplier_is_pressure:
            return self.surface.nodal(self._pressure_form)
        pressure = np.minimum(lam, 0.0)
        peak = self.comm.allreduce(float(np.max(-pressure, initial=0.0)), op=MPI.MAX)
        pressure[pressure > -1e-12 * peak] = 0.0
        return pressure

    def _contact_force_form(self) -> fem.Form:
        """The force from the multiplier when it is the pressure, else from min(lam + r g, 0).

        At huge r the latter carries the round-off r * eps * g of the gap.
        """
        by_multiplier = getattr(self, "_multiplier_force_form", None)
        if self.multiplier_is_pressure and by_multiplier is not None:
            return by_multiplier
        return self._force_form

    def active_signature(self) -> tuple[bytes, ...]:
        """A hashable fingerprint of the global active set (lam + r g < 0 at the nodes)."""
        active = self.surface.nodal(self._pressure_form) < 0.0
        return tuple(self.comm.allgather(np.packbits(active).tobytes()))

    def update_multiplier(self) -> None:
        """Uzawa update lam <- min(lam + r g, 0) at the nodes (paper eq. 10)."""
        pressure = self.surface.nodal(self._pressure_form)
        self.lam.x.array[: pressure.size] = pressure
        self.lam.x.scatter_forward()

    def laws(self) -> list[tuple[Elastic, np.ndarray | None]]:
        """Each body's law and its cells (None: every cell): one body here."""
        return [(self.material, None)]

    def body_ids(self) -> fem.Function | None:
        """Cell-wise body index for the output; None for a single body."""
        return None

    def nodal_coordinates(self) -> np.ndarray:
        """Reference coordinates of the owned multiplier nodes, shape (n, 3)."""
        n = self.Q.dofmap.index_map.size_local
        return self.Q.tabulate_dof_coordinates()[:n]

