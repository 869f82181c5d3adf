"""The condensed Newton tangent of a contact problem against central differences."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from dolfinx.fem import petsc as fem_petsc

from fenics_contact.solvers.condensed import kernel_for


def condensed_tangent_errors(problem, rng: np.random.Generator,
                             steps: Sequence[float] = (1e-5, 1e-6)) -> list[float]:
    """|J du - FD du| / |FD du| of the augmented system at the current state, per step.

    du is random on every free unknown (zero on Dirichlet rows); the state is put back.
    """
    kernel = kernel_for(problem.augmented_system())
    kernel._pull()
    x0 = kernel.x.copy()
    du = x0.duplicate()
    values = rng.standard_normal(x0.getLocalSize())
    values[kernel._bc_local] = 0.0
    du.setArray(values)

    def residual(x) -> np.ndarray:
        fem_petsc.assign(x, kernel.unknowns)
        for f in kernel.unknowns:
            f.x.scatter_forward()
        kernel._assemble_b()
        return kernel.b.getArray().copy()

    residual(x0)
    kernel._assemble_A()
    jdu = x0.duplicate()
    kernel.A.mult(du, jdu)
    errors = []
    for eps in steps:
        plus, minus = x0.copy(), x0.copy()
        plus.axpy(eps, du)
        minus.axpy(-eps, du)
        fd = (residual(plus) - residual(minus)) / (2 * eps)
        errors.append(float(np.linalg.norm(fd - jdu.getArray()) / np.linalg.norm(fd)))
    residual(x0)
    return errors
