"""Wall-clock accounts of the Newton kernel: compilation, assembly, linear solves.

Whatever a driver spends outside these accounts (diagnostics, Python
bookkeeping, I/O) is its overhead: total wall time minus the accounted sum.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, fields


@dataclass
class KernelTimings:
    """Seconds spent in each phase, and counts, accumulated over the kernel's life.

    Attributes:
        compile_s: form compilation (FFCx JIT or its cache) and PETSc object creation.
        residual_s: residual assembly, lifting and boundary conditions.
        jacobian_s: Jacobian assembly.
        setup_s: linear solver set-up (LU factorisation, or preconditioner set-up).
        solve_s: linear solves proper (triangular solves or Krylov iterations).
        residuals: residual assemblies.
        jacobians: Jacobian assemblies.
        linear_solves: linear systems solved.
        krylov_iterations: Krylov iterations over all solves (0 with a direct solver).
        search_s: two-body closest-point search and filling the target coefficients.
        transfer_s: two-body condensation: selection matrix, P^T R and P^T J P.
    """

    compile_s: float = 0.0
    residual_s: float = 0.0
    jacobian_s: float = 0.0
    setup_s: float = 0.0
    solve_s: float = 0.0
    residuals: int = 0
    jacobians: int = 0
    linear_solves: int = 0
    krylov_iterations: int = 0
    search_s: float = 0.0
    transfer_s: float = 0.0

    @property
    def assembly_s(self) -> float:
        """Residual plus Jacobian assembly (seconds)."""
        return self.residual_s + self.jacobian_s

    @property
    def linear_s(self) -> float:
        """Linear solver set-up plus solves (seconds)."""
        return self.setup_s + self.solve_s

    def snapshot(self) -> KernelTimings:
        """A copy of the current values."""
        return KernelTimings(**asdict(self))

    def since(self, earlier: KernelTimings) -> KernelTimings:
        """The difference ``self - earlier``, field by field."""
        return KernelTimings(
            **{f.name: getattr(self, f.name) - getattr(earlier, f.name) for f in fields(self)}
        )

    def to_dict(self) -> dict[str, float]:
        """Plain-data view with the derived sums."""
        out: dict[str, float] = asdict(self)
        out["assembly_s"] = self.assembly_s
        out["linear_s"] = self.linear_s
        return out


@contextmanager
def stopwatch(timings: KernelTimings, account: str) -> Iterator[None]:
    """Add the wall time of the ``with`` body to ``timings.<account>`` (seconds)."""
    start = time.perf_counter()
    try:
        yield
    finally:
        setattr(timings, account, getattr(timings, account) + time.perf_counter() - start)
