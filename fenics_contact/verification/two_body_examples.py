"""Two-body examples for ``study``: two cylinders and the contact patch test.

Both are linear elastic (E = 200, nu = 0.3, plane strain) with one
node-to-segment pair (upper body: striker; lower: target) and non-matching
meshes; the nodal (vertex) rule is the only quadrature two-body contact has.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from dolfinx.io.gmsh import MeshData

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.materials import material
from fenics_contact.model.pairs import Body, TwoBodyProblem
from fenics_contact.model.problem import PrescribedDisplacement
from fenics_contact.scene import two_body_meshing as tbm

#: Prescribed components by facet tag (None: free), values at load factor 1 (length).
Fixed = dict[int, tuple[float | None, ...]]


def linear_pair(
    md: MeshData,
    settings: ContactSettings,
    fixed: Fixed,
    E_upper: float = 200.0,
    E_lower: float = 200.0,
) -> TwoBodyProblem:
    """Linear elastic bodies (nu = 0.3) on a :mod:`~fenics_contact.scene.two_body_meshing` mesh.

    The upper body (cell tag STRIKER_TAG) is the striker, its contact face
    STRIKER_FACE_TAG; the lower one the target (TARGET_TAG, TARGET_FACE_TAG).

    Args:
        md: the two-body mesh with its cell and facet tags.
        settings: contact settings (r, quadrature).
        fixed: prescribed displacements by facet tag, proportional to the load factor.
        E_upper: Young's modulus of the striker (stress).
        E_lower: Young's modulus of the target (stress).
    """
    ft = md.facet_tags
    bodies = [Body("upper", tbm.STRIKER_TAG, material("linear", E_upper, 0.3)),
              Body("lower", tbm.TARGET_TAG, material("linear", E_lower, 0.3))]
    return TwoBodyProblem(
        md.mesh, md.cell_tags, bodies,
        ft.find(tbm.STRIKER_FACE_TAG), ft.find(tbm.TARGET_FACE_TAG), settings,
        prescribed=[PrescribedDisplacement(ft.find(tag), value) for tag, value in fixed.items()],
    )


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

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> TwoBodyProblem:
        """Mesh both bodies and create the problem."""
        md = tbm.two_half_disks(comm, h_contact=self.h_contact, h_far=0.2)
        return linear_pair(
            md, settings, {tbm.LOAD_TAG: (0.0, -self.push), tbm.SUPPORT_TAG: (0.0, 0.0)},
            E_upper=200.0 * self.stiffness_ratio,
        )


@dataclass
class BlockOnBlock:
    """The contact patch test: a block pressed by 0.01 onto another (8 and 11 divisions)."""

    n_upper: int = 8
    n_lower: int = 11
    steps: int = 2

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> TwoBodyProblem:
        """Mesh both blocks and create the problem."""
        return linear_pair(self.mesh(comm), settings, self.FIXED)

    #: Pressed 0.01 at the top, held at the bottom, symmetric at x = 0.
    FIXED: ClassVar[Fixed] = {tbm.LOAD_TAG: (None, -0.01), tbm.SUPPORT_TAG: (None, 0.0),
                              tbm.SYMMETRY_TAG: (0.0, None)}

    def mesh(self, comm: MPI.Comm = MPI.COMM_WORLD) -> MeshData:
        """The two blocks' mesh (:func:`two_body_meshing.block_on_block`)."""
        return tbm.block_on_block(comm, n_upper=self.n_upper, n_lower=self.n_lower)


@dataclass
class IroningShort:
    """Coarse ironing: neo-Hookean indenter (E = 1000) on a block (E = 100).

    Pressed 0.1 over the first 20 % of the path, then slid ``slide`` (0.6 =
    1.2 radii).
    """

    steps: int = 10
    slide: float = 0.6

    def build(self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD) -> TwoBodyProblem:
        """Mesh indenter and block and create the problem."""
        from fenics_contact.model.problem import PathDisplacement

        md = tbm.ironing(comm, h_indenter=0.08, h_block=0.12)
        ft = md.facet_tags
        bodies = [Body("indenter", tbm.STRIKER_TAG, material("neo-hookean", 1000.0, 0.3)),
                  Body("block", tbm.TARGET_TAG, material("neo-hookean", 100.0, 0.3))]
        path = ((0.0, 0.0, 0.0), (0.2, 0.0, -0.1), (1.0, self.slide, -0.1))
        return TwoBodyProblem(
            md.mesh, md.cell_tags, bodies, ft.find(tbm.STRIKER_FACE_TAG),
            ft.find(tbm.TARGET_FACE_TAG), settings,
            prescribed=[PrescribedDisplacement(ft.find(tbm.SUPPORT_TAG), (0.0, 0.0)),
                        PathDisplacement(ft.find(tbm.LOAD_TAG), (None, None), path=path)],
        )
