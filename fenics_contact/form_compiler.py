"""Form compilation: three costs of FFCx 0.11 and UFL on Python 3.12 taken away.

Each shim leaves the generated C the same, byte for byte, and so the cache
entries; together they cut the first start of the large contact forms
(docs/benchmarks.md, "Time to the first Newton iteration").

1. **Node lookup in FFCx's value numbering.** FFCx
   (``ffcx.ir.analysis.valuenumbering.ValueNumberer``) finds the symbols of
   an operand by scanning every node of the integrand's graph and comparing
   expressions, once per ``Indexed`` and ``ComponentTensor`` node: quadratic
   in the size of the integrand. The mortar and friction kernels are large
   (thousands of such nodes), and the scan took half of their compilation:
   247 of 485 s for the 2D mortar friction forms of
   ``scenes/ironing_friction.toml`` on an empty cache (profiled). The lookup
   below builds a dictionary of the graph's expressions once per numbering
   and returns the same node (the first one equal to the operand: UFL
   expressions hash consistently with equality).
2. **One UFL cell per cell name.** basix's UFL element builds a new
   ``ufl.Cell`` each time its ``cell`` is asked for, and a cell builds all
   its sub-entity cells (about 40 for a tetrahedron); FFCx and UFL ask
   hundreds of thousands of times while compiling a large form. Cells are
   immutable values compared by name, so one per name serves.
3. **Dispatch without a new wrapper per call.** UFL's DAG traversers and
   FFCx's C formatter dispatch on the node type with
   ``functools.singledispatchmethod``, whose ``__get__`` builds a function
   and copies its metadata (``update_wrapper``) at every call on Python
   3.12. :class:`_Dispatch` binds the same registry's choice directly.

:func:`install` is idempotent and leaves a library alone where it does not
have the expected shape (a later version).
"""

from __future__ import annotations

import functools
import types
from typing import Any

_INDEX = "_fenics_contact_node_index"


def _node_symbols(self: Any, expr: Any) -> list[int]:
    """The symbols of the graph node whose expression equals ``expr`` (the first one)."""
    index = getattr(self, _INDEX, None)
    if index is None:
        index = {}
        for i, v in self.G.nodes.items():
            index.setdefault(v["expression"], i)
        setattr(self, _INDEX, index)
    return self.V_symbols[index[expr]]


def _numberer() -> Any:
    """FFCx's value numbering class, or None when it is not the expected one."""
    try:
        from ffcx.ir.analysis import valuenumbering
    except ImportError:
        return None
    numberer = getattr(valuenumbering, "ValueNumberer", None)
    if numberer is None or not hasattr(numberer, "get_node_symbols"):
        return None
    return numberer


class _Dispatch:
    """A ``singledispatchmethod`` whose bound form dispatches without building a wrapper.

    Access on an instance returns a bound method that chooses the registered
    implementation by the class of its first argument, as the original does;
    access on the class (``register``, ``super()`` chains) is the original's.
    """

    def __init__(self, original: functools.singledispatchmethod) -> None:
        self.original = original
        dispatch = original.dispatcher.dispatch

        def call(owner: Any, *args: Any, **kwargs: Any) -> Any:
            chosen = dispatch(args[0].__class__)
            if type(chosen) is types.FunctionType:
                return chosen(owner, *args, **kwargs)
            return chosen.__get__(owner, type(owner))(*args, **kwargs)

        self._call = call

    def __get__(self, owner: Any, cls: type | None = None) -> Any:
        if owner is None:
            return self.original.__get__(owner, cls)
        return types.MethodType(self._call, owner)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.original, name)


def _dispatching_classes() -> list[tuple[type, str]]:
    """UFL's DAG traversers (``process``) and FFCx's C formatter (``__call__``)."""
    found: list[tuple[type, str]] = []
    try:
        import ufl.algorithms.apply_coefficient_split
        import ufl.algorithms.apply_derivatives  # noqa: F401
        from ufl.corealg.dag_traverser import DAGTraverser
    except ImportError:
        DAGTraverser = None
    if DAGTraverser is not None:
        todo = [DAGTraverser]
        while todo:
            cls = todo.pop()
            todo.extend(cls.__subclasses__())
            found.append((cls, "process"))
    try:
        from ffcx.codegeneration.C.formatter import Formatter
    except ImportError:
        Formatter = None
    if Formatter is not None:
        found.append((Formatter, "__call__"))
    return found


@functools.cache
def _cell(name: str) -> Any:
    import ufl.cell
    return ufl.cell.Cell(name)


def _element_cell(self: Any) -> Any:
    """The UFL cell of a basix element, one per cell name."""
    return _cell(self._cellname)


def _element_base() -> Any:
    """Basix's UFL element base class, or None when ``cell`` is not the expected property."""
    try:
        import basix.ufl
    except ImportError:
        return None
    base = getattr(basix.ufl, "_ElementBase", None)
    if base is None or not isinstance(base.__dict__.get("cell"), property):
        return None
    return base


_original: dict[str, Any] = {}


def install() -> bool:
    """Install the three shims (where the libraries have the expected shape).

    Returns True when the node lookup (the largest of them) is installed.
    """
    for cls, name in _dispatching_classes():
        attr = cls.__dict__.get(name)
        if isinstance(attr, functools.singledispatchmethod):
            _original.setdefault(f"dispatch:{cls.__module__}.{cls.__qualname__}.{name}",
                                 (cls, name, attr))
            setattr(cls, name, _Dispatch(attr))
    base = _element_base()
    if base is not None and base.__dict__["cell"].fget is not _element_cell:
        _original.setdefault("cell", base.__dict__["cell"])
        base.cell = property(_element_cell, doc=base.__dict__["cell"].__doc__)
    numberer = _numberer()
    if numberer is None:
        return False
    if numberer.get_node_symbols is not _node_symbols:
        _original.setdefault("get_node_symbols", numberer.get_node_symbols)
        numberer.get_node_symbols = _node_symbols
    return True


def uninstall() -> None:
    """Give FFCx, UFL and basix their own code back (to measure what :func:`install` buys)."""
    numberer = _numberer()
    if numberer is not None and "get_node_symbols" in _original:
        numberer.get_node_symbols = _original.pop("get_node_symbols")
    base = _element_base()
    if base is not None and "cell" in _original:
        base.cell = _original.pop("cell")
    for key in [k for k in _original if k.startswith("dispatch:")]:
        cls, name, attr = _original.pop(key)
        setattr(cls, name, attr)
