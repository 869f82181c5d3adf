"""fenics-contact: frictionless contact of hyperelastic bodies on FEniCSx.

The contact term (penalty or the Alart-Curnier augmented Lagrangian) is a UFL
form on a mixed displacement/multiplier space whose multiplier lives on a
submesh of the candidate contact facets. Every tangent comes from
``ufl.derivative``. Solution strategies (penalty, Uzawa, generalized Newton)
are Python drivers over one Newton kernel.

Sign convention: the gap ``g`` is positive when open; the multiplier
``lam <= 0`` is the normal contact pressure (force per reference area).
"""

try:  # the wheel build of DOLFINx must be imported before dolfinx/petsc4py
    import dolfinx_solver  # noqa: F401
except ImportError:  # DOLFINx installed otherwise (official images)
    pass

__version__ = "0.1.0"
