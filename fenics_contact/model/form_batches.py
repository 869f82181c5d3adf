"""Compile the blocks of a block form together, in one or a few C modules at once.

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

A batch large enough to keep a C compiler busy for seconds (the contact
kernels of mortar and frictional pairs) is split into :data:`GROUPS`
modules of about equal estimated cost (:func:`compile_size`), and the
modules missing from the cache are compiled at the same time, each by a
child process forked for it (FFCx, then the C compiler), as many at once as
the process has cores (:func:`compile_jobs`; the environment variable
``FENICS_CONTACT_COMPILE_JOBS`` sets another number, 1 compiles in this
process only). The children write only the form cache, which this process
then reads; a child that fails leaves its module to this process. The
modules are the same whatever the cores, so a run under MPI (which compiles
on rank 0 without forking) finds a serial run's modules. On a warm cache
nothing is forked. :func:`compile_in_background` starts such children
early, while the process goes on building the problem.
"""

from __future__ import annotations

import multiprocessing
import multiprocessing.connection
import os
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
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


#: Modules a large batch is split into. Fixed, so that the cache entries do not
#: depend on the machine's cores (a run on 2 processes finds a serial run's modules).
GROUPS = 4
#: Most processes compiling at once (see :func:`compile_jobs`).
MAX_JOBS = 4
#: Estimated size (:func:`compile_size`) of a batch below which it stays one module,
#: where more modules' fixed costs would eat the gain: the twelve Jacobian and residual
#: blocks of the 2D mortar kernel estimate 400 000 (37 s to compile in one process),
#: a batch of four other forms of the same scene 5 600 (1.1 s).
SPLIT_ABOVE = 50_000


def compile_jobs() -> int:
    """Processes that compile at once: the cores this process may use, at most 4.

    ``FENICS_CONTACT_COMPILE_JOBS`` (a positive integer) overrides it; 1 compiles
    every module in this process, one after the other.
    """
    text = os.environ.get("FENICS_CONTACT_COMPILE_JOBS", "").strip()
    if text:
        try:
            jobs = int(text)
        except ValueError:
            jobs = 0
        if jobs < 1:
            raise ValueError(f"FENICS_CONTACT_COMPILE_JOBS = {text!r}: give a positive "
                             "integer (1 compiles in this process only).")
        return jobs
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return max(1, min(MAX_JOBS, cores))


def compile_size(form: ufl.Form) -> int:
    """A cheap estimate of a form's compilation cost (its C code grows with it).

    The distinct UFL nodes of its integrands (derivatives not expanded) times
    the summed element dimensions of its arguments: on the 2D mortar kernel it
    orders the twelve blocks as their C sizes (56 kB to 1.3 MB) but for near ties.
    """
    from ufl.corealg.traversal import unique_pre_traversal

    nodes = sum(sum(1 for _ in unique_pre_traversal(i.integrand())) for i in form.integrals())
    dims = sum(a.ufl_function_space().ufl_element().dim for a in form.arguments())
    return nodes * max(1, dims)


def split_batch(forms: Sequence[ufl.Form]) -> list[list[int]]:
    """Indices of ``forms`` in up to :data:`GROUPS` groups of about equal estimated cost.

    One group for a small batch (:data:`SPLIT_ABOVE`). Largest first into the
    lightest group; the grouping depends only on the forms, so every run and
    every process finds the same modules. Groups come largest first.
    """
    if len(forms) < 2:
        return [list(range(len(forms)))]
    sizes = [compile_size(f) for f in forms]
    if sum(sizes) < SPLIT_ABOVE:
        return [list(range(len(forms)))]
    groups: list[list[int]] = [[] for _ in range(min(GROUPS, len(forms)))]
    loads = [0] * len(groups)
    for i in sorted(range(len(forms)), key=lambda i: -sizes[i]):
        g = loads.index(min(loads))
        groups[g].append(i)
        loads[g] += sizes[i]
    order = sorted(range(len(groups)), key=lambda g: -loads[g])
    return [sorted(groups[g]) for g in order if groups[g]]


def _module_c_file(forms: list[ufl.Form], options: dict, jit: dict) -> Path | None:
    """The C file of the cache entry FFCx makes for ``forms`` (None: unknown FFCx)."""
    jit_module = ffcx.codegeneration.jit
    option_sig = getattr(jit_module, "_compute_option_signature", None)
    compile_sig = getattr(jit_module, "_compilation_signature", None)
    if option_sig is None or compile_sig is None or jit.get("cache_dir") is None:
        return None
    p = ffcx.options.get_options(options)
    name = "libffcx_forms_" + ffcx.naming.compute_signature(
        forms, option_sig(p) + compile_sig(jit.get("cffi_extra_compile_args", []),
                                           jit.get("cffi_debug", False)))
    return Path(jit["cache_dir"]) / f"{name}.c"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def _owner_file(c_file: Path) -> Path:
    return c_file.with_suffix(".c.owner")


def clear_stale_lock(c_file: Path | None) -> bool:
    """Remove the cache's lock on a module whose compiling process is gone.

    FFCx marks a module being compiled by its (at first empty) C file and
    waits for the ``.c.cached`` file that ends the compilation; a process
    killed meanwhile (Ctrl-C during a first run, a killed job) leaves the C
    file behind, and every later run waited for it until its timeout and
    failed. The package writes the compiling process's id beside the C file
    (``.c.owner``); a lock whose owner no longer runs is removed. Returns
    True when one was.
    """
    if c_file is None or not c_file.exists() or c_file.with_suffix(".c.cached").exists():
        return False
    owner = _owner_file(c_file)
    try:
        pid = int(owner.read_text().strip())
    except (OSError, ValueError):
        return False  # not ours (or not written yet): leave it to FFCx's wait
    if _alive(pid):
        return False
    c_file.unlink(missing_ok=True)
    owner.unlink(missing_ok=True)
    return True


def _claim(c_file: Path | None) -> None:
    """Before compiling: clear a stale lock, then name this process as the owner."""
    if c_file is None:
        return
    clear_stale_lock(c_file)
    if not c_file.exists():
        try:
            _owner_file(c_file).parent.mkdir(parents=True, exist_ok=True)
            _owner_file(c_file).write_text(str(os.getpid()))
        except OSError:
            pass


def _release(c_file: Path | None) -> None:
    if c_file is not None and c_file.with_suffix(".c.cached").exists():
        _owner_file(c_file).unlink(missing_ok=True)


def _compile_module(forms: list[ufl.Form], options: dict, jit: dict) -> tuple:
    """FFCx's compile_forms, with the module's lock owned (see :func:`clear_stale_lock`)."""
    c_file = _module_c_file(forms, options, jit)
    _claim(c_file)
    out = ffcx.codegeneration.jit.compile_forms(forms, options=options, **jit)
    _release(c_file)
    return out


def _compile_in_child(forms: list[ufl.Form], options: dict, jit: dict) -> None:
    """Body of a forked child: fill the cache entry of ``forms``, nothing else."""
    _compile_module(forms, options, jit)


def _can_fork() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


class BackgroundCompilation:
    """Child processes filling the form cache, at most ``jobs`` at a time.

    Each (forms, ffcx options, jit options) of ``modules`` is compiled as one
    module (FFCx's ``compile_forms``) in a child forked for it, unless it is
    in the cache already (or being compiled). :meth:`wait` returns when all
    are done; nothing is read back: the caller compiles the same forms,
    which then come from the cache. A failed child's unfinished entry is
    removed, so that the caller compiles it itself (and reports the error).
    """

    def __init__(self, modules: Sequence[tuple[list[ufl.Form], dict, dict]],
                 jobs: int | None = None) -> None:
        self._queue: list[tuple[list[ufl.Form], dict, dict, Path]] = []
        for forms, options, jit in modules:
            c_file = _module_c_file(forms, options, jit)
            clear_stale_lock(c_file)
            if c_file is not None and not c_file.exists():
                self._queue.append((forms, options, jit, c_file))
        self._jobs = max(1, jobs or compile_jobs())
        self._running: list[tuple[Any, Path]] = []
        self._fill()

    def __len__(self) -> int:
        """Modules not finished yet."""
        return len(self._queue) + len(self._running)

    def _fill(self) -> None:
        context = multiprocessing.get_context("fork")
        while self._queue and len(self._running) < self._jobs:
            forms, options, jit, c_file = self._queue.pop(0)
            child = context.Process(target=_compile_in_child, args=(forms, options, jit),
                                    daemon=True)
            with warnings.catch_warnings():  # Python 3.12 warns of BLAS/MPI threads at a fork
                warnings.simplefilter("ignore", DeprecationWarning)
                child.start()
            self._running.append((child, c_file))

    def wait(self) -> None:
        """Run the queue to its end, ``jobs`` children at a time."""
        while self._running:
            multiprocessing.connection.wait([child.sentinel for child, _ in self._running])
            still = []
            for child, c_file in self._running:
                if child.is_alive():
                    still.append((child, c_file))
                    continue
                child.join()
                if child.exitcode != 0 and not c_file.with_suffix(".c.cached").exists():
                    c_file.unlink(missing_ok=True)  # left to the caller
                    _owner_file(c_file).unlink(missing_ok=True)
            self._running = still
            self._fill()


def compile_in_background(requests: Sequence[tuple[list[ufl.Form], dict | None]],
                          comm) -> BackgroundCompilation | None:
    """Start compiling each (forms, jit_options) of ``requests`` as its own module, all at once.

    Returns the handle to :meth:`~BackgroundCompilation.wait` on before the forms
    are compiled by ``dolfinx.fem.form`` (they then come from the cache), or
    None where nothing is started (MPI, one job, no fork).
    """
    if comm.size > 1 or compile_jobs() < 2 or not _can_fork():
        return None
    options = ffcx.get_options({"scalar_type": default_scalar_type})
    modules = []
    for forms, jit_options in requests:
        jit = dolfinx.jit.get_options(jit_options)
        jit["timeout"] = max(int(jit.get("timeout", 10)), WAIT_S)
        modules.append((list(forms), options, jit))
    # all at once: this process goes on meanwhile and nothing would start the queued ones
    return BackgroundCompilation(modules, jobs=len(modules))


def _compile_groups(forms: list[ufl.Form], options: dict, jit: dict, parallel: bool) -> list:
    """FFCx's compile_forms on ``forms``, in the modules :func:`split_batch` gives.

    Returns, per form, (compiled form, module, code). With ``parallel`` the
    modules missing from the cache are first compiled by forked children,
    :func:`compile_jobs` at a time.
    """
    groups = split_batch(forms)
    if parallel and len(groups) > 1 and compile_jobs() > 1 and _can_fork():
        BackgroundCompilation([([forms[i] for i in g], options, jit) for g in groups]).wait()
    out: list = [None] * len(forms)
    for group in groups:
        compiled, module, code = _compile_module([forms[i] for i in group], options, jit)
        for i, c in zip(group, compiled, strict=True):
            out[i] = (c, module, code)
    return out


def _compile(comm, forms: list[ufl.Form], options: dict, jit_options: dict) -> list:
    """The batch's modules on rank 0 first, then on the others (from the cache).

    Returns, per form, (compiled form, module, code).
    """
    def compile_all(parallel: bool):
        return _compile_groups(forms, options, jit_options, parallel)

    if comm.size == 1:
        return compile_all(True)
    failed = 0
    out = None
    if comm.rank == 0:
        try:
            out = compile_all(False)
        except Exception:  # reported by every rank below
            failed = 1
    if comm.bcast(failed, root=0):
        raise RuntimeError("Compiling a block form failed on rank 0.")
    if comm.rank != 0:
        out = compile_all(False)
    return out


def form_together(forms: Any, *, entity_maps=None, jit_options: dict | None = None) -> Any:
    """``dolfinx.fem.form(forms, ...)`` with every UFL form of ``forms`` in one module.

    ``forms``: a UFL form or a (nested) list of them and ``None``s, as
    ``fem.form`` takes them. One form or none: plain ``fem.form``.
    """
    flat = list(_flat(forms))
    if len(flat) < 2:
        c_file = None
        if flat and flat[0].ufl_domain().ufl_cargo().comm.rank == 0:
            c_file = _module_c_file(flat, ffcx.get_options({"scalar_type": default_scalar_type}),
                                    dolfinx.jit.get_options(jit_options))
            _claim(c_file)
        compiled = fem.form(forms, entity_maps=entity_maps, jit_options=jit_options)
        _release(c_file)
        return compiled
    comm = flat[0].ufl_domain().ufl_cargo().comm
    options = ffcx.get_options({"scalar_type": default_scalar_type})
    jit = dolfinx.jit.get_options(jit_options)
    # another process compiling the same module is waited for (a batch compiles for longer
    # than one form: DOLFINx's default wait of 10 s would fail a second run started meanwhile)
    jit["timeout"] = max(int(jit.get("timeout", 10)), WAIT_S)
    ready = {id(f): hit for f, hit in zip(flat, _compile(comm, flat, options, jit), strict=True)}
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
