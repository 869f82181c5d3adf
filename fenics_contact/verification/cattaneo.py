"""Cattaneo-Mindlin partial slip of a cylinder on a rigid plane (interim check).

Cattaneo-Mindlin's closed form needs uncoupled normal and tangential
problems: two identical bodies, or Dundurs' beta = 0. For an elastic body on
a rigid plane beta = (1 - 2 nu) / (2 (1 - nu)) (plane strain), which vanishes
as nu -> 0.5. Two measured obstacles to simply taking nu -> 0.5: P1 (and P2)
triangles lock near incompressibility, and the nodal stick multipliers then
oscillate node to node (nu = 0.49: +-1.8 after pressing, where the answer
is about 0); and with beta > 0 pressing with friction locks in inward
tractions (Spence). :func:`solve_cattaneo` therefore presses frictionless
(mu = 0 until the end of pressing, which is what beta = 0 would give) and
switches mu on for the tangential phase; nu = 0.45 (beta = 0.091) keeps
the Q-induced change of pressure small without locking. The half-cylinder of
:class:`~fenics_contact.verification.hertz_problem.HertzCylinder` (small
strain, top face clamped) is pressed by moving the rigid plane up by
``push``, then loaded tangentially by moving it sideways by ``shift`` (Q <
mu P). Cattaneo-Mindlin (2D):

    c / a = sqrt(1 - Q / (mu P)),
    q(x) = mu p0 sqrt(1 - x^2/a^2)                          for c <= |x| <= a,
    q(x) = mu p0 [sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - x^2/c^2)]  for |x| < c.

The measured stick half-width is half the distance between the innermost
slipping nodes on either side and the outermost sticking ones (midpoints),
so it is known to about one contact facet.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

from fenics_contact.model.contact import ContactSettings
from fenics_contact.model.friction import SLIP, STICK, FrictionalContactProblem
from fenics_contact.model.materials import LinearElastic
from fenics_contact.model.obstacles import RigidPlane
from fenics_contact.model.problem import PrescribedDisplacement
from fenics_contact.scene.meshing import CONTACT_TAG, TOP_TAG, hertz_half_disk
from fenics_contact.solvers import make_strategy
from fenics_contact.solvers.diagnostics import SolverSettings
from fenics_contact.verification.hertz import fit_contact_profile


@dataclass(frozen=True)
class CattaneoCylinder:
    """A small-strain half-cylinder (R, E, nu) on a rigid plane with friction mu.

    Attributes:
        radius: R (length).
        E: Young's modulus (stress).
        nu: Poisson's ratio (close to 0.5 for beta ~ 0).
        mu: friction coefficient.
        push: upward plane displacement, reached at load factor ``press_until`` (length).
        shift: sideways plane displacement at load factor 1 (length).
        press_until: load factor at which pressing ends and the shift starts.
        h_contact: element size near contact (length).
        fine_radius: radius meshed at ``h_contact`` (length).
        contact_band: candidate facets have midpoints below contact_band * R.
        degree: displacement degree (2 avoids the volumetric locking of P1
            triangles at nu -> 0.5, which makes nodal tractions oscillate).
    """

    radius: float = 1.0
    E: float = 200.0
    nu: float = 0.45
    mu: float = 0.3
    push: float = 0.01
    shift: float = 0.002
    press_until: float = 0.5
    h_contact: float = 0.004
    fine_radius: float = 0.15
    contact_band: float = 0.02
    degree: int = 1

    @property
    def dundurs_beta(self) -> float:
        """Dundurs' beta of an elastic body on a rigid plane (plane strain)."""
        return (1.0 - 2.0 * self.nu) / (2.0 * (1.0 - self.nu))

    def build(
        self, settings: ContactSettings, comm: MPI.Comm = MPI.COMM_WORLD
    ) -> FrictionalContactProblem:
        """Mesh the half-disk and create the frictional problem (plane on a schedule)."""
        data = hertz_half_disk(
            comm, radius=self.radius, h_contact=self.h_contact, h_far=0.1,
            fine_radius=self.fine_radius, coarse_radius=0.5,
        )
        domain = data.mesh
        fdim = domain.topology.dim - 1
        arc = data.facet_tags.find(CONTACT_TAG)
        midpoints = mesh.compute_midpoints(domain, fdim, arc)
        band = arc[midpoints[:, 1] < self.contact_band * self.radius]
        top = data.facet_tags.find(TOP_TAG)
        plane = RigidPlane(domain, point=(0.0, 0.0), normal=(0.0, 1.0))
        schedule = [
            (0.0, 0.0, 0.0), (self.press_until, 0.0, self.push), (1.0, self.shift, self.push)
        ]
        return FrictionalContactProblem(
            domain, LinearElastic(E=self.E, nu=self.nu), plane, band, settings,
            prescribed=[PrescribedDisplacement(top, (0.0, 0.0))],
            obstacle_schedule=schedule, mu=self.mu, degree=self.degree,
        )


@dataclass(frozen=True)
class StickZone:
    """Measured and analytic stick zone at one tangential load.

    Attributes:
        P: normal force (force per thickness).
        Q: tangential force (force per thickness).
        a: fitted contact half-width (length).
        p0: fitted peak pressure (stress).
        c_measured: stick half-width from the nodes (length).
        c_analytic: a sqrt(1 - Q/(mu P)) (length).
        c_error: (c_measured - c_analytic) / c_analytic.
        c_resolution: half the node spacing at the stick edge over c_analytic.
        traction_error: relative L2 (nodal) error of |tau| against q(x).
        stick_nodes: nodes sticking; slip_nodes: nodes slipping.
    """

    P: float
    Q: float
    a: float
    p0: float
    c_measured: float
    c_analytic: float
    c_error: float
    c_resolution: float
    traction_error: float
    stick_nodes: int
    slip_nodes: int

    def to_dict(self) -> dict:
        """Plain data."""
        return asdict(self)


def analytic_traction(x: np.ndarray, a: float, c: float, p0: float, mu: float) -> np.ndarray:
    """Cattaneo-Mindlin tangential traction magnitude q(x) (stress)."""
    q = mu * p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))
    inner = np.abs(x) < c
    q[inner] -= mu * p0 * (c / a) * np.sqrt(1.0 - (x[inner] / c) ** 2)
    return q


def measure_stick_zone(problem: FrictionalContactProblem) -> StickZone:
    """Compare the converged state with Cattaneo-Mindlin (collective; every rank gets it)."""
    state = problem.contact_state()
    comm = problem.comm
    x = np.concatenate(comm.allgather(problem.nodal_coordinates()[:, 0]))
    p = np.concatenate(comm.allgather(state.pressure))
    tau = np.concatenate(comm.allgather(np.abs(state.tangential_traction[:, 0])))
    node = np.concatenate(comm.allgather(state.node_state))
    order = np.argsort(x)
    x, p, tau, node = x[order], p[order], tau[order], node[order]
    mu = problem.friction_coefficient
    P = state.contact_force
    Q = state.tangential_force
    fit = fit_contact_profile(x, p)
    c_analytic = fit.a * np.sqrt(max(1.0 - Q / (mu * P), 0.0))
    stick_x = x[node == STICK]
    slip_x = x[node == SLIP]
    if stick_x.size == 0:
        c_measured, spacing = 0.0, 0.0
    else:
        right_slip = slip_x[slip_x > stick_x.max()]
        left_slip = slip_x[slip_x < stick_x.min()]
        right = 0.5 * (stick_x.max() + right_slip.min()) if right_slip.size else stick_x.max()
        left = 0.5 * (stick_x.min() + left_slip.max()) if left_slip.size else stick_x.min()
        c_measured = 0.5 * (right - left)
        spacing = 0.5 * (right_slip.min() - stick_x.max()) if right_slip.size else 0.0
    q = analytic_traction(x, fit.a, c_analytic, fit.p0, mu)
    closed = p < 0
    error = float(np.linalg.norm(tau[closed] - q[closed]) / np.linalg.norm(q[closed]))
    return StickZone(
        P=P, Q=Q, a=fit.a, p0=fit.p0, c_measured=c_measured, c_analytic=c_analytic,
        c_error=(c_measured - c_analytic) / c_analytic if c_analytic > 0 else float("nan"),
        c_resolution=spacing / c_analytic if c_analytic > 0 else float("nan"),
        traction_error=error,
        stick_nodes=int(np.sum(node == STICK)), slip_nodes=int(np.sum(node == SLIP)),
    )


def solve_cattaneo(
    cylinder: CattaneoCylinder,
    settings: ContactSettings | None = None,
    *,
    press_steps: int = 4,
    shear_steps: int = 8,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[FrictionalContactProblem, list[StickZone], list[int]]:
    """Press frictionless, then shear with friction; measure the stick zone each shear step.

    GNRM at r = 0.01 E/h (nodal) unless ``settings`` say otherwise. Returns the
    problem, one :class:`StickZone` per shear step and the Newton iterations of
    every step. Raises RuntimeError when a step does not converge.
    """
    problem = cylinder.build(settings or ContactSettings(r=0.01), comm)
    strategy = make_strategy(
        "gnrm", problem, SolverSettings(atol=1e-10, rtol=1e-10, max_iterations=60),
        predictor="previous",
    )
    mu = problem.friction_coefficient
    zones: list[StickZone] = []
    iterations: list[int] = []
    problem.mu.value = 0.0
    loads = [cylinder.press_until * k / press_steps for k in range(1, press_steps + 1)]
    loads += [
        cylinder.press_until + (1.0 - cylinder.press_until) * k / shear_steps
        for k in range(1, shear_steps + 1)
    ]
    for k, t in enumerate(loads):
        if k == press_steps:
            problem.mu.value = mu
        problem.commit()
        problem.set_load(t)
        result = strategy.solve()
        if not result.converged:
            raise RuntimeError(f"Cattaneo-Mindlin step at load {t:g}: {result.status.value}.")
        iterations.append(result.iterations)
        if k >= press_steps:
            zones.append(measure_stick_zone(problem))
    return problem, zones, iterations
