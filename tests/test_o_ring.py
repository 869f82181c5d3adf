"""An O-ring section squeezed to 30 % between two rigid plates (scenes/o_ring.toml, coarse).

Half model (symmetry plane x = 0, two [[obstacle]] plates), neo-Hookean,
nu = 0.49, plane strain. The force per unit length of the whole ring is
compared with Lindley's empirical F/L = E d (1.25 c^1.5 + 50 c^6): the
plane-strain answer lies about 29 % above it at c = 0.3 on every mesh
(h = 0.04: +30.4 %, 0.02: +29.5 %, 0.01: +28.5 %; quadratic elements at
h = 0.01: +27.4 %), so the 15 % aim is not met; the test holds the mesh
convergence and the measured gap (docs/contacts.md). At 1 % compression the
same section in linear elasticity meets the exact plane-strain answer (a
disc under two Hertz loads) to a fraction of a per cent, where Lindley's
power law lies 58 % below it: the gap is the formula's, not the model's.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mpi4py import MPI

from fenics_contact.references.hertz import load_for_diametral_approach
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene

SCENE = Path(__file__).parent.parent / "scenes" / "o_ring.toml"
E, D, SQUEEZE = 6.0, 2.0, 0.3
#: F/L at c = 0.3 on the h = 0.01 mesh (19 652 displacement DOFs, 10 steps).
FINE = 3.72928


def lindley(c: float) -> float:
    return E * D * (1.25 * c**1.5 + 50.0 * c**6)


def _variant(folder: Path, text: str):
    path = folder / "o_ring.toml"
    path.write_text(text.replace('"../meshes/', f'"{SCENE.parent.parent / "meshes"}/'))
    return run_scene(load_scene(path), folder / "out", comm=MPI.COMM_SELF, pictures=False)


@pytest.fixture(scope="module")
def squeezed(tmp_path_factory):
    text = SCENE.read_text().replace("h_contact = 0.02, h_far = 0.08", "h_contact = 0.04, "
                                     "h_far = 0.1").replace("steps = 10", "steps = 6")
    return _variant(tmp_path_factory.mktemp("o_ring"), text)


@pytest.mark.parametrize(("nu", "tolerance"), [(0.3, 0.002), (0.49, 0.012)])
def test_small_squeeze_meets_the_elastic_disc_between_plates(tmp_path, nu, tolerance):
    """Linear elasticity at c = 0.01: F/L = the exact plane-strain answer, Lindley far below.

    The plates' approach delta = 2 P / (pi E*) (2 ln(4 R / a) - 1) (a disc
    under two Hertz loads). Measured at h = 0.01: -0.03 % (nu = 0.3) and
    +0.60 % (nu = 0.49; +0.22 % at h = 0.005, +2.1 % at 0.02: P1 locking
    fading with h).
    """
    push = 0.01
    text = (SCENE.read_text().replace('law = "neo-hookean"', 'law = "linear"')
            .replace("nu = 0.49", f"nu = {nu}")
            .replace("h_contact = 0.02", "h_contact = 0.01")
            .replace("motion = [0.0, 0.3]", f"motion = [0.0, {push}]")
            .replace("motion = [0.0, -0.3]", f"motion = [0.0, -{push}]")
            .replace("steps = 10", "steps = 2"))
    result = _variant(tmp_path, text)
    assert result.path.converged
    force = 2.0 * result.summary["steps"][-1]["contacts"]["top"]["normal_force"]
    exact = load_for_diametral_approach(2.0 * push, D / 2.0, E, nu)
    assert force == pytest.approx(exact, rel=tolerance)
    assert lindley(2.0 * push / D) < 0.6 * exact  # 0.42 (nu = 0.49) and 0.50 of it


def test_the_ring_is_squeezed_to_30_percent_with_balanced_plates(squeezed):
    assert squeezed.path.converged
    states = squeezed.problem.contact_states()
    top, bottom = states["top"], states["bottom"]
    assert top.contact_force == pytest.approx(bottom.contact_force, rel=1e-10)
    assert max(top.max_penetration, bottom.max_penetration) < 1e-10 * D
    assert np.all(np.asarray(top.pressure) <= 0.0)


def test_force_per_length_against_lindley(squeezed):
    """F/L within 2 % of the fine mesh's; 29 % above Lindley (the 15 % aim is missed)."""
    steps = squeezed.summary["steps"]
    force = [2.0 * s["contacts"]["top"]["normal_force"] for s in steps]
    assert force[-1] == pytest.approx(FINE, rel=0.02)  # measured +1.5 %
    ratio = force[-1] / lindley(SQUEEZE)
    assert 1.2 < ratio < 1.35  # measured 1.304 here, 1.285 at h = 0.01
    # the force grows faster than linearly in c, like Lindley's, from c = 0.1 on
    ratios = [f / lindley(SQUEEZE * s["load_factor"]) for f, s in zip(force, steps, strict=True)]
    assert all(abs(r / ratios[-1] - 1) < 0.05 for r in ratios[2:])


def test_contact_width_at_30_percent(squeezed):
    """Deformed contact width against each plate: 0.72 d (h = 0.02: 0.718 d)."""
    problem = squeezed.problem
    domain = problem.domain
    x = domain.geometry.x[:, :2]
    block = np.full(x.shape[0], -1, np.int64)
    block[domain.geometry.dofmaps[0].reshape(-1)] = problem.V.dofmap.list.reshape(-1)
    u = problem.u.x.array.reshape(-1, 2)[block]
    for name, state in problem.contact_states().items():
        contact = next(c for c in problem.contacts if c.name == name)
        nodes = [int(np.argmin(np.linalg.norm(x - p[:2], axis=1)))
                 for p in contact.nodal_coordinates()]
        active = np.asarray(state.pressure) < 0
        width = 2.0 * np.max(x[nodes][active, 0] + u[nodes][active, 0])
        assert 0.66 * D < width < 0.78 * D, name
