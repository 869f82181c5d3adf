"""Two-body examples for ``study`` and the stability grid.

Two cylinders, the contact patch test and the sliding blocks with Coulomb
friction are linear elastic (E = 200, nu = 0.3, plane strain) with one
node-to-segment pair (upper body: striker; lower: target) and non-matching
meshes; the nodal (vertex) rule is the only quadrature two-body contact has.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from dolfinx.io.gmsh import MeshData

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import FrictionSettings
from fenics_contact.model.materials import material
from fenics_contact.model.problem import (
    Body,
    ContactProblem,
    PathDisplacement,
    PrescribedDisplacement,
    two_body_problem,
)
from fenics_contact.scene import two_body_meshing as tbm

#: Prescribed components by facet tag (None: free), values at load factor 1 (length).
Fixed = dict[int, tuple[float | None, ...]]
#: Knots (t, u_1, ..., u_d) of a piecewise-linear displacement path (length).
Path = tuple[tuple[float, ...], ...]


def linear_pair(
    md: MeshData,
    settings: ContactSettings,
    fixed: Fixed,
    E_upper: float = 200.0,
    E_lower: float = 200.0,
    *,
    paths: dict[int, Path] | None = None,
    mu: float | None = None,
    tangential_r_max: float | None = 2.0,
) -> ContactProblem:
    """Linear elastic bodies (nu = 0.3) on a :mod:`~fenics_contact.scene.two_body_meshing` mesh.

    The upper body (cell tag STRIKER_TAG) is the striker, its contact face
    STRIKER_FACE_TAG; the lower one the target (TARGET_TAG, TARGET_FACE_TAG).

    Args:
        md: the two-body mesh with its cell and facet tags.
        settings: contact settings (r, quadrature).
        fixed: prescribed displacements by facet tag, proportional to the load factor.
        E_upper: Young's modulus of the striker (stress).
        E_lower: Young's modulus of the target (stress).
        paths: displacements by facet tag along a piecewise-linear path in the load factor.
        mu: Coulomb coefficient (None: frictionless; a number, 0 included: Coulomb
            friction).
        tangential_r_max: cap of r_t relative to E/L (friction only; None: r_t = r).
    """
    ft = md.facet_tags
    bodies = [Body("upper", tbm.STRIKER_TAG, material("linear", E_upper, 0.3)),
              Body("lower", tbm.TARGET_TAG, material("linear", E_lower, 0.3))]
    prescribed = [PrescribedDisplacement(ft.find(tag), value) for tag, value in fixed.items()]
    prescribed += [PathDisplacement(ft.find(tag), (None,) * len(path[0][1:]), path=path)
                   for tag, path in (paths or {}).items()]
    args = (md.mesh, md.cell_tags, bodies, ft.find(tbm.STRIKER_FACE_TAG),
            ft.find(tbm.TARGET_FACE_TAG), settings)
    friction = None if mu is None else FrictionSettings(mu, tangential_r_max)
    return two_body_problem(*args, prescribed=prescribed, friction=friction)


def hemispheres_fixed(push: float) -> Fixed:
    """Dirichlet data of :func:`two_body_meshing.two_hemispheres`: flat faces ``push`` closer."""
    return {tbm.LOAD_TAG: (None, None, -push), tbm.SUPPORT_TAG: (None, None, 0.0),
            tbm.SYMMETRY_TAG: (0.0, None, None), tbm.SYMMETRY_Y_TAG: (None, 0.0, None)}


@dataclass
class TwoCylinders:
    """Two half-disks (R = 1) pushed together by ``push`` (Hertz, two cylinders).

    Attributes:
        h_contact: element size at the contact point (length).
        push: approach of the flat faces at load factor 1 (length).
        steps: load steps.
        stiffness_ratio: E_upper / E_lower (E_lower = 200).
    """

    h_contact: float = 0.02
    push: float = 0.02
    steps: int = 3
    stiffness_ratio: float = 1.0

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh both bodies and create the problem."""
        md = tbm.two_half_disks(comm, h_contact=self.h_contact, h_far=0.2)
        return linear_pair(
            md, settings, {tbm.LOAD_TAG: (0.0, -self.push), tbm.SUPPORT_TAG: (0.0, 0.0)},
            E_upper=200.0 * self.stiffness_ratio,
        )


@dataclass
class BlockOnBlock:
    """The contact patch test: a block pressed by 0.01 onto another (8 and 11 divisions).

    Attributes:
        n_upper, n_lower: divisions along x of the striker and the target.
        steps: load steps.
        upper_width: width of the striker, centred on the 1-wide target (None: 1).
    """

    n_upper: int = 8
    n_lower: int = 11
    steps: int = 2
    upper_width: float | None = None

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh both blocks and create the problem."""
        return self.problem(self.mesh(comm), settings)

    def problem(self, md: MeshData, settings: ContactSettings) -> ContactProblem:
        """The problem on the mesh ``md`` of :meth:`mesh` (keep ``md`` for its facet tags)."""
        return linear_pair(md, settings, self.FIXED)

    #: Pressed 0.01 at the top, held at the bottom, symmetric at x = 0.
    FIXED: ClassVar[Fixed] = {tbm.LOAD_TAG: (None, -0.01), tbm.SUPPORT_TAG: (None, 0.0),
                              tbm.SYMMETRY_TAG: (0.0, None)}

    def mesh(self, comm: MPI.Comm = MPI.COMM_WORLD) -> MeshData:
        """The two blocks' mesh (:func:`two_body_meshing.block_on_block`)."""
        return tbm.block_on_block(comm, n_upper=self.n_upper, n_lower=self.n_lower,
                                  upper_width=self.upper_width)


#: Sliding blocks: press 0.01 over load factors 0 ... 0.4, then slide 0.04 (t, dx, dy).
PRESS_SLIDE_PAIR: Path = ((0.0, 0.0, 0.0), (0.4, 0.0, -0.01), (1.0, 0.04, -0.01))
#: Press as above, slide +0.04 by t = 0.7, then back to -0.02: the friction reverses.
REVERSAL_PAIR: Path = ((0.0, 0.0, 0.0), (0.4, 0.0, -0.01), (0.7, 0.04, -0.01),
                       (1.0, -0.02, -0.01))


@dataclass
class SlidingBlocks(BlockOnBlock):
    """A 0.6-wide block (6 divisions) pressed onto a 1-wide one (9), then slid, with friction.

    The striker's top follows ``path`` (t, dx, dy); the target's bottom is
    clamped. Coulomb coefficient ``mu`` (None: the frictionless pair), r_t =
    min(r, tangential_r_max E/L) (None: r_t = r).
    """

    n_upper: int = 6
    n_lower: int = 9
    steps: int = 10
    upper_width: float | None = 0.6
    mu: float | None = 0.3
    path: Path = PRESS_SLIDE_PAIR
    tangential_r_max: float | None = 2.0

    def problem(self, md: MeshData, settings: ContactSettings) -> ContactProblem:
        """The (frictional) problem on the mesh ``md`` of :meth:`mesh`."""
        return linear_pair(
            md, settings, {tbm.SUPPORT_TAG: (0.0, 0.0)},
            paths={tbm.LOAD_TAG: self.path}, mu=self.mu,
            tangential_r_max=self.tangential_r_max,
        )


@dataclass
class IroningShort:
    """Coarse ironing: neo-Hookean indenter (E = 1000) on a block (E = 100).

    Pressed 0.1 over the first 20 % of the path, then slid ``slide`` (0.6 =
    1.2 radii).
    """

    steps: int = 10
    slide: float = 0.6

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> ContactProblem:
        """Mesh indenter and block and create the problem."""
        from fenics_contact.model.problem import PathDisplacement

        md = tbm.ironing(comm, h_indenter=0.08, h_block=0.12)
        ft = md.facet_tags
        bodies = [Body("indenter", tbm.STRIKER_TAG, material("neo-hookean", 1000.0, 0.3)),
                  Body("block", tbm.TARGET_TAG, material("neo-hookean", 100.0, 0.3))]
        path = ((0.0, 0.0, 0.0), (0.2, 0.0, -0.1), (1.0, self.slide, -0.1))
        return two_body_problem(
            md.mesh, md.cell_tags, bodies, ft.find(tbm.STRIKER_FACE_TAG),
            ft.find(tbm.TARGET_FACE_TAG), settings,
            prescribed=[PrescribedDisplacement(ft.find(tbm.SUPPORT_TAG), (0.0, 0.0)),
                        PathDisplacement(ft.find(tbm.LOAD_TAG), (None, None), path=path)],
        )
