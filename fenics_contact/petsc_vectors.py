"""Small helpers that assemble forms into owned numpy arrays."""

from __future__ import annotations

import numpy as np
from dolfinx import fem, la


def assemble_local(compiled: fem.Form) -> np.ndarray:
    """Assemble a linear form and return the owned entries, ghosts summed in."""
    vec = fem.assemble_vector(compiled)
    vec.scatter_reverse(la.InsertMode.add)
    im = vec.index_map
    return vec.array[: im.size_local * vec.block_size].copy()
