"""Contact terms in UFL and the multiplier space on the contact submesh.

Sign conventions: the gap ``g >= 0`` when open; the multiplier ``lam <= 0``
is the normal contact pressure (force per unit reference area); ``r > 0``
(stress per length) is the penalty or augmentation parameter.

Penalty (paper eq. 7):            r/2 min(g, 0)^2
Alart-Curnier (paper eq. 9):      [min(lam + r g, 0)^2 - lam^2] / (2 r)
Stationarity in lam gives the AC complementarity function
lam = min(lam + r g, 0), which holds at the nodes with the vertex rule.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import ufl
from dolfinx import fem, la, mesh

from mpi4py import MPI

from fenics_contact.model.form_batches import form_together

Quadrature = Literal["nodal", "gauss"]

#: Tag given to candidate contact facets in the facet tags of ``ds``.
CONTACT_TAG = 1


def assemble_local(compiled: fem.Form) -> np.ndarray:
    """Assemble a linear form; return the owned entries with ghost contributions summed in."""
    vec = fem.assemble_vector(compiled)
    vec.scatter_reverse(la.InsertMode.add)
    n = vec.index_map.size_local * vec.block_size
    return vec.array[:n].copy()


def penalty_energy(g: ufl.core.expr.Expr, r: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """Penalty energy density r/2 min(g, 0)^2 (energy per reference area).

    Written min(0, g): UFL differentiates min(a, b) as b's derivative where
    a < b fails, so a touching node (g = 0) takes the closed branch in the
    tangent. Written min(g, 0), it took the open one: a body that only
    touches its support at the start had no stiffness there, and a load
    pressing it sent the first Newton step to infinity.
    """
    return 0.5 * r * ufl.min_value(0, g) ** 2


def augmented_lagrangian_energy(
    g: ufl.core.expr.Expr, lam: ufl.core.expr.Expr, r: ufl.core.expr.Expr
) -> ufl.core.expr.Expr:
    """Alart-Curnier augmented Lagrangian density [min(lam + r g, 0)^2 - lam^2] / (2 r)."""
    return (ufl.min_value(lam + r * g, 0) ** 2 - lam**2) / (2 * r)


def augmented_pressure(
    g: ufl.core.expr.Expr, lam: ufl.core.expr.Expr, r: ufl.core.expr.Expr
) -> ufl.core.expr.Expr:
    """The pressure the AL term transmits, min(lam + r g, 0) (<= 0)."""
    return ufl.min_value(lam + r * g, 0)


def r_problem(r: float) -> str | None:
    """What is wrong with the contact parameter r, or None: the one rule for r."""
    if not (np.isfinite(r) and r > 0):
        return "must be finite and > 0; typical values are 1e-2 to 1e2 relative to E/h."
    return None


def check_r(r: float) -> None:
    """Raise ValueError when :func:`r_problem` finds r invalid (TypeError: not a number)."""
    if isinstance(r, bool) or not isinstance(r, int | float | np.floating | np.integer):
        raise TypeError(f"The contact parameter r = {r!r} must be a number (stress per length, "
                        "or a multiple of E/h with relative = True).")
    problem = r_problem(r)
    if problem is not None:
        raise ValueError(f"The contact parameter r = {r}: {problem}")


@dataclass(frozen=True)
class ContactSettings:
    """How contact is regularised and integrated.

    Attributes:
        r: penalty/augmentation parameter, 1 by default. Relative to E/h (E
            Young's modulus, h the mean contact facet size) when ``relative``
            is true (the default), absolute (stress/length) otherwise, as the
            paper's tables give it.
        relative: see ``r``.
        quadrature: 'nodal' (default) puts the quadrature points at the facet
            vertices (the paper's node-on-facet, lumped multiplier mass, the
            complementarity exact at each node, an answer independent of r);
            'gauss' integrates the contact term with a degree-4 Gauss rule on
            each facet (an integral constraint whose answer depends a little
            on r; needed with quadratic displacements).
        interference_until: the load factor by which an overlap the surfaces
            start in (an interference fit meshed as it is before assembly) is
            resolved: each striker node's starting overlap is allowed, less
            and less in proportion to the load factor, until then. None (the
            default): the first load step resolves it at once.
    """

    r: float = 1.0
    relative: bool = True
    quadrature: Quadrature = "nodal"
    interference_until: float | None = None

    def __post_init__(self) -> None:
        check_r(self.r)
        t = self.interference_until
        if t is not None and not 0.0 < t <= 1.0:
            raise ValueError(f"interference_until must be a load factor in (0, 1], got {t}.")
        if self.quadrature not in ("nodal", "gauss"):
            raise ValueError(
                f"Contact quadrature {self.quadrature!r} is unknown; use 'nodal' or 'gauss'."
            )


def vertex_measure(
    domain: mesh.Mesh,
    tags: mesh.MeshTags,
    quadrature: Quadrature = "nodal",
    ids: int | tuple[int, ...] = CONTACT_TAG,
) -> ufl.Measure:
    """Surface measure over the facets tagged ``ids``, with the vertex rule for 'nodal'."""
    metadata = (
        {"quadrature_rule": "vertex", "quadrature_degree": 1}
        if quadrature == "nodal"
        else {"quadrature_degree": 4}
    )
    return ufl.Measure(
        "ds", domain=domain, subdomain_data=tags, subdomain_id=ids, metadata=metadata
    )


def facet_diameters(domain: mesh.Mesh, facets: np.ndarray) -> np.ndarray:
    """Largest vertex-to-vertex distance of each facet (length units)."""
    fdim = domain.topology.dim - 1
    nodes = mesh.entities_to_geometry(domain, fdim, facets)
    coords = domain.geometry.x[nodes]  # (n_facets, n_nodes, 3)
    diffs = coords[:, :, None, :] - coords[:, None, :, :]
    return np.linalg.norm(diffs, axis=-1).max(axis=(1, 2))


class ContactSurface:
    """Candidate contact facets, their submesh and the P1 multiplier space on it.

    Only the facets given here carry multiplier degrees of freedom.
    """

    def __init__(
        self,
        domain: mesh.Mesh,
        facets: np.ndarray,
        quadrature: Quadrature = "nodal",
        tags: mesh.MeshTags | None = None,
        ids: int | tuple[int, ...] = CONTACT_TAG,
    ) -> None:
        """Build the submesh and multiplier space.

        ``tags``: facet tags of the whole mesh in which ``facets`` are those
        carrying the values ``ids`` (one tag set must serve every ``ds`` of a
        form, see :func:`~.tags.facet_roles`); made here when not given.
        """
        fdim = domain.topology.dim - 1
        domain.topology.create_connectivity(fdim, domain.topology.dim)
        facets = np.unique(np.asarray(facets, dtype=np.int32))
        n_global = domain.comm.allreduce(facets.size, op=MPI.SUM)
        if n_global == 0:
            raise ValueError(
                "No candidate contact facets: check the contact tag or the obstacle "
                "detection margin."
            )
        self.domain = domain
        self.facets = facets
        self.quadrature = quadrature
        self.tags = tags if tags is not None else mesh.meshtags(
            domain, fdim, facets, np.full(facets.size, CONTACT_TAG, dtype=np.int32)
        )
        self.submesh, self.entity_map, _, self.node_map = mesh.create_submesh(domain, fdim, facets)
        self.Q = fem.functionspace(self.submesh, ("Lagrange", 1))
        self.ds = vertex_measure(domain, self.tags, quadrature, ids)
        self.ds_nodal = vertex_measure(domain, self.tags, "nodal", ids)
        self.entity_maps = [self.entity_map]
        size = domain.comm.allreduce(float(np.sum(facet_diameters(domain, facets))), op=MPI.SUM)
        #: Mean size of the candidate contact facets (length units).
        self.h = size / n_global
        mu = ufl.TestFunction(self.Q)
        self._mu = mu
        self.lumped_area = assemble_local(
            fem.form(mu * self.ds_nodal, entity_maps=self.entity_maps)
        )

    def parent_dofs(self, V: fem.FunctionSpace) -> np.ndarray:
        """The block (vertex dof) of the body's P1 space ``V`` at each local multiplier dof.

        Found through the submesh's geometry-node map, cell by cell: a
        multiplier node maps to its own parent vertex even where another body
        has a vertex at the same point (two bodies meshed touching).
        Ghost multiplier dofs are included (length: owned + ghost).
        """
        parent_node = np.asarray(self.node_map)
        sub_nodes = self.submesh.geometry.dofmaps[0]
        q_dofs = self.Q.dofmap.list
        n_vertices = q_dofs.shape[1]
        body_block = np.full(V.mesh.geometry.x.shape[0], -1, dtype=np.int64)
        body_nodes = V.mesh.geometry.dofmaps[0]
        body_block[body_nodes[:, : V.dofmap.list.shape[1]].reshape(-1)] = V.dofmap.list.reshape(-1)
        index_map = self.Q.dofmap.index_map
        out = np.full(index_map.size_local + index_map.num_ghosts, -1, dtype=np.int64)
        out[q_dofs.reshape(-1)] = body_block[parent_node[sub_nodes[:, :n_vertices].reshape(-1)]]
        return out

    @property
    def num_dofs(self) -> int:
        """Global number of multiplier degrees of freedom."""
        im = self.Q.dofmap.index_map
        return im.size_global * self.Q.dofmap.index_map_bs

    #: Compilation options of the forms on this surface (None: the defaults).
    jit_options: dict | None = None

    def nodal_integrand(self, expr: ufl.core.expr.Expr) -> ufl.Form:
        """The UFL form whose assembled vector is the lumped area times ``expr`` at each node."""
        return expr * self._mu * self.ds_nodal

    def nodal_form(self, expr: ufl.core.expr.Expr) -> fem.Form:
        """Compile the form that gives nodal values of ``expr`` (see :meth:`nodal`)."""
        return self.compile(self.nodal_integrand(expr))

    def compile(self, forms: Any) -> Any:
        """Compile a UFL form or a nested list of them on this surface, in one C module.

        One module for many forms saves the fixed cost of a compilation per
        form on an empty cache (:func:`~.form_batches.form_together`).
        """
        return form_together(forms, entity_maps=self.entity_maps, jit_options=self.jit_options)

    def nodal(self, compiled: fem.Form) -> np.ndarray:
        """Values at the owned multiplier nodes of an expression compiled by :meth:`nodal_form`.

        The vertex rule makes the assembled vector the lumped area times the
        nodal value; dividing by the lumped area returns the value.
        """
        return assemble_local(compiled) / self.lumped_area
