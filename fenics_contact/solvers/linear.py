"""Linear solvers for the Newton kernel: direct (MUMPS) or Krylov with block preconditioning.

The contact Jacobian is a saddle-point matrix on (u, lam)::

    [ K   B^T ] [du  ]   [F_u  ]
    [ C   D   ] [dlam] = [F_lam]

with the elastic (plus contact) stiffness K, the gap gradient B, C = r B on
active nodes and D the (lumped, diagonal) multiplier block on inactive ones.
The iterative option is right-preconditioned GMRES with a Schur-complement
field split: algebraic multigrid (GAMG) with the rigid body modes as its
near-null space on the displacement block K, and the ``selfp`` Schur
approximation D - C diag(K)^-1 B^T, factorised exactly (it lives on the
contact surface only, so it is small). Systems with one block (penalty,
Uzawa) get GMRES with GAMG directly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from dolfinx import fem

from petsc4py import PETSc

LinearKind = Literal["direct", "iterative"]
Forcing = Literal["fixed", "eisenstat-walker"]
Reuse = Literal["no", "step", "path"]


@dataclass(frozen=True)
class LinearSolverSettings:
    """How the Newton kernel solves J dx = F.

    Attributes:
        kind: 'direct' (LU, the default, MUMPS) or 'iterative' (GMRES with
            a Schur field split and GAMG on the displacement block).
        factor: LU package of the direct solver, and of the Schur block.
        rtol: Krylov relative tolerance (unpreconditioned residual, right
            preconditioning). Tight by default so that Newton counts match
            the direct solver's.
        atol: Krylov absolute tolerance (force units, the residual's).
        max_it: Krylov iteration limit per linear solve.
        restart: GMRES restart length.
        schur_fact: PETSc Schur factorisation type ('full', 'upper', 'lower',
            'diag'); None: 'full' with the fixed forcing (two multigrid cycles
            per Krylov iteration; the recorded ladder figures), 'upper' with
            Eisenstat-Walker (one cycle: 20 % faster at 1e5 DOFs in 3D, 1 %
            more Krylov iterations; see :attr:`schur_factorisation`).
        amg_threshold: GAMG drop tolerance for the strength graph (-1: keep all).
        amg_smooth_its: GAMG smoothing sweeps per level.
        reuse_interpolation: keep the GAMG prolongators between Newton steps
            (only the Galerkin products are recomputed).
        null_pivots: let MUMPS set aside pivots that are zero to round-off
            (its threshold, 1e-5 eps ||A||) and solve the consistent singular
            system. For contacts that share nodes: a corner pressed on a floor
            and sticking to a wall is held twice in one direction, two
            constraint rows are equal and only their sum is determined. Off
            by default, so that a singular problem (a body nothing holds)
            fails as such.
        forcing: Krylov tolerance of each Newton step (iterative solver only).
            'fixed': ``rtol`` at every step. 'eisenstat-walker': an inexact
            Newton method, the forcing term eta_k of :class:`EisenstatWalker`
            (loose while the Newton residual falls slowly, tight where it
            converges fast, never tighter than ``rtol``).
        eta_max: largest forcing term (the first step of each solve uses it).
            0.01: looser terms (0.1, the textbook's) let inexact early steps
            choose a different contact set and cost Newton iterations (3D
            ladder at 3e4 DOFs: 11 instead of 8), for a few Krylov iterations.
        reuse_preconditioner: keep the multigrid hierarchy of the displacement
            block (its coarse operators and smoothers) from one Newton step
            to the next while the Krylov convergence rate holds (rebuilt when
            a step needed more than ``lag_factor`` times the iterations per
            decade of the step that built it: :class:`PreconditionerLag`).
            'no': rebuilt at every step (iterative solver's set-up as before);
            'step': kept within a nonlinear solve (load step), rebuilt at the
            start of each; 'path': kept from one load step to the next too.
            The Schur block is rebuilt at every step (the contact set changes
            it); so is everything when the kernel's matrix is replaced.
        lag_factor: Krylov iterations per decade of residual reduction, over
            those of the step that built the hierarchy, above which it is
            rebuilt.
    """

    kind: LinearKind = "direct"
    factor: str = "mumps"
    rtol: float = 1e-10
    atol: float = 1e-13
    max_it: int = 1000
    restart: int = 150
    schur_fact: str | None = None
    amg_threshold: float = 0.02
    amg_smooth_its: int = 2
    reuse_interpolation: bool = True
    null_pivots: bool = False
    forcing: Forcing = "fixed"
    eta_max: float = 0.01
    reuse_preconditioner: Reuse = "no"
    lag_factor: float = 1.5

    def __post_init__(self) -> None:
        if self.kind not in ("direct", "iterative"):
            raise ValueError(
                f"Linear solver kind {self.kind!r} is unknown; use 'direct' or 'iterative'."
            )
        if not (0 < self.rtol < 1 and self.atol >= 0):
            raise ValueError(f"Krylov tolerances need 0 < rtol < 1, atol >= 0 (got {self}).")
        if self.forcing not in ("fixed", "eisenstat-walker"):
            raise ValueError(
                f"Forcing {self.forcing!r} is unknown; use 'fixed' or 'eisenstat-walker'."
            )
        if self.reuse_preconditioner not in ("no", "step", "path"):
            raise ValueError(
                f"reuse_preconditioner {self.reuse_preconditioner!r} is unknown; "
                "use 'no', 'step' or 'path'."
            )
        if not (self.rtol <= self.eta_max < 1):
            raise ValueError(f"eta_max needs rtol <= eta_max < 1 (got {self.eta_max}).")
        if self.lag_factor < 1:
            raise ValueError(f"lag_factor needs to be >= 1 (got {self.lag_factor}).")

    @property
    def inexact(self) -> bool:
        """True when the Krylov tolerance follows the Eisenstat-Walker forcing term."""
        return self.kind == "iterative" and self.forcing == "eisenstat-walker"

    @property
    def schur_factorisation(self) -> str:
        """The Schur factorisation type used: ``schur_fact``, or the forcing's default."""
        if self.schur_fact is not None:
            return self.schur_fact
        return "upper" if self.forcing == "eisenstat-walker" else "full"

    @property
    def lagged(self) -> bool:
        """True when the multigrid hierarchy is kept between Newton steps."""
        return self.kind == "iterative" and self.reuse_preconditioner != "no"


class EisenstatWalker:
    """Forcing terms of an inexact Newton method (Eisenstat and Walker 1996, choice 2).

    Newton step k solves J dx = F_k to ``||J dx - F_k|| <= eta_k ||F_k||`` with

        eta_k = gamma (||F_k|| / ||F_(k-1)||)^alpha,  gamma = 0.9, alpha = 2,

    safeguarded against a sudden drop (eta_k >= gamma eta_(k-1)^alpha when
    that exceeds 0.1) and capped by ``eta_max``. The first step of a solve
    has no ratio to go by: it uses a tenth of the reduction the first step
    of the previous solve achieved, ``||F_1|| / ||F_0||`` (``eta_max`` at
    most, and at the first solve). A nearly linear problem, whose first
    Newton step alone reduces the residual by orders of magnitude, so
    starts tight instead of wasting that step on an inexact solve (which
    costs an extra Newton step per load step). Near convergence the term is
    not tighter than half the Newton tolerance over the residual (no
    oversolving: the linear residual of the last step is then below half
    the tolerance, so the next Newton residual reaches it), and never
    tighter than ``eta_min``.

    Args:
        eta_max: largest forcing term.
        eta_min: smallest forcing term (the fixed Krylov tolerance).
    """

    gamma = 0.9
    alpha = 2.0
    #: Level above which the previous term bounds the next (the choice 2 safeguard).
    safeguard = 0.1
    #: The first term of a solve over the first reduction of the previous solve.
    first_margin = 0.1

    def __init__(self, eta_max: float = 0.01, eta_min: float = 1e-10) -> None:
        self.eta_max = eta_max
        self.eta_min = eta_min
        self._first_ratio = np.inf
        self.reset()

    def reset(self) -> None:
        """A new nonlinear solve: the next term is the first of a solve."""
        self._steps = 0
        self._norm = np.inf
        self._eta = self.eta_max

    def first(self) -> float:
        """The first term of a solve (before any tolerance bound)."""
        eta = self.first_margin * self._first_ratio
        return float(max(min(eta, self.eta_max), self.eta_min))

    def __call__(self, norm: float, tolerance: float = 0.0) -> float:
        """The forcing term of a step at residual ``norm`` (Newton tolerance ``tolerance``)."""
        self._steps += 1
        if self._steps == 2 and np.isfinite(self._norm) and self._norm > 0.0:
            self._first_ratio = norm / self._norm
        if not np.isfinite(self._norm) or self._norm <= 0.0:
            eta = self.first()
        else:
            eta = self.gamma * (norm / self._norm) ** self.alpha
            bound = self.gamma * self._eta**self.alpha
            if bound > self.safeguard:
                eta = max(eta, bound)
        if tolerance > 0.0 and norm > 0.0:
            eta = max(eta, 0.5 * tolerance / norm)
        eta = float(max(min(eta, self.eta_max), self.eta_min))
        self._norm, self._eta = norm, eta
        return eta


class PreconditionerLag:
    """When to rebuild the multigrid hierarchy of an iterative solve.

    The measure of a preconditioner's quality is the Krylov iterations per
    decade of residual reduction (independent of the tolerance the step
    asked for). The hierarchy built at the first step of a solve is kept
    while a step needs at most ``factor`` times the iterations per decade
    of the step that built it.

    Args:
        factor: allowed growth of the iterations per decade.
    """

    def __init__(self, factor: float = 1.5) -> None:
        self.factor = factor
        #: Hierarchies built (over the object's life).
        self.builds = 0
        self.reset()

    def reset(self) -> None:
        """Rebuild at the next step."""
        self.rebuild = True
        self._reference = np.inf

    def record(self, iterations: int, reduction: float, built: bool) -> None:
        """Account a finished solve: its iterations and ``||r|| / ||r_0||``."""
        decades = -np.log10(reduction) if 0.0 < reduction < 1.0 else 0.0
        rate = iterations / max(decades, 0.5)
        if built:
            self._reference = max(rate, 1.0)
            self.builds += 1
        self.rebuild = rate > self.factor * self._reference


def rigid_body_modes(V: fem.FunctionSpace) -> PETSc.NullSpace:
    """Orthonormal rigid body modes of a vector P-k space (3 in 2D, 6 in 3D).

    Args:
        V: vector Lagrange space of the displacement (length units).

    Returns:
        A PETSc near-null space in the layout of V's owned degrees of freedom.
    """
    gdim = V.mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    if bs != gdim:
        raise ValueError(f"Rigid body modes need a {gdim}-vector space, got block size {bs}.")
    n_local = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n_local]
    n_modes = 3 if gdim == 2 else 6
    arrays = [np.zeros((n_local, bs)) for _ in range(n_modes)]
    for i in range(gdim):  # translations
        arrays[i][:, i] = 1.0
    if gdim == 2:
        arrays[2][:, 0], arrays[2][:, 1] = -x[:, 1], x[:, 0]
    else:
        arrays[3][:, 0], arrays[3][:, 1] = -x[:, 1], x[:, 0]
        arrays[4][:, 0], arrays[4][:, 2] = x[:, 2], -x[:, 0]
        arrays[5][:, 2], arrays[5][:, 1] = x[:, 1], -x[:, 2]
    vecs = []
    for a in arrays:
        v = PETSc.Vec().createMPI((n_local * bs, PETSc.DECIDE), comm=V.mesh.comm)
        v.setArray(a.ravel())
        vecs.append(v)
    # Gram-Schmidt: PETSc wants an orthonormal basis.
    basis: list[PETSc.Vec] = []
    for v in vecs:
        w = v.copy()
        for b in basis:
            w.axpy(-w.dot(b), b)
        w.normalize()
        basis.append(w)
    return PETSc.NullSpace().create(vectors=basis, comm=V.mesh.comm)


def block_index_sets(A: PETSc.Mat, spaces: list[fem.FunctionSpace]) -> list[PETSc.IS]:
    """Global row indices of each block of a blocked (kind='mpi') matrix on this rank.

    DOLFINx orders each rank's owned rows block after block, so block i
    occupies a contiguous stretch of the rank's ownership range.
    """
    start = A.getOwnershipRange()[0]
    sets = []
    for V in spaces:
        n = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
        sets.append(PETSc.IS().createStride(n, first=start, step=1, comm=A.getComm()))
        start += n
    return sets


def _set_options(prefix: str, options: dict[str, object]) -> None:
    """Put defaults into the options database; values already there are kept."""
    db = PETSc.Options()
    for key, value in options.items():
        name = f"{prefix}{key}"
        if not db.hasName(name):
            db[name] = str(value).lower() if isinstance(value, bool) else value


def _amg_options(settings: LinearSolverSettings) -> dict[str, object]:
    return {
        "ksp_type": "preonly",
        "pc_type": "gamg",
        "pc_gamg_type": "agg",
        "pc_gamg_threshold": settings.amg_threshold,
        "pc_gamg_reuse_interpolation": settings.reuse_interpolation,
        "mg_levels_ksp_type": "chebyshev",
        "mg_levels_pc_type": "jacobi",
        "mg_levels_ksp_max_it": settings.amg_smooth_its,
        "mg_levels_esteig_ksp_type": "cg",
    }


def configure_ksp(
    ksp: PETSc.KSP,
    A: PETSc.Mat,
    spaces: list[fem.FunctionSpace],
    settings: LinearSolverSettings,
) -> tuple:
    """Set up ``ksp`` (operator ``A``, options prefix already set) as ``settings`` asks.

    Options already in the PETSc options database under the KSP's prefix
    win over these defaults (``setFromOptions`` runs last).

    Returns:
        PETSc objects (index sets, near-null space) the caller must keep
        alive as long as the solver.
    """
    prefix = ksp.getOptionsPrefix() or ""
    pc = ksp.getPC()
    if settings.kind == "direct":
        ksp.setType("preonly")
        pc.setType("lu")
        pc.setFactorSolverType(settings.factor)
        if settings.null_pivots and settings.factor == "mumps":
            _set_options(prefix, {"mat_mumps_icntl_24": 1})
        ksp.setFromOptions()
        return ()
    ksp.setType("gmres")
    ksp.setPCSide(PETSc.PC.Side.RIGHT)
    ksp.setTolerances(rtol=settings.rtol, atol=settings.atol, max_it=settings.max_it)
    ksp.setGMRESRestart(settings.restart)
    near_null = rigid_body_modes(spaces[0])
    if len(spaces) == 1:
        A.setNearNullSpace(near_null)
        _set_options(prefix, {k: v for k, v in _amg_options(settings).items() if k != "ksp_type"})
        pc.setType("gamg")
        ksp.setFromOptions()
        return (near_null,)
    is_u = block_index_sets(A, spaces)[0]
    # every multiplier block (normal, and tangential with friction) in one split:
    # they follow the displacement rows contiguously on each rank
    first = A.getOwnershipRange()[0] + is_u.getLocalSize()
    is_lam = PETSc.IS().createStride(
        A.getOwnershipRange()[1] - first, first=first, step=1, comm=A.getComm()
    )
    # PCFIELDSPLIT hands a near-null space composed on a split's IS to its sub-matrix.
    is_u.compose("nearnullspace", near_null)
    pc.setType("fieldsplit")
    pc.setFieldSplitIS(("u", is_u), ("lam", is_lam))
    pc.setFieldSplitType(PETSc.PC.CompositeType.SCHUR)
    options: dict[str, object] = {
        "pc_fieldsplit_schur_fact_type": settings.schur_factorisation,
        "pc_fieldsplit_schur_precondition": "selfp",
        "fieldsplit_lam_ksp_type": "preonly",
        "fieldsplit_lam_pc_type": "lu",
        "fieldsplit_lam_pc_factor_mat_solver_type": settings.factor,
    }
    options.update({f"fieldsplit_u_{k}": v for k, v in _amg_options(settings).items()})
    _set_options(prefix, options)
    ksp.setFromOptions()
    return (is_u, is_lam, near_null)
