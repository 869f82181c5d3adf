"""The deformable part of a problem: bodies in one mesh, their laws and conditions.

A :class:`Solid` owns the displacement ``u`` (vector P-k on the mesh), the
strain energy of every body (each body a set of cells with its own law),
the Dirichlet conditions and the surface tractions. All loads are
proportional to one load factor ``t`` in [0, 1]. Contacts
(:mod:`.obstacle_contact`, :mod:`.pairs`) are added to it by
:class:`~fenics_contact.model.problem.ContactProblem`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import basix
import numpy as np
import ufl
import ufl.algorithms
from dolfinx import default_scalar_type, fem, la, mesh

from mpi4py import MPI

from fenics_contact.model.materials import Elastic


@dataclass(frozen=True)
class Body:
    """One body of the mesh.

    Attributes:
        name: label used in outputs.
        tag: its cell tag in the mesh (None: every cell, a one-body mesh).
        material: its constitutive law.
        stabilise: weak springs tying every point to its reference position, of
            stiffness stabilise E / L^2 per unit volume (L the diagonal of the body's
            bounding box): they hold rigid motions that nothing holds before the load
            presses the body (a round seal that only friction holds). 0: none.
    """

    name: str
    tag: int | None
    material: Elastic
    stabilise: float = 0.0


@dataclass(frozen=True)
class PrescribedDisplacement:
    """Displacement imposed on facets, proportional to the load factor.

    Attributes:
        facets: facet indices (local) where the condition holds.
        value: final displacement per component (length units); ``None``
            (or ``"free"``, as scenes write it) leaves that component free.
        name: the support's name in the reports (the scene's tag); conditions
            of one name make one support.
    """

    facets: np.ndarray
    value: tuple[float | None, ...]
    name: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.value, tuple | list | np.ndarray):
            raise TypeError(f"value = {self.value!r}: give one entry per component, e.g. "
                            "(0.0, -0.01), None for a free one: (None, -0.01).")
        if not isinstance(self.facets, np.ndarray | list | tuple):
            raise TypeError(f"facets: give an array of facet indices, not "
                            f"{type(self.facets).__name__} (a MeshTags: tags.find(value)).")
        value = tuple(None if isinstance(v, str) and v.strip().lower() == "free" else v
                      for v in self.value)
        for v in value:
            if isinstance(v, str):
                raise ValueError(f"value = {self.value!r}: {v!r} is neither a number nor free; "
                                 "give a displacement (length) or None (or 'free').")
        object.__setattr__(self, "value", value)

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
    """Traction on facets per unit reference area, proportional to the load factor.

    Attributes:
        facets: facet indices (local) it acts on.
        value: the traction at load factor 1, a vector in the global axes (stress,
            force per reference area; a dead load: it keeps its direction as the
            surface turns), one entry per component; (0, -p) presses a top face down.
    """

    facets: np.ndarray
    value: tuple[float, ...]


def facet_area(domain: mesh.Mesh, facets: np.ndarray) -> float:
    """The reference area of the facets, summed over ranks (length in 2D, area in 3D).

    Straight facets: segments, triangles, or quadrilaterals (half the cross
    product of their diagonals, in dolfinx's vertex order 0-1-3-2).
    """
    fdim = domain.topology.dim - 1
    owned = facets[facets < domain.topology.index_map(fdim).size_local]
    x = domain.geometry.x[mesh.entities_to_geometry(domain, fdim, owned)]
    if fdim == 1:
        local = np.linalg.norm(x[:, 1] - x[:, 0], axis=1).sum()
    elif x.shape[1] == 3:
        local = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1).sum()
    else:
        local = 0.5 * np.linalg.norm(np.cross(x[:, 3] - x[:, 0], x[:, 2] - x[:, 1]), axis=1).sum()
    return domain.comm.allreduce(float(local), op=MPI.SUM)


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


def _check_bodies(domain: mesh.Mesh, cell_tags: mesh.MeshTags | None,
                  bodies: Sequence[Body]) -> None:
    """Raise ValueError for no body, repeated tags or a tag no cell carries."""
    if not bodies:
        raise ValueError("Give at least one body.")
    if cell_tags is None:
        if len(bodies) != 1:
            raise ValueError(
                f"{len(bodies)} bodies need cell tags to tell them apart; give the mesh's "
                "cell tags."
            )
        if bodies[0].tag is not None:
            raise ValueError(
                f"Body {bodies[0].name!r} has cell tag {bodies[0].tag}, but no cell tags were "
                "given: its energy would hold no cell. Give the mesh's cell tags "
                "(Solid(..., cell_tags=...)), or tag=None for the one body that is the whole "
                "mesh."
            )
        return
    tags = [b.tag for b in bodies]
    if len(set(tags)) != len(tags):
        raise ValueError(f"Bodies {[b.name for b in bodies]} have the cell tags {tags}, which "
                         "repeat; give each body its own tag.")
    present = set(np.unique(cell_tags.values).tolist())
    present = set().union(*domain.comm.allgather(present))
    for b in bodies:
        if b.tag not in present:
            raise ValueError(
                f"Body {b.name!r} has cell tag {b.tag}, which no cell of the mesh carries "
                f"(tags present: {sorted(present)})."
            )
    unclaimed = unclaimed_cells(domain, cell_tags, tags)
    if unclaimed:
        text = describe_unclaimed(unclaimed)
        raise ValueError(
            f"{text[0].upper()}{text[1:]} belong to no body: their displacements would be "
            "unknowns without stiffness (a singular Jacobian). Give them a body, or mesh "
            "without them."
        )


def unclaimed_cells(domain: mesh.Mesh, cell_tags: mesh.MeshTags,
                    tags: Sequence[int | None]) -> dict[int | None, int]:
    """Cells no body's tag holds, counted per tag (None: cells without a tag; collective)."""
    owned = domain.topology.index_map(domain.topology.dim).size_local
    keep = cell_tags.indices < owned
    indices, values = cell_tags.indices[keep], cell_tags.values[keep]
    counts: dict[int | None, int] = {}
    untagged = owned - np.unique(indices).size
    if untagged:
        counts[None] = int(untagged)
    for tag in np.unique(values).tolist():
        if tag not in tags:
            counts[int(tag)] = int(np.sum(values == tag))
    merged: dict[int | None, int] = {}
    for part in domain.comm.allgather(counts):
        for tag, n in part.items():
            merged[tag] = merged.get(tag, 0) + n
    return merged


def describe_unclaimed(counts: dict[int | None, int], names: dict[int, str] | None = None) -> str:
    """'The 312 cells tagged 1 ("striker")'-style words for :func:`unclaimed_cells`."""
    names = names or {}
    parts = []
    for tag, n in sorted(counts.items(), key=lambda kv: (kv[0] is None, kv[0] or 0)):
        if tag is None:
            parts.append(f"{n} cells without a cell tag")
        else:
            name = f" ({names[tag]!r})" if tag in names else ""
            parts.append(f"{n} cells tagged {tag}{name}")
    return "the mesh's " + " and ".join(parts)


class Solid:
    """The bodies of one mesh: displacement, strain energy, Dirichlet conditions, tractions.

    Args:
        domain: the mesh (topological and geometric dimensions equal).
        bodies: the bodies; one body with ``tag=None`` holds every cell.
        cell_tags: the cell tags that tell several bodies apart.
        prescribed: Dirichlet conditions (proportional or along a path).
        tractions: surface tractions (proportional).
        degree: polynomial degree of the displacement.
        quadrature_degree: quadrature degree of the strain energy (default:
            :func:`energy_quadrature_degree` of each body's law).
    """

    def __init__(
        self,
        domain: mesh.Mesh,
        bodies: Sequence[Body],
        cell_tags: mesh.MeshTags | None = None,
        *,
        prescribed: Sequence[PrescribedDisplacement] = (),
        tractions: Sequence[SurfaceTraction] = (),
        degree: int = 1,
        quadrature_degree: int | None = None,
    ) -> None:
        gdim = domain.geometry.dim
        if domain.topology.dim != gdim:
            raise ValueError(
                f"The body mesh is {domain.topology.dim}D in {gdim}D space; "
                "use a mesh whose topological and geometric dimensions agree."
            )
        _check_bodies(domain, cell_tags, bodies)
        for traction in tractions:
            if len(traction.value) != gdim:
                raise ValueError(f"Traction {traction.value} needs {gdim} components.")
        self.domain = domain
        self.comm = domain.comm
        self.gdim = gdim
        self.degree = degree
        self.bodies = list(bodies)
        self.cell_tags = cell_tags
        self.tractions = list(tractions)
        self.V = fem.functionspace(domain, ("Lagrange", degree, (gdim,)))
        self.u = fem.Function(self.V, name="displacement")
        self.prescribed = list(prescribed)
        self.bcs = self._dirichlet(self.prescribed)
        self._plane_axes: tuple[fem.Function, fem.Function] | bool | None = False  # not yet found
        self._traction_constants = [
            (fem.Constant(domain, np.zeros(gdim)), np.asarray(t.value, float))
            for t in self.tractions
        ]
        dx = ufl.Measure("dx", domain=domain, subdomain_data=cell_tags)
        self._dx = {}
        #: Each body's Lame moduli (mu, lmbda) as constants: the compiled forms serve
        #: any E and nu (one compilation per law and body layout, not per value).
        self._moduli = {
            b.tag: (fem.Constant(domain, default_scalar_type(b.material.mu)),
                    fem.Constant(domain, default_scalar_type(b.material.lmbda)))
            for b in self.bodies
        }
        for b in self.bodies:
            psi = b.material.strain_energy(self.u)
            q = quadrature_degree or energy_quadrature_degree(psi, self.u, degree)
            metadata = {"quadrature_degree": q}
            self._dx[b.tag] = dx(metadata=metadata) if b.tag is None else dx(
                b.tag, metadata=metadata
            )
        #: each stabilised body's spring stiffness (stress per length^2), by tag
        self._spring = self._springs(cell_tags)
        self._spring_forms: dict = {}
        self._internal_form: fem.Form | None = None
        # det F at the energy's degree-2 points: every load step checks it (compiled with
        # the other forms, not inside the first step)
        points, _ = basix.make_quadrature(domain.basix_cell(), 2)
        self._det_expr = fem.Expression(ufl.det(ufl.Identity(gdim) + ufl.grad(self.u)), points)
        self._det_cells = np.arange(domain.topology.index_map(gdim).size_local, dtype=np.int32)

    # -- energy -------------------------------------------------------------------
    def strain_energy(self) -> ufl.Form:
        """Sum over the bodies of int psi_b dV (energy; per unit thickness in 2D).

        A stabilised body adds its springs' energy int k |u|^2 / 2 dV
        (:meth:`stabilisation_force`).
        """
        terms = [b.material.strain_energy(self.u, self._moduli[b.tag]) * self._dx[b.tag]
                 for b in self.bodies]
        terms += [0.5 * self._spring[b.tag] * ufl.dot(self.u, self.u) * self._dx[b.tag]
                  for b in self.bodies if b.tag in self._spring]
        return sum(terms[1:], terms[0])

    def stabilisation_force(self, body: str) -> np.ndarray:
        """The force the springs of a stabilised body put on it, int -k u dV (collective).

        Force (per unit thickness in 2D); zeros for a body without springs.
        """
        b = next(b for b in self.bodies if b.name == body)
        if b.tag not in self._spring:
            return np.zeros(self.gdim)
        if b.tag not in self._spring_forms:  # compiled once, assembled at every step
            k = self._spring[b.tag]
            self._spring_forms[b.tag] = [fem.form(-k * self.u[i] * self._dx[b.tag])
                                         for i in range(self.gdim)]
        return np.array([self.comm.allreduce(fem.assemble_scalar(f), op=MPI.SUM)
                         for f in self._spring_forms[b.tag]])

    def _springs(self, cell_tags: mesh.MeshTags | None) -> dict:
        """Each stabilised body's spring stiffness stabilise E / L^2 (a Constant, by tag)."""
        return {b.tag: fem.Constant(self.domain, default_scalar_type(
                    b.stabilise * b.material.E / self.body_size(b.name)**2))
                for b in self.bodies if b.stabilise > 0.0}

    def _body_cells(self, body: Body) -> np.ndarray:
        """The owned cells of ``body`` (every owned cell for an untagged body)."""
        tdim = self.domain.topology.dim
        if body.tag is None:
            return np.arange(self.domain.topology.index_map(tdim).size_local, dtype=np.int32)
        return self.cell_tags.find(body.tag)

    def _body(self, name: str) -> Body:
        return next(b for b in self.bodies if b.name == name)

    def body_size(self, body: str) -> float:
        """The diagonal of the body's reference bounding box (length; collective)."""
        cells = self._body_cells(self._body(body))
        nodes = np.unique(self.domain.geometry.dofmaps[0][cells].reshape(-1))
        x = self.domain.geometry.x[nodes, : self.gdim]
        lo = self.comm.allreduce(np.min(x, axis=0, initial=np.inf), op=MPI.MIN)
        hi = self.comm.allreduce(np.max(x, axis=0, initial=-np.inf), op=MPI.MAX)
        return float(np.linalg.norm(hi - lo))

    def body_motion(self, body: str) -> float:
        """The largest nodal displacement |u| over the body's cells (length; collective)."""
        cells = self._body_cells(self._body(body))
        dofs = np.unique(self.V.dofmap.list[cells].reshape(-1))
        u = self.u.x.array.reshape(-1, self.gdim)[dofs]
        local = float(np.max(np.linalg.norm(u, axis=1), initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    def traction_resultants(self) -> list[np.ndarray]:
        """Each traction's resultant at the current load: value times reference area (force).

        Per unit thickness in 2D; collective. The areas are measured once.
        """
        if not hasattr(self, "_traction_areas"):
            self._traction_areas = [facet_area(self.domain, t.facets) for t in self.tractions]
        return [np.array(const.value, float) * area
                for (const, _), area in zip(self._traction_constants, self._traction_areas,
                                            strict=True)]

    def external_work(self, ds: ufl.Measure, ids: Sequence[tuple[int, ...]]) -> ufl.Form | None:
        """Work of the tractions, int t . u dA over each traction's tagged facets.

        ``ds`` carries the problem's facet tags and ``ids[i]`` the tag values
        of the i-th traction's facets (see :func:`~.tags.facet_roles`).
        """
        work = None
        for (const, _), tag_ids in zip(self._traction_constants, ids, strict=True):
            term = ufl.dot(const, self.u) * ds(tag_ids)
            work = term if work is None else work + term
        return work

    @property
    def stiffest(self) -> Elastic:
        """The first body's law (the r scale of a one-body problem)."""
        return self.bodies[0].material

    def material_of(self, body: str) -> Elastic:
        """The law of the body named ``body``."""
        for b in self.bodies:
            if b.name == body:
                return b.material
        raise ValueError(
            f"The body {body!r} is not among the bodies {[b.name for b in self.bodies]}; "
            "use one of those names."
        )

    def body_of_facets(self, facets: np.ndarray, role: str) -> Body:
        """The one body whose cells carry the facets (collective)."""
        if self.cell_tags is None:
            return self.bodies[0]
        domain = self.domain
        tdim = domain.topology.dim
        domain.topology.create_connectivity(tdim - 1, tdim)
        f2c = domain.topology.connectivity(tdim - 1, tdim)
        tag_of = dict(zip(self.cell_tags.indices.tolist(), self.cell_tags.values.tolist(),
                          strict=True))
        local = {tag_of.get(int(c)) for f in np.asarray(facets) for c in f2c.links(int(f))}
        tags = set().union(*self.comm.allgather(local)) - {None}
        matching = [b for b in self.bodies if b.tag in tags]
        if len(matching) != 1:
            raise ValueError(
                f"The {role} facets border cells of {len(matching)} bodies "
                f"({[b.name for b in matching]}); a {role} surface lies on one body."
            )
        return matching[0]

    # -- loads ----------------------------------------------------------------------
    def _dirichlet(self, prescribed: Sequence[PrescribedDisplacement]) -> list[fem.DirichletBC]:
        """One Dirichlet condition per prescribed component, valued by :meth:`set_load`."""
        fdim = self.domain.topology.dim - 1
        self._bc_constants: list[tuple[fem.Constant, PrescribedDisplacement, int]] = []
        bcs = []
        for k, condition in enumerate(prescribed):
            if self.comm.allreduce(np.asarray(condition.facets).size, op=MPI.SUM) == 0:
                raise ValueError(
                    f"Prescribed displacement {condition.name or k + 1!r} holds no facet; give "
                    "the facets it acts on (mesh.locate_entities_boundary, or a facet tag)."
                )
            components = condition.at(1.0)
            if len(components) != self.gdim:
                raise ValueError(
                    f"Prescribed displacement {condition.value} needs one entry per "
                    f"component ({self.gdim}); use None for a free one."
                )
            for i, value in enumerate(components):
                if value is None:
                    continue
                Vi = self.V.sub(i)
                dofs = fem.locate_dofs_topological(Vi, fdim, condition.facets)
                const = fem.Constant(self.domain, default_scalar_type(0.0))
                self._bc_constants.append((const, condition, i))
                bcs.append(fem.dirichletbc(const, dofs, Vi))
        self._check_conflicts(bcs)
        return bcs

    def _check_conflicts(self, bcs: Sequence[fem.DirichletBC]) -> None:
        """Refuse two conditions that give one node's component different values (collective).

        Compared at every knot of the load path (paths) and at t = 1; one of
        them would silently win and the other be reported as not met.
        """
        times = sorted({1.0, *(float(k[0]) for c in self.prescribed
                                for k in getattr(c, "path", ()))})
        seen: dict[int, tuple[int, np.ndarray]] = {}
        clash = None
        for k, ((_, condition, i), bc) in enumerate(zip(self._bc_constants, bcs, strict=True)):
            values = np.array([condition.at(t)[i] for t in times])
            dofs, _ = bc.dof_indices()
            for dof in dofs.tolist():
                other = seen.setdefault(dof, (k, values))
                if other[0] != k and not np.allclose(other[1], values, rtol=1e-12, atol=0.0):
                    clash = (other[0], k, dof)
                    break
            if clash:
                break
        found = self.comm.allgather(None if clash is None else self._describe_clash(*clash))
        message = next((m for m in found if m is not None), None)
        if message is not None:
            raise ValueError(message)

    def _describe_clash(self, first: int, second: int, dof: int) -> str:
        """The message for two conditions that disagree at the (blocked-unrolled) dof."""
        (_, a, i), (_, b, _) = self._bc_constants[first], self._bc_constants[second]
        point = self.V.tabulate_dof_coordinates()[dof // self.gdim][: self.gdim]
        names = [repr(c.name) if c.name else f"{c.value}" for c in (a, b)]
        return (f"Two prescribed displacements hold u_{'xyz'[i]} at the node "
                f"{(np.round(point, 6) + 0.0).tolist()} with different values: {names[0]} gives "
                f"{a.at(1.0)[i]} and {names[1]} gives {b.at(1.0)[i]} at the end of the load "
                "path. A node shared by two supports takes one value: restrict one of them "
                "(e.g. its coordinate range) or leave that component free in one.")

    def symmetry_plane_axes(self) -> tuple[fem.Function, fem.Function] | None:
        """The symmetry planes' nodal data (:func:`~.friction.plane_axes`; None without).

        Collective on first call (it finds the planes), cached after.
        """
        if self._plane_axes is False:
            from fenics_contact.model.friction import plane_axes, symmetry_planes

            self._plane_axes = plane_axes(self.V, symmetry_planes(self.domain, self.prescribed))
        return self._plane_axes  # type: ignore[return-value]

    def set_load(self, t: float) -> None:
        """Set every prescribed component and traction to its value at load factor t."""
        for const, condition, i in self._bc_constants:
            const.value = condition.at(t)[i]
        for const, value in self._traction_constants:
            const.value[:] = t * value

    def prescribed_mismatch(self) -> float:
        """Largest |u - u_D| over the prescribed components at the current load (length).

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

    # -- diagnostics --------------------------------------------------------------------
    def _internal_force(self) -> la.Vector:
        """The strain energy's nodal forces at the current u (owned and ghosts summed)."""
        if self._internal_form is None:
            v = ufl.TestFunction(self.V)
            self._internal_form = fem.form(ufl.derivative(self.strain_energy(), self.u, v))
        vec = fem.assemble_vector(self._internal_form)
        vec.scatter_reverse(la.InsertMode.add)
        return vec

    def reaction(self, facets: np.ndarray) -> np.ndarray:
        """Internal nodal force summed over the facets' nodes, per component (force).

        With prescribed displacements on those facets this is the force the
        support exerts on the body (per unit thickness in 2D); tractions on
        the same facets are not included.
        """
        vec = self._internal_force()
        n_owned = self.V.dofmap.index_map.size_local
        out = np.zeros(self.gdim)
        for i in range(self.gdim):
            dofs = fem.locate_dofs_topological(self.V.sub(i), self.gdim - 1, facets)
            dofs = dofs[dofs < n_owned * self.gdim]
            out[i] = vec.array[dofs].sum()
        return self.comm.allreduce(out, op=MPI.SUM)

    def record_support_residual(self, dofs: np.ndarray,
                                values: np.ndarray | Callable[[], np.ndarray]) -> None:
        """Keep a solver's residual on the Dirichlet rows (owned u dofs) at the current u.

        The whole residual there (strain energy, tractions and every contact,
        the deformable targets' share condensed onto their vertices) is the
        supports' force on the bodies; :meth:`support_reactions` uses it while
        u is unchanged. ``values`` may be a function that assembles them when
        asked (collective).
        """
        self._support_residual = (np.asarray(dofs), values, self.u.x.array.copy())

    def support_reactions(self) -> dict[str, list[float]]:
        """The force each support exerts on the bodies, per component (force; per thickness in 2D).

        One entry per support: the prescribed-displacement conditions of one
        name (unnamed ones are ``dirichlet K``, K their position). A component
        is the nodal force summed over the displacement components the support
        prescribes (a free component reads 0), each counted once per support;
        a component two supports prescribe at one node counts in both. The
        nodal force is the whole residual at the current u when a solver
        recorded it (:meth:`record_support_residual`: a held node in contact
        passes its contact force to the support), else the internal force.
        Over supports that share no prescribed component, the reactions
        balance the contact forces and the tractions. Collective.
        """
        vec, held = self._support_dofs()
        local = np.array([[vec[np.unique(np.concatenate(c))].sum() if c else 0.0
                           for c in parts] for parts in held.values()]).reshape(-1, self.gdim)
        total = self.comm.allreduce(local, op=MPI.SUM)
        return {name: [float(v) for v in row] for name, row in zip(held, total, strict=True)}

    def support_total(self) -> list[float]:
        """The force all supports together exert on the bodies, per component (collective).

        Each prescribed component of a node counts once, where
        :meth:`support_reactions` counts a component two supports share in
        both: this total balances the contact forces and the tractions.
        """
        vec, held = self._support_dofs()
        local = np.array([
            vec[np.unique(np.concatenate([d for parts in held.values() for d in parts[i]]
                                         or [np.zeros(0, np.int32)]))].sum()
            for i in range(self.gdim)])
        return [float(v) for v in self.comm.allreduce(local, op=MPI.SUM)]

    def _support_dofs(self) -> tuple[np.ndarray, dict[str, list[list[np.ndarray]]]]:
        """(nodal forces, owned dofs per support and component) for the reactions."""
        vec = self._internal_force()
        recorded = getattr(self, "_support_residual", None)
        if recorded is not None and np.array_equal(recorded[2], self.u.x.array):
            values = recorded[1]() if callable(recorded[1]) else recorded[1]
            vec.array[recorded[0]] = values
        n_owned = self.V.dofmap.index_map.size_local * self.gdim
        fdim = self.domain.topology.dim - 1
        held: dict[str, list[list[np.ndarray]]] = {}
        for k, condition in enumerate(self.prescribed):
            parts = held.setdefault(condition.name or f"dirichlet {k + 1}",
                                    [[] for _ in range(self.gdim)])
            for i, value in enumerate(condition.at(1.0)):
                if value is not None:
                    dofs = fem.locate_dofs_topological(self.V.sub(i), fdim, condition.facets)
                    parts[i].append(dofs[dofs < n_owned])
        return vec.array, held

    def stresses(self) -> list[tuple[ufl.core.expr.Expr, np.ndarray | None]]:
        """Each body's Cauchy stress (3 x 3, UFL, with the moduli constants) and its cells."""
        return [
            (b.material.cauchy_stress(self.u, self._moduli[b.tag]),
             None if b.tag is None else self.cell_tags.find(b.tag))
            for b in self.bodies
        ]

    def body_ids(self) -> fem.Function | None:
        """Cell-wise body index (0, 1, ...) in the order of ``bodies`` (DG0); None for one body."""
        if len(self.bodies) == 1:
            return None
        D = fem.functionspace(self.domain, ("DG", 0))
        f = fem.Function(D, name="body_id")
        for i, b in enumerate(self.bodies):
            cells = self.cell_tags.find(b.tag)
            f.x.array[D.dofmap.list[cells].reshape(-1)] = float(i)
        f.x.scatter_forward()
        return f

    def min_det_F(self) -> DetFMinimum:
        """Smallest det F over the bodies (quadrature points of degree 2, all ranks).

        The points are those of a degree-2 rule on the cell, where the strain
        energy is integrated; one compiled expression per solid.
        """
        if not hasattr(self, "_det_expr"):
            import basix

            points, _ = basix.make_quadrature(self.domain.basix_cell(), 2)
            F = ufl.Identity(self.gdim) + ufl.grad(self.u)
            self._det_expr = fem.Expression(ufl.det(F), points)
            self._det_cells = np.arange(
                self.domain.topology.index_map(self.domain.topology.dim).size_local,
                dtype=np.int32,
            )
        if self._det_cells.size:
            values = self._det_expr.eval(self.domain, self._det_cells)
            flat = int(np.argmin(values))  # NaN first: an inside-out log J
            worst = flat // (values.size // self._det_cells.size)
            local = float(values.flat[flat])
            where = mesh.compute_midpoints(
                self.domain, self.domain.topology.dim, self._det_cells[worst : worst + 1]
            )[0]
        else:  # a rank without cells
            local, where = np.inf, np.zeros(3)
        if not np.isfinite(local):
            local = -np.inf if np.isnan(local) else local
        value, rank = self.comm.allreduce((local, self.comm.rank), op=MPI.MINLOC)
        where = self.comm.bcast(np.asarray(where, float), root=rank)
        return DetFMinimum(float(value), (float(where[0]), float(where[1]), float(where[2])))
