"""The condensed kernel keeps exactly the derivative blocks that do not vanish."""

from pathlib import Path

import pytest
import ufl
from dolfinx import fem

from fenics_contact import load_scene
from fenics_contact.runner import scene_strategy
from fenics_contact.scene.build import build_problem
from fenics_contact.solvers import condensed

SCENES = Path(__file__).resolve().parents[1] / "scenes"


class _Built(Exception):
    pass


@pytest.mark.parametrize("scene", ["stack_3_blocks", "cattaneo_mindlin"])
def test_block_pattern_is_that_of_the_expanded_blocks(monkeypatch, scene):
    """Three node-to-segment pairs; a 2D mortar pair with friction (lam, lam_t, extras)."""
    seen = []

    def inspect(self, system, linear=None):
        ext = [*system.unknowns, *system.extras]
        blocks = fem.forms.derivative_block(list(system.residuals), ext)
        expanded = [[f is not None and not ufl.algorithms.expand_derivatives(f).empty()
                     for f in row] for row in blocks]
        kept = [[f is not None for f in row]
                for row in condensed._nonempty_blocks(list(system.residuals), ext)]
        seen.append((expanded, kept))
        raise _Built

    monkeypatch.setattr(condensed.CondensedKernel, "__init__", inspect)
    with pytest.raises(_Built):
        loaded = load_scene(SCENES / f"{scene}.toml")
        scene_strategy(loaded, build_problem(loaded))
    (expanded, kept), = seen
    assert kept == expanded
    n = len(kept)
    assert 0 < sum(map(sum, kept)) < n * n  # some blocks vanish, some do not
