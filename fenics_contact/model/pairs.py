"""Two deformable bodies in one mesh: node-to-segment Alart-Curnier contact in UFL.

The bodies share one mesh, one displacement space and one set of boundary
conditions; cell tags tell them apart and each has its own material. A
contact pair is a striker facet set against a target facet set.

The gap of a striker node s on its assigned target facet (vertices a, b in
2D; a, b, c in 3D), in the current configuration ``x = X + u``:

    t = x_b - x_a,  n = perp(t) / |t|            (3D: (x_b - x_a) x (x_c - x_a) normalised)
    g = (x_s - x_a) . n                          (g >= 0 open)

The target vertex positions are held as vector P1 coefficients on the
striker's contact submesh: reference positions ``X_k`` and displacements
``w_k`` (k = a, b[, c]), filled by the search (:mod:`.search`) every
iteration. With ``x_k = X_k + w_k`` the gap is a UFL expression, so
``ufl.derivative`` with respect to u, lam and every w_k gives the residual
and the whole node-to-segment tangent, including the rotation of the target
facet. The solver condenses the w_k onto u with the selection w_k = S_k u
(:meth:`DeformablePair.sources`). Sign conventions as in
:mod:`fenics_contact.model.contact`: lam <= 0 is the striker's pressure.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import ufl
from dolfinx import fem, la, mesh

from mpi4py import MPI

from fenics_contact.model.contact import (
    ContactSettings,
    ContactSurface,
    augmented_lagrangian_energy,
    augmented_pressure,
)
from fenics_contact.model.materials import Elastic
from fenics_contact.model.problem import (
    ContactProblem,
    ContactState,
    PrescribedDisplacement,
    SurfaceTraction,
    energy_quadrature_degree,
)
from fenics_contact.model.search import SurfaceSearch, penetration_depth


@dataclass(frozen=True)
class Body:
    """One body of a multi-body mesh.

    Attributes:
        name: label used in outputs.
        tag: its cell tag in the mesh.
        material: its constitutive law.
    """

    name: str
    tag: int
    material: Elastic


def _node_to_block(V: fem.FunctionSpace) -> np.ndarray:
    """Local block (vertex dof) of V at each local geometry node (P1 on a P1 mesh)."""
    geo = V.mesh.geometry
    out = np.full(geo.x.shape[0], -1, dtype=np.int64)
    out[geo.dofmaps[0].reshape(-1)] = V.dofmap.list.reshape(-1)
    return out


class DeformablePair:
    """A striker surface against a deformable target surface of the same mesh.

    Args:
        V: the displacement space (vector P1).
        u: the displacement.
        surface: the striker's contact surface (its submesh carries lam and W).
        target_facets: local facet indices of the target surface.
    """

    def __init__(
        self,
        V: fem.FunctionSpace,
        u: fem.Function,
        surface: ContactSurface,
        target_facets: np.ndarray,
    ) -> None:
        domain = V.mesh
        comm = domain.comm
        gdim = domain.geometry.dim
        tdim = domain.topology.dim
        fdim = tdim - 1
        self.comm = comm
        self.gdim = gdim
        self.V = V
        self.u = u
        self.surface = surface
        nv = gdim  # vertices per facet: segments in 2D, triangles in 3D
        topology = domain.topology
        for d0, d1 in ((fdim, tdim), (0, tdim), (tdim, 0), (fdim, 0)):
            topology.create_connectivity(d0, d1)
        facet_im = topology.index_map(fdim)
        facets = np.unique(np.asarray(target_facets, np.int32))
        facets = facets[facets < facet_im.size_local]
        nodes = mesh.entities_to_geometry(domain, fdim, facets).reshape(-1, nv) \
            if facets.size else np.zeros((0, nv), np.int32)
        if facets.size and mesh.entities_to_geometry(domain, fdim, facets).shape[1] != nv:
            raise ValueError(
                "Target facets must be segments (2D) or triangles (3D); split "
                "quadrilateral faces into triangles."
            )
        x = domain.geometry.x[:, :gdim]
        # Orient each facet: the vertex order gives the outward normal.
        f2c = topology.connectivity(fdim, tdim)
        cells = np.array([f2c.links(f)[0] for f in facets], np.int64)
        cell_centre = (
            x[domain.geometry.dofmaps[0][cells]].mean(axis=1)
            if facets.size else np.zeros((0, gdim))
        )
        X = x[nodes]
        normal = self._normals(X)
        flip = np.einsum("ij,ij->i", normal, X.mean(axis=1) - cell_centre) < 0
        if nv == 2:
            nodes[flip] = nodes[flip][:, ::-1]
        else:
            nodes[flip] = nodes[flip][:, [0, 2, 1]]
        node_block = _node_to_block(V)
        im = V.dofmap.index_map
        gblocks = im.local_to_global(node_block[nodes].reshape(-1).astype(np.int32)).reshape(
            -1, nv
        ) if facets.size else np.zeros((0, nv), np.int64)
        # Target surface on every rank (O(surface) memory and traffic).
        all_blocks = np.concatenate(comm.allgather(gblocks.astype(np.int64)))
        all_X = np.concatenate(comm.allgather(x[nodes].reshape(-1, nv, gdim)))
        if all_blocks.shape[0] == 0:
            raise ValueError("The target facet set is empty on every rank.")
        self.target_blocks = all_blocks  # (m, nv) global V blocks per facet vertex
        self.vertices, self.facet_vertex = np.unique(all_blocks, return_inverse=True)
        self.facet_vertex = self.facet_vertex.reshape(-1, nv)
        self.X_vertices = np.zeros((self.vertices.size, gdim))
        self.X_vertices[self.facet_vertex.reshape(-1)] = all_X.reshape(-1, gdim)
        lo, hi = im.local_range
        mine = (self.vertices >= lo) & (self.vertices < hi)
        self._own_local = (self.vertices[mine] - lo).astype(np.int64)
        self._own_pos = np.concatenate(comm.allgather(np.flatnonzero(mine)))
        # Striker nodes: W blocks on the submesh and their parent V blocks.
        self.W = fem.functionspace(surface.submesh, ("Lagrange", 1, (gdim,)))
        sub_geo = surface.submesh.geometry
        parent_node = np.asarray(surface.node_map)[sub_geo.dofmaps[0].reshape(-1)]
        n_w = self.W.dofmap.index_map.size_local + self.W.dofmap.index_map.num_ghosts
        self._striker_node = np.zeros(n_w, np.int64)
        self._striker_node[self.W.dofmap.list.reshape(-1)] = parent_node
        self._striker_block = node_block[self._striker_node]
        self.n_owned = self.W.dofmap.index_map.size_local
        self.X = [fem.Function(self.W, name=f"target_X{k}") for k in range(nv)]
        self.w = [fem.Function(self.W, name=f"target_w{k}") for k in range(nv)]
        self.assignment = np.full(n_w, -1, np.int64)
        self.projection = None
        self.w_prev: list[fem.Function] | None = None
        #: Incremented whenever some striker node changes facet (on any rank).
        self.version = 0
        self.search_count = 0
        self._searched_u: np.ndarray | None = None

    def _normals(self, X: np.ndarray) -> np.ndarray:
        if self.gdim == 2:
            t = X[:, 1] - X[:, 0]
            return np.stack([t[:, 1], -t[:, 0]], axis=-1)
        return np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0])

    # -- UFL -------------------------------------------------------------------
    def positions(self) -> list[ufl.core.expr.Expr]:
        """Current positions x_k = X_k + w_k of the assigned facet's vertices."""
        return [Xk + wk for Xk, wk in zip(self.X, self.w, strict=True)]

    def normal(self) -> ufl.core.expr.Expr:
        """Unit outward normal of the assigned target facet (current configuration)."""
        xk = self.positions()
        if self.gdim == 2:
            t = xk[1] - xk[0]
            return ufl.as_vector((t[1], -t[0])) / ufl.sqrt(ufl.dot(t, t))
        c = ufl.cross(xk[1] - xk[0], xk[2] - xk[0])
        return c / ufl.sqrt(ufl.dot(c, c))

    def gap(self, x_s: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """Signed normal gap of the striker point ``x_s`` to its facet's plane (length)."""
        return ufl.dot(x_s - self.positions()[0], self.normal())

    def shape_weights(self, x_s: ufl.core.expr.Expr) -> list[ufl.core.expr.Expr]:
        """Weights N_k of the facet vertices at the projection of ``x_s`` (sum 1).

        2D: xi = (x_s - x_a) . t / |t|^2, N = (1 - xi, xi). 3D: the
        barycentric coordinates (1 - s - t, s, t) of the projection on the
        triangle's plane. Unclamped, like the gap.
        """
        xk = self.positions()
        d = x_s - xk[0]
        if self.gdim == 2:
            t = xk[1] - xk[0]
            xi = ufl.dot(d, t) / ufl.dot(t, t)
            return [1.0 - xi, xi]
        e1, e2 = xk[1] - xk[0], xk[2] - xk[0]
        g11, g12, g22 = ufl.dot(e1, e1), ufl.dot(e1, e2), ufl.dot(e2, e2)
        r1, r2 = ufl.dot(d, e1), ufl.dot(d, e2)
        det = g11 * g22 - g12**2
        s = (g22 * r1 - g12 * r2) / det
        t = (g11 * r2 - g12 * r1) / det
        return [1.0 - s - t, s, t]

    def track_previous(self, u_prev: fem.Function) -> list[fem.Function]:
        """Hold the assigned vertices' displacements in ``u_prev`` as data on W.

        Returns the coefficients w_prev_k (filled at every search and by
        :meth:`set_previous`); they are data, not unknowns.
        """
        self._u_prev = u_prev
        self.w_prev = [fem.Function(self.W, name=f"target_w{k}_prev") for k in range(self.gdim)]
        self.set_previous()
        return self.w_prev

    def set_previous(self) -> None:
        """Gather the target's displacements in u_prev and refill w_prev_k (collective)."""
        self._prev_t = self.target_displacements(self._u_prev)
        self._fill_previous()

    def _fill_previous(self) -> None:
        if self.w_prev is None or self.assignment.size == 0 or np.any(self.assignment < 0):
            return
        verts = self.facet_vertex[self.assignment]
        for k, wk in enumerate(self.w_prev):
            wk.x.array[:] = self._prev_t[verts[:, k]].reshape(-1)

    # -- search ------------------------------------------------------------------
    def target_displacements(self, u: fem.Function | None = None) -> np.ndarray:
        """Displacement (default: the current u) of every target vertex, on every rank."""
        bs = self.gdim
        values = (self.u if u is None else u).x.array.reshape(-1, bs)[self._own_local]
        gathered = np.concatenate(self.comm.allgather(values.reshape(-1, bs)))
        out = np.empty((self.vertices.size, bs))
        out[self._own_pos] = gathered
        return out

    def striker_positions(self) -> np.ndarray:
        """Current positions of the striker nodes (owned and ghost W blocks)."""
        x0 = self.V.mesh.geometry.x[self._striker_node, : self.gdim]
        return x0 + self.u.x.array.reshape(-1, self.gdim)[self._striker_block]

    def refresh(self) -> bool:
        """Search, then fill X_k and w_k; True when the assignment changed on any rank.

        Skipped (False) when u has not changed since the last search on any rank.
        """
        same = self._searched_u is not None and np.array_equal(self._searched_u, self.u.x.array)
        if self.comm.allreduce(same, op=MPI.LAND):
            return False
        self._searched_u = self.u.x.array.copy()
        w_t = self.target_displacements()
        current = (self.X_vertices + w_t)[self.facet_vertex]
        proj = SurfaceSearch(current).closest(self.striker_positions(), previous=self.assignment)
        self.search_count += 1
        self.projection = proj
        facet = proj.facet
        changed = not np.array_equal(facet[: self.n_owned], self.assignment[: self.n_owned])
        changed = self.comm.allreduce(changed, op=MPI.LOR)
        self.assignment = facet
        verts = self.facet_vertex[facet]
        for k in range(self.gdim):
            self.X[k].x.array[:] = self.X_vertices[verts[:, k]].reshape(-1)
            self.w[k].x.array[:] = w_t[verts[:, k]].reshape(-1)
        self._fill_previous()
        if changed:
            self.version += 1
        return changed

    def penetration(self) -> np.ndarray:
        """Depth of each owned striker node inside the current target surface (length, >= 0).

        Measured to the closest point of the whole target surface (collective:
        the target surface is gathered), not to the plane of the assigned
        facet: a node left on the extension of a facet it has passed can lie
        inside the real surface while its gap to that plane is positive.
        """
        current = (self.X_vertices + self.target_displacements())[self.facet_vertex]
        return penetration_depth(self.striker_positions()[: self.n_owned], current)

    def sources(self) -> list[np.ndarray]:
        """Global V block index that each owned W block selects, one array per vertex k.

        w_k = S_k u with S_k[i*bs + c, sources[k][i]*bs + c] = 1.
        """
        facet = self.assignment[: self.n_owned]
        return [self.target_blocks[facet, k] for k in range(self.gdim)]


class TwoBodyProblem(ContactProblem):
    """Several bodies in one mesh and one striker/target contact pair.

    Same API as :class:`ContactProblem` (the systems carry the target's
    vertex displacements as extra unknowns for the condensing kernel).
    ``r`` relative to E/h uses E = 2 E_s E_t / (E_s + E_t) of the striker's
    and target's bodies and h of the striker facets.
    """

    def __init__(
        self,
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
    ) -> None:
        gdim = domain.geometry.dim
        if domain.topology.dim != gdim:
            raise ValueError("The mesh's topological and geometric dimensions must agree.")
        if degree != 1:
            raise ValueError(
                f"Two-body contact needs degree = 1 (vertex node-to-segment), got {degree}."
            )
        if settings.quadrature != "nodal":
            raise ValueError(
                "Two-body contact is node-to-segment: use quadrature = 'nodal', "
                f"got {settings.quadrature!r}."
            )
        if not bodies:
            raise ValueError("Give at least one body.")
        tags = [b.tag for b in bodies]
        if len(set(tags)) != len(tags):
            raise ValueError(f"Body cell tags {tags} repeat; give each body its own tag.")
        present = set(np.unique(cell_tags.values).tolist())
        present = set().union(*domain.comm.allgather(present))
        for b in bodies:
            if b.tag not in present:
                raise ValueError(
                    f"Body {b.name!r} has cell tag {b.tag}, which no cell of the mesh carries "
                    f"(tags present: {sorted(present)})."
                )
        self.domain = domain
        self.comm = domain.comm
        self.cell_tags = cell_tags
        self.bodies = list(bodies)
        comm = domain.comm
        overlap = np.intersect1d(np.asarray(striker_facets), np.asarray(target_facets)).size
        if comm.allreduce(overlap, op=MPI.SUM):
            raise ValueError(
                "The striker and target facet sets share facets; a contact pair needs two "
                "disjoint surfaces (tag them separately)."
            )
        s_body = self._body_of(domain, cell_tags, bodies, striker_facets, striker, "striker")
        t_body = self._body_of(domain, cell_tags, bodies, target_facets, target, "target")
        Es, Et = s_body.material.E, t_body.material.E
        self.pair_modulus = 2.0 * Es * Et / (Es + Et)
        self.material = s_body.material
        self.obstacle = None
        self._unknowns(settings, striker_facets, tractions, degree)
        self._motion = np.zeros(gdim)
        self.bcs = self._dirichlet(prescribed)
        self._traction_constants = []
        external = self._external_work(tractions)

        self.pair = DeformablePair(self.V, self.u, self.surface, target_facets)
        x = ufl.SpatialCoordinate(domain) + self.u
        self.gap = self.pair.gap(x)
        self.pressure = augmented_pressure(self.gap, self.lam, self.r)
        dx = ufl.Measure("dx", domain=domain, subdomain_data=cell_tags)
        degrees = {}
        potential = 0
        for b in bodies:
            psi = b.material.strain_energy(self.u)
            degrees[b.tag] = energy_quadrature_degree(psi, self.u, degree)
            potential += psi * dx(b.tag, metadata={"quadrature_degree": degrees[b.tag]})
        self._dx = lambda tag: dx(tag, metadata={"quadrature_degree": degrees[tag]})
        self._internal_form = None
        self._target_force_forms: list[fem.Form] | None = None
        self.potential = potential
        if external is not None:
            self.potential -= external
        self._diagnostic_forms()
        self.pair.refresh()

    @staticmethod
    def _body_of(domain, cell_tags, bodies, facets, name, role) -> Body:
        """The body named ``name``, or the one whose cells carry the facets."""
        if name is not None:
            found = [b for b in bodies if b.name == name]
            if not found:
                raise ValueError(
                    f"The {role} body {name!r} is not among the bodies "
                    f"{[b.name for b in bodies]}; use one of those names."
                )
            return found[0]
        tdim = domain.topology.dim
        domain.topology.create_connectivity(tdim - 1, tdim)
        f2c = domain.topology.connectivity(tdim - 1, tdim)
        tag_of = dict(zip(cell_tags.indices.tolist(), cell_tags.values.tolist(), strict=True))
        local = {tag_of.get(int(c)) for f in np.asarray(facets) for c in f2c.links(int(f))}
        tags = set().union(*domain.comm.allgather(local)) - {None}
        matching = [b for b in bodies if b.tag in tags]
        if len(matching) != 1:
            raise ValueError(
                f"The {role} facets border cells of {len(matching)} bodies "
                f"({[b.name for b in matching]}); a {role} surface lies on one body."
            )
        return matching[0]

    # -- parameters and loads ---------------------------------------------------
    @property
    def stiffness_scale(self) -> float:
        """E/h with E the pair modulus 2 E_s E_t / (E_s + E_t) (stress per length)."""
        return self.pair_modulus / self.surface.h

    def set_load(self, t: float) -> None:
        """Apply the load factor t to the prescribed values and tractions."""
        self.load_factor = float(t)
        self._apply_prescribed(t)
        for const, value in self._traction_constants:
            const.value[:] = t * value

    def reaction(self, facets: np.ndarray) -> np.ndarray:
        """Internal nodal force summed over the facets' nodes, per component (force).

        With prescribed displacements on those facets this is the force the
        support exerts on the body (per unit thickness in 2D); tractions on
        the same facets are not included.
        """
        if self._internal_form is None:
            v = ufl.TestFunction(self.V)
            psi = None
            for b in self.bodies:
                term = b.material.strain_energy(self.u) * self._dx(b.tag)
                psi = term if psi is None else psi + term
            self._internal_form = fem.form(ufl.derivative(psi, self.u, v))
        vec = fem.assemble_vector(self._internal_form)
        vec.scatter_reverse(la.InsertMode.add)
        gdim = self.domain.geometry.dim
        n_owned = self.V.dofmap.index_map.size_local
        out = np.zeros(gdim)
        for i in range(gdim):
            dofs = fem.locate_dofs_topological(self.V.sub(i), gdim - 1, facets)
            dofs = dofs[dofs < n_owned * gdim]
            out[i] = vec.array[dofs].sum()
        return self.comm.allreduce(out, op=MPI.SUM)

    def _contact_residual(self, wk: fem.Function, q: ufl.Argument) -> ufl.Form:
        """dL_c/dw_k[q] of the contact term (the force on the k-th facet vertex, negated)."""
        term = augmented_lagrangian_energy(self.gap, self.lam, self.r) * self.surface.ds
        return ufl.derivative(term, wk, q)

    def target_force(self) -> fem.Function:
        """Contact force the striker puts on the target's vertices (force per node).

        f_target = sum_k S_k^T dL_c/dw_k with L_c the contact term: the
        node-to-segment transfer, (1 - xi) and xi of each striker node's
        force on its facet's vertices in 2D. Zero off the target surface.
        """
        if self._target_force_forms is None:
            q = ufl.TestFunction(self.pair.W)
            self._target_force_forms = [
                fem.form(self._contact_residual(wk, q), entity_maps=self.surface.entity_maps)
                for wk in self.pair.w
            ]
        self.pair.refresh()
        from petsc4py import PETSc

        gdim = self.domain.geometry.dim
        im = self.V.dofmap.index_map
        vec = PETSc.Vec().createMPI((im.size_local * gdim, im.size_global * gdim),
                                    bsize=gdim, comm=self.comm)
        vec.set(0.0)
        for form, src in zip(self._target_force_forms, self.pair.sources(), strict=True):
            local = fem.assemble_vector(form)
            local.scatter_reverse(la.InsertMode.add)
            values = local.array[: self.pair.n_owned * gdim]
            vec.setValuesBlocked(src.astype(PETSc.IntType), values, addv=PETSc.InsertMode.ADD)
        vec.assemblyBegin()
        vec.assemblyEnd()
        out = fem.Function(self.V, name="target_contact_force")
        out.x.array[: im.size_local * gdim] = -vec.getArray(readonly=True)
        out.x.scatter_forward()
        vec.destroy()
        return out

    def laws(self) -> list[tuple[Elastic, np.ndarray | None]]:
        """Each body's law and the cells it holds."""
        return [(b.material, self.cell_tags.find(b.tag)) for b in self.bodies]

    def body_ids(self) -> fem.Function:
        """Cell-wise body index (0, 1, ...) in the order of ``bodies`` (DG0)."""
        D = fem.functionspace(self.domain, ("DG", 0))
        f = fem.Function(D, name="body_id")
        for i, b in enumerate(self.bodies):
            cells = self.cell_tags.find(b.tag)
            f.x.array[D.dofmap.list[cells].reshape(-1)] = float(i)
        f.x.scatter_forward()
        return f

    # -- systems -----------------------------------------------------------------
    def _extra_unknowns(self) -> list[fem.Function]:
        """The target vertex displacements w_k (condensed by w_k = S_k u)."""
        return list(self.pair.w)

    # -- diagnostics (search first: u may have moved since the last assembly) -----
    def refresh_search(self) -> None:
        """Search and refill the target coefficients when u has changed."""
        self.pair.refresh()

    def contact_state(self) -> ContactState:
        """Nodal gaps, pressures and global summaries at the current u (fresh search).

        The max penetration is measured against the actual target surface
        (:meth:`DeformablePair.penetration`), so the Signorini check and the
        report see a node that sits inside the target past the end of its facet.
        """
        self.pair.refresh()
        state = super().contact_state()
        depth = self.pair.penetration()
        deepest = self.comm.allreduce(float(np.max(depth, initial=0.0)), op=MPI.MAX)
        return dataclasses.replace(
            state, max_penetration=deepest, constraint_penetration=state.max_penetration
        )

    def active_signature(self) -> tuple[bytes, ...]:
        """Fingerprint of the active set at the current u (fresh search)."""
        self.pair.refresh()
        return super().active_signature()

    def update_multiplier(self) -> None:
        """Uzawa update at the current u (fresh search)."""
        self.pair.refresh()
        super().update_multiplier()
