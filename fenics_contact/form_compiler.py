"""Form compilation: a linear-time node lookup in FFCx's value numbering.

FFCx 0.11 (``ffcx.ir.analysis.valuenumbering.ValueNumberer``) finds the
symbols of an operand by scanning every node of the integrand's graph and
comparing expressions, once per ``Indexed`` and ``ComponentTensor`` node:
quadratic in the size of the integrand. The mortar and friction kernels are
large (thousands of such nodes), and the scan took half of their
compilation: 247 of 485 s for the 2D mortar friction forms of
``scenes/ironing_friction.toml`` on an empty cache (profiled). The lookup
below builds a dictionary of the graph's expressions once per numbering
and returns the same node (the first one equal to the operand: UFL
expressions hash consistently with equality), so the generated C is the
same, byte for byte, and so are the cache entries.

:func:`install` is idempotent and leaves FFCx alone when its value
numbering does not have the expected shape (a later FFCx).
"""

from __future__ import annotations

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


_original: dict[str, Any] = {}


def install() -> bool:
    """Replace the quadratic scan by the dictionary lookup; True when installed."""
    numberer = _numberer()
    if numberer is None:
        return False
    if numberer.get_node_symbols is not _node_symbols:
        _original.setdefault("get_node_symbols", numberer.get_node_symbols)
        numberer.get_node_symbols = _node_symbols
    return True


def uninstall() -> None:
    """Give FFCx its own lookup back (to measure what :func:`install` buys)."""
    numberer = _numberer()
    if numberer is not None and "get_node_symbols" in _original:
        numberer.get_node_symbols = _original.pop("get_node_symbols")
