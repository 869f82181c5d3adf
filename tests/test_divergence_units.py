"""The divergence test compares forces: the same problem diverges or not in any units.

A displacement-driven step starts from a residual whose Dirichlet rows hold
x - x_D (a length); after one Newton step it is an out-of-balance force that
scales with E. Compared unweighted, steel in Pa grew 0.017 -> 2e6 in one step
of a linear problem and was "diverged" at every cut-back.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact import load_scene, run_scene
from fenics_contact.solvers.diagnostics import ConvergenceMonitor, SolverSettings, Status

SCENES = Path(__file__).parents[1] / "scenes"
MESHES = SCENES.parent / "meshes"


def _scene(tmp_path: Path, name: str, edits: dict[str, str]) -> Path:
    """A copy of a shipped scene with text replaced (its mesh path made absolute)."""
    text = (SCENES / name).read_text().replace('"../meshes/', f'"{MESHES}/')
    for old, new in edits.items():
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / name
    path.write_text(text)
    return path


def _run(tmp_path: Path, scene: Path, out: str):
    return run_scene(load_scene(scene), tmp_path / out, comm=MPI.COMM_SELF,
                     pictures=False).path


def test_a_length_first_residual_weighted_as_force_is_not_divergence():
    """0.017 of Dirichlet mismatch at E = 2.1e11 is a force of 3.6e9: 2e6 is no growth."""
    settings = SolverSettings(atol=1e-2)
    assert ConvergenceMonitor(settings).check(0.017) is None
    plain = ConvergenceMonitor(settings)
    plain.check(0.017)
    assert plain.check(2e6) == Status.DIVERGED  # a length against a force
    weighted = ConvergenceMonitor(settings, force=lambda norm: 2.1e11 * norm if norm < 1 else norm)
    weighted.check(0.017)
    assert weighted.check(2e6) is None
    assert weighted.forces == pytest.approx([0.017 * 2.1e11, 2e6])
    assert weighted.check(4e15) == Status.DIVERGED  # growth of forces still is


#: E = 200's default atol (1e-8) in Pa: the same stopping test for steel.
STEEL_ATOL = 1e-8 * 2.1e11 / 200.0


@pytest.mark.parametrize("method, r, atol", [
    ("gnrm", None, None),  # atol left to the scene default
    ("penalty", 1e4, STEEL_ATOL),  # the default lies below the round-off of r = 1e4 E/h
])
def test_the_same_displacement_driven_problem_takes_the_same_steps_in_si_units(
    tmp_path, method, r, atol
):
    """A node-to-segment patch test at E = 200 and in Pa (steel): the same Newton steps.

    The first Newton step of the steel problem goes from a Dirichlet mismatch of
    0.015 to forces of 2e6 (GNRM) or 2.7e8 (penalty at r = 1e4 E/h): "diverged"
    at every cut-back when the two were compared as numbers.
    """
    name = "block_on_block_node_to_segment.toml"
    edits = {'method = "gnrm"': f'method = "{method}"'}
    if r is not None:
        edits['target = "target_face"'] = f'target = "target_face"\nr = {r!r}'
    base = _run(tmp_path, _scene(tmp_path, name, edits), "E200")
    edits["E = 200.0"] = "E = 2.1e11"
    if atol is not None:
        edits["steps = 2"] = f"steps = 2\natol = {atol!r}"
    steel = _run(tmp_path, _scene(tmp_path, name, edits), "steel")
    for path in (base, steel):
        assert path.status == "converged", path.steps[-1].message
        assert path.cutbacks == 0
    assert [s.iterations for s in steel.steps] == [s.iterations for s in base.steps]
    assert steel.contact_force == pytest.approx(2.1e11 / 200.0 * base.contact_force, rel=1e-6)
