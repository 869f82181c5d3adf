"""Shipped many-contact scenes on 2 processes: the serial Newton counts and forces.

Each scene runs through ``run_scene`` on the whole communicator (the O-ring
coarsened as in tests/test_o_ring.py); the per-step Newton iterations and every
contact's force are those measured serially (2 processes: the same counts, forces
to 3e-14) (``make test`` runs this file on 1 and,
marked ``mpi``, on 2 processes).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene

ROOT = Path(__file__).resolve().parents[1]

#: scene -> (text edits, Newton iterations per step, force per contact) measured serially.
SERIAL = {
    "o_ring": ((("h_contact = 0.02, h_far = 0.08", "h_contact = 0.04, h_far = 0.1"),
                ("steps = 10", "steps = 6")), [5, 5, 5, 5, 5, 5],
               {"bottom": 1.8925285522677908, "top": 1.8925285522677908}),
    "cylinder_between_plates": ((), [4, 3, 2],  # its pair mortar (the default)
                                {"side": 0.029874538781392512, "floor": 0.5578839917150387,
                                 "press": 0.5577947983473641}),
    "three_blocks_3d": ((), [3, 2],
                        {"middle-on-bottom": 0.2536185451592128,
                         "top-on-middle": 0.253626215966294, "floor": 0.25361549536003536}),
}



def _run(name: str, edits, tmp_path):
    text = (ROOT / "scenes" / f"{name}.toml").read_text()
    for old, new in edits:
        assert old in text, (name, old)
        text = text.replace(old, new)
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace('"../meshes/', f'"{ROOT / "meshes"}/'))
    folder = MPI.COMM_WORLD.bcast(str(tmp_path / "out") if MPI.COMM_WORLD.rank == 0 else None)
    return run_scene(load_scene(path), Path(folder), comm=MPI.COMM_WORLD, pictures=False)


@pytest.mark.mpi
@pytest.mark.parametrize("name", sorted(SERIAL))
def test_scene_gives_the_serial_counts_and_forces(name: str, tmp_path) -> None:
    edits, iterations, forces = SERIAL[name]
    outcome = _run(name, edits, tmp_path)
    assert outcome.path.converged
    its = [s.iterations for s in outcome.path.steps]
    states = outcome.problem.contact_states()
    got = {k: s.contact_force for k, s in states.items()}
    assert its == iterations
    assert sorted(got) == sorted(forces)
    for k, f in forces.items():
        assert got[k] == pytest.approx(f, rel=1e-10, abs=1e-14), k
