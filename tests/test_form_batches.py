"""The blocks of a block form compiled together: one module, the same matrices.

Measured (2026-11-27, empty form cache, time to the first Newton iteration):
the frictional node-to-segment hemispheres 30.6 -> 27.6 s, the frictionless
ones 9.4 -> 7.1 s, the Hertz cylinder 2.3 -> 1.8 s (docs/benchmarks.md).
"""

from __future__ import annotations

import os

import numpy as np
import pytest
import ufl
from dolfinx import default_scalar_type, fem, mesh
from dolfinx.fem import petsc as fem_petsc

from mpi4py import MPI

import fenics_contact  # noqa: F401  (before petsc4py)
from fenics_contact.model.form_batches import form_together


def _blocks():
    domain = mesh.create_unit_square(MPI.COMM_WORLD, 6, 5)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    Q = fem.functionspace(domain, ("Lagrange", 1))
    u, p = fem.Function(V), fem.Function(Q)
    u.interpolate(lambda x: np.vstack([0.1 * x[0] * x[1], 0.05 * x[0] ** 2]))
    p.interpolate(lambda x: 1.0 + x[0])
    v, q = ufl.TestFunction(V), ufl.TestFunction(Q)
    F = ufl.Identity(2) + ufl.grad(u)
    residuals = [ufl.inner(p * F, ufl.grad(v)) * ufl.dx + ufl.det(F) * v[0] * ufl.ds,
                 (ufl.det(F) - p ** 2) * q * ufl.dx]
    return residuals, fem.forms.derivative_block(residuals, [u, p])


@pytest.mark.mpi
def test_blocks_compiled_together_assemble_the_same_matrix_from_one_module():
    residuals, jacobian = _blocks()
    F_sep, J_sep = fem.form(residuals), fem.form(jacobian)
    F_one, J_one = form_together([residuals, jacobian])
    modules = {id(f.module) for f in [*F_one, *(b for row in J_one for b in row)]}
    assert len(modules) == 1
    A_sep = fem_petsc.assemble_matrix(J_sep, kind="mpi")
    A_one = fem_petsc.assemble_matrix(J_one, kind="mpi")
    A_sep.assemble()
    A_one.assemble()
    A_one.axpy(-1.0, A_sep)
    assert A_one.norm() <= 1e-14 * A_sep.norm()
    b_sep = fem_petsc.assemble_vector(F_sep, kind="mpi")
    b_one = fem_petsc.assemble_vector(F_one, kind="mpi")
    b_one.axpy(-1.0, b_sep)
    assert b_one.norm() <= 1e-14 * b_sep.norm()


def test_a_single_form_is_compiled_as_usual():
    residuals, _ = _blocks()
    compiled = form_together(residuals[0])
    assert isinstance(compiled, fem.Form)


def _count_compilations(monkeypatch) -> list:
    """Patch FFCx's code generation in this process to record each module it makes."""
    import ffcx.compiler

    made: list = []
    original = ffcx.compiler.compile_ufl_objects

    def counting(objects, *args, **kwargs):
        made.append(len(objects))
        return original(objects, *args, **kwargs)

    monkeypatch.setattr(ffcx.compiler, "compile_ufl_objects", counting)
    return made


def _assembled(J) -> np.ndarray:
    A = fem_petsc.assemble_matrix(J, kind="mpi")
    A.assemble()
    return A.convert("dense").getDenseArray()


def test_a_large_batch_is_split_and_compiled_by_child_processes(tmp_path, monkeypatch):
    """Forked children fill the cache; this process reads the modules and assembles the same."""
    from fenics_contact.model import form_batches

    residuals, jacobian = _blocks()
    reference = _assembled(fem.form(jacobian))
    monkeypatch.setattr(form_batches, "SPLIT_ABOVE", 0)  # split this small batch
    monkeypatch.setenv("FENICS_CONTACT_COMPILE_JOBS", "2")
    flat = [*residuals, *(b for row in jacobian for b in row)]
    groups = form_batches.split_batch(flat)
    assert sorted(i for g in groups for i in g) == list(range(len(flat)))
    assert len(groups) == min(form_batches.GROUPS, len(flat))
    assert form_batches.split_batch(flat) == groups  # the same modules every time
    made = _count_compilations(monkeypatch)  # after the fork, only this process counts
    F, J = form_together([residuals, jacobian], jit_options={"cache_dir": str(tmp_path)})
    assert made == []  # every module came from a child, through the cache
    assert len(list(tmp_path.glob("*.c.cached"))) == len(groups)
    modules = {id(f.module) for f in [*F, *(b for row in J for b in row)]}
    assert len(modules) == len(groups)
    assert np.allclose(_assembled(J), reference, rtol=1e-14, atol=1e-14)


def test_a_failed_child_leaves_its_module_to_this_process(tmp_path, monkeypatch):
    from fenics_contact.model import form_batches

    def failing(*args):
        raise RuntimeError("no compiler")

    residuals, jacobian = _blocks()
    monkeypatch.setattr(form_batches, "SPLIT_ABOVE", 0)
    monkeypatch.setenv("FENICS_CONTACT_COMPILE_JOBS", "2")
    monkeypatch.setattr(form_batches, "_compile_in_child", failing)
    made = _count_compilations(monkeypatch)
    _, J = form_together([residuals, jacobian], jit_options={"cache_dir": str(tmp_path)})
    assert len(made) == min(form_batches.GROUPS, 6)  # each module compiled here
    assert np.allclose(_assembled(J), _assembled(fem.form(jacobian)), rtol=1e-14, atol=1e-14)


def test_compile_jobs_from_the_environment(monkeypatch):
    from fenics_contact.model.form_batches import MAX_JOBS, compile_jobs

    monkeypatch.delenv("FENICS_CONTACT_COMPILE_JOBS", raising=False)
    assert compile_jobs() == min(MAX_JOBS, len(os.sched_getaffinity(0)))
    monkeypatch.setenv("FENICS_CONTACT_COMPILE_JOBS", "3")
    assert compile_jobs() == 3
    for bad in ("0", "two"):
        monkeypatch.setenv("FENICS_CONTACT_COMPILE_JOBS", bad)
        with pytest.raises(ValueError, match=r"FENICS_CONTACT_COMPILE_JOBS.*positive integer"):
            compile_jobs()


def _dead_pid() -> int:
    import subprocess
    import sys

    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


@pytest.mark.parametrize("single", [False, True])
def test_a_lock_left_by_a_killed_compilation_is_cleared(tmp_path, monkeypatch, single):
    """A run killed while compiling (Ctrl-C in a first start) left the module's empty C
    file, and the next run waited for it until its timeout, then failed. A lock whose
    owner no longer runs is removed and the module compiled; a live owner's is kept."""
    import dolfinx.jit
    import ffcx

    from fenics_contact.model import form_batches

    monkeypatch.setattr(form_batches, "WAIT_S", 3)
    monkeypatch.setenv("FENICS_CONTACT_COMPILE_JOBS", "1")
    residuals, jacobian = _blocks()
    forms = [residuals[0]] if single else [*residuals, *(b for row in jacobian for b in row)]
    jit = {"cache_dir": str(tmp_path), "timeout": 3}
    c_file = form_batches._module_c_file(
        forms, ffcx.get_options({"scalar_type": default_scalar_type}),
        dolfinx.jit.get_options(jit))
    c_file.parent.mkdir(parents=True, exist_ok=True)
    c_file.write_text("")
    owner = c_file.with_suffix(".c.owner")
    owner.write_text(str(os.getpid()))  # alive: kept
    assert not form_batches.clear_stale_lock(c_file) and c_file.exists()
    owner.write_text(str(_dead_pid()))
    compiled = form_together(forms[0] if single else [residuals, jacobian], jit_options=jit)
    assert c_file.with_suffix(".c.cached").exists() and not owner.exists()
    if single:
        assert isinstance(compiled, fem.Form)
