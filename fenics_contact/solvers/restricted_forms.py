"""Forms integrated over fewer facets: compiled forms rebuilt with shorter entity lists.

A frictionless node-to-segment pair's terms vanish exactly at a striker
node that is open at any r (lam >= 0 and a gap above a facet size,
:meth:`~fenics_contact.model.pairs.DeformablePair.coupled`): its residual,
its tangent and its coupling to the target are zero there, whatever the
target's vertices do. Only the multiplier's own equation, lam / r = 0,
remains, and that is a block of its own. Most striker facets are such
open facets (about seven in eight on the hemispheres), and the contact
kernels are the largest of the problem, so a Newton kernel integrates the
contact terms only over the facets that touch a node that can act.

:func:`restrict` builds a DOLFINx ``Form`` from the same compiled module
as a given one (no compilation: the module, its coefficients and constants
are shared) with the exterior-facet entities of chosen tag values limited
to chosen facets; every other integral keeps its entities.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from dolfinx import fem, mesh

#: The integral types in the order of a compiled form's integral offsets.
_TYPES = tuple(fem.IntegralType)


class FacetLimit:
    """Exterior-facet integrals of some tag values, limited to some facets.

    ``ids``: the tag values whose integrals are limited; ``facets``: local
    facet indices of the mesh to keep (sorted, unique).
    """

    def __init__(self, ids: Sequence[int], facets: np.ndarray) -> None:
        self.ids = tuple(int(i) for i in ids)
        self.facets = np.unique(np.asarray(facets, np.int32))

    def same_as(self, other: FacetLimit | None) -> bool:
        """Whether ``other`` limits the same tag values to the same facets."""
        return (other is not None and other.ids == self.ids
                and np.array_equal(other.facets, self.facets))


def _facets_of(domain: mesh.Mesh, pairs: np.ndarray) -> np.ndarray:
    """The local facet index of each (cell, local facet) pair."""
    tdim = domain.topology.dim
    domain.topology.create_connectivity(tdim, tdim - 1)
    c2f = domain.topology.connectivity(tdim, tdim - 1)
    return c2f.array[c2f.offsets[pairs[:, 0]] + pairs[:, 1]]


def restrict(form: fem.Form, limits: Sequence[FacetLimit], entity_maps: Sequence) -> fem.Form:
    """``form`` with each limit's exterior-facet integrals over its facets only.

    Args:
        form: a form made by ``dolfinx.fem.form`` (it keeps its module).
        limits: the tag values to limit and the facets to keep of each.
        entity_maps: the entity maps the form was made with (submeshes).

    Returns:
        A new form sharing the compiled kernels, coefficients and constants.
    """
    cpp, ufcx = form._cpp_object, form.ufcx_form
    domain = form.mesh
    keep = {i: limit.facets for limit in limits for i in limit.ids}
    offsets = [ufcx.form_integral_offsets[k] for k in range(len(_TYPES) + 1)]
    subdomains: dict = {}
    for k, kind in enumerate(_TYPES):
        entries = []
        for j in range(offsets[k], offsets[k + 1]):
            tag = int(ufcx.form_integral_ids[j])
            entities = np.asarray(cpp.domains(kind, j - offsets[k]), np.int32)
            if kind == fem.IntegralType.exterior_facet and tag in keep:
                pairs = entities.reshape(-1, 2)
                entities = pairs[np.isin(_facets_of(domain, pairs), keep[tag])]
            entries.append((tag, np.ascontiguousarray(entities.reshape(-1))))
        if entries:
            subdomains[kind] = entries
    module = form.module
    pointer = module.ffi.cast("uintptr_t", module.ffi.addressof(ufcx))
    made = type(cpp)([pointer], cpp.function_spaces, cpp.coefficients, cpp.constants,
                     subdomains, [m._cpp_object for m in entity_maps], cpp.mesh)
    return fem.Form(made, ufcx, form.code, module)


__all__ = ["FacetLimit", "restrict"]
