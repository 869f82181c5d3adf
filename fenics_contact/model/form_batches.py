"""Compile the blocks of a block form together: one C module, one compiler run.

``dolfinx.fem.form`` compiles every block of a nested list of forms as its
own module (FFCx, then a C compiler and CFFI for each). A Newton kernel's
Jacobian has a block per pair of unknowns, and a two-body kernel's has a
block per pair of unknowns and target coefficients: the frictional
node-to-segment hemispheres compile about thirty, each paying the fixed cost
of a module (docs/benchmarks.md, "Time to the first Newton iteration").
:func:`form_together` compiles all of them in one FFCx call (one module, one
compiler run; cached on disk as one entry) and then lets DOLFINx build its
``Form`` objects from that module's compiled forms, so everything after the
compilation is DOLFINx's own code.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import dolfinx.jit
import ffcx
import ffcx.codegeneration.jit
import ufl
from dolfinx import default_scalar_type, fem

#: Seconds a process waits for another one that compiles the same module.
WAIT_S = 600


#: C flags of the contact kernels (MBs of straight-line C): -O1 compiles them in a
#: fraction of -O2's time and assembles as fast; -O0 assembles 2.3x slower. Tried:
#: gcc's cheaper register allocation (-fira-region=one -fira-algorithm=priority)
#: took 24.5 s of CPU against 29.3 s on the 4.4 MB 2D mortar kernel but 227 s
#: against 149 s on an 11.4 MB frictional one (docs/benchmarks.md).
CONTACT_CFLAGS = ["-O1", "-g0"]


def _flat(forms: Any) -> Iterator[ufl.Form]:
    if isinstance(forms, ufl.Form):
        yield forms
    elif isinstance(forms, list | tuple):
        for f in forms:
            yield from _flat(f)


def _compile(comm, forms: list[ufl.Form], options: dict, jit_options: dict) -> tuple:
    """FFCx's compile_forms on rank 0 first, then on the others (from the cache)."""
    def compile_all():
        return ffcx.codegeneration.jit.compile_forms(forms, options=options, **jit_options)

    if comm.size == 1:
        return compile_all()
    failed = 0
    out = None
    if comm.rank == 0:
        try:
            out = compile_all()
        except Exception:  # reported by every rank below
            failed = 1
    if comm.bcast(failed, root=0):
        raise RuntimeError("Compiling a block form failed on rank 0.")
    if comm.rank != 0:
        out = compile_all()
    return out


def form_together(forms: Any, *, entity_maps=None, jit_options: dict | None = None) -> Any:
    """``dolfinx.fem.form(forms, ...)`` with every UFL form of ``forms`` in one module.

    ``forms``: a UFL form or a (nested) list of them and ``None``s, as
    ``fem.form`` takes them. One form or none: plain ``fem.form``.
    """
    flat = list(_flat(forms))
    if len(flat) < 2:
        return fem.form(forms, entity_maps=entity_maps, jit_options=jit_options)
    comm = flat[0].ufl_domain().ufl_cargo().comm
    options = ffcx.get_options({"scalar_type": default_scalar_type})
    jit = dolfinx.jit.get_options(jit_options)
    # another process compiling the same module is waited for (a batch compiles for longer
    # than one form: DOLFINx's default wait of 10 s would fail a second run started meanwhile)
    jit["timeout"] = max(int(jit.get("timeout", 10)), WAIT_S)
    compiled, module, code = _compile(comm, flat, options, jit)
    ready = {id(f): (c, module, code) for f, c in zip(flat, compiled, strict=True)}
    original = dolfinx.jit.ffcx_jit

    def lookup(comm, ufl_object, form_compiler_options=None, jit_options=None):
        hit = ready.get(id(ufl_object))
        if hit is not None:
            return hit
        return original(comm, ufl_object, form_compiler_options=form_compiler_options,
                        jit_options=jit_options)

    dolfinx.jit.ffcx_jit = lookup
    try:
        return fem.form(forms, entity_maps=entity_maps, jit_options=jit_options)
    finally:
        dolfinx.jit.ffcx_jit = original
