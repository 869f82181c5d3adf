"""A checkpoint resumes only the run that wrote it, and damaged files are named (exit 2)."""

from pathlib import Path

import pytest

from mpi4py import MPI

from fenics_contact.cli import main
from fenics_contact.output.checkpoint import CheckpointError, identity, read_latest
from fenics_contact.runner import run_scene
from fenics_contact.scene.schema import load_scene

ROOT = Path(__file__).parent.parent
BLOCKS = (ROOT / "scenes" / "block_on_block_node_to_segment.toml").read_text().replace(
    '"../meshes/block_on_block.geo"', f'"{ROOT / "meshes" / "block_on_block.geo"}"'
) + "\n[output]\npictures = false\n"


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """block_on_block (two bodies, one pair) run to the end: its output folder and scene."""
    folder = tmp_path_factory.mktemp("blocks")
    scene = folder / "blocks.toml"
    scene.write_text(BLOCKS)
    out = folder / "out"
    assert run_scene(load_scene(scene), out, comm=MPI.COMM_SELF).path.status == "converged"
    return scene, out


def _identity_of(tmp_path, text):
    path = tmp_path / "changed.toml"
    path.write_text(text)
    return identity(load_scene(path), 1)


@pytest.mark.parametrize(("old", "new", "named"), [
    ('name = "lower"\ntag = "target"\nlaw = "linear"\nE = 200.0',
     'name = "lower"\ntag = "target"\nlaw = "linear"\nE = 100.0',
     "bodies[1].E: checkpoint 200.0, now 100.0"),
    ('name = "lower"\ntag = "target"\nlaw = "linear"',
     'name = "lower"\ntag = "target"\nlaw = "neo-hookean"',
     "bodies[1].law: checkpoint 'linear', now 'neo-hookean'"),
    ('target = "target_face"', 'target = "bottom"',
     "pairs[0].target: checkpoint 'target_face', now 'bottom'"),
    ('target = "target_face"', 'target = "target_face"\nr = 10.0',
     "pairs[0].r: checkpoint 1.0, now 10.0"),
    ("n_lower = 11", "n_lower = 12", "mesh.parameters.n_lower: checkpoint 11, now 12"),
    ('method = "gnrm"', 'method = "auto"', "solver.method: checkpoint 'gnrm', now 'auto'"),
])
def test_resume_refuses_a_scene_that_changes_the_answer(finished, tmp_path, old, new, named):
    _, out = finished
    assert old in BLOCKS
    with pytest.raises(CheckpointError, match=r"written by another run") as info:
        read_latest(out / "checkpoint", _identity_of(tmp_path, BLOCKS.replace(old, new)))
    assert named in str(info.value)


def test_resume_accepts_settings_that_do_not_change_the_answer(finished, tmp_path):
    _, out = finished
    text = BLOCKS.replace('method = "gnrm"', 'method = "gnrm"\natol = 1e-9\nmax_iterations = 80')
    text = text.replace('name = "block-on-block-node-to-segment"', 'name = "renamed"')
    assert read_latest(out / "checkpoint", _identity_of(tmp_path, text))["step"] == 2


def test_a_changed_mesh_file_is_refused(finished, tmp_path):
    """Same parameters, other file content: the mesh file's digest differs."""
    _, out = finished
    geo = tmp_path / "block_on_block.geo"
    geo.write_text((ROOT / "meshes" / "block_on_block.geo").read_text() + "\n// edited\n")
    text = BLOCKS.replace(str(ROOT / "meshes" / "block_on_block.geo"), str(geo))
    with pytest.raises(CheckpointError, match=r"mesh_file_sha256: checkpoint '[0-9a-f]{64}'"):
        read_latest(out / "checkpoint", _identity_of(tmp_path, text))


def _copy(finished, tmp_path):
    import shutil

    scene, out = finished
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    return scene, copy


def _damage(path: Path, how: str, keep: int = 100, flip: int = 8) -> int:
    """Truncate ``path`` to ``keep`` bytes, flip ``flip`` bytes in its middle, or remove it.

    Returns its size before.
    """
    data = path.read_bytes()
    if how == "truncated":
        path.write_bytes(data[:keep])
    elif how == "missing":
        path.unlink()
    else:
        middle = len(data) // 2
        path.write_bytes(data[:middle] + bytes(b ^ 0xFF for b in data[middle:middle + flip])
                         + data[middle + flip:])
    return len(data)


def _resume(scene, out, capsys):
    code = main(["run", str(scene), "--resume", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return code, err


@pytest.mark.parametrize("damage", ["truncated", "flipped"])
def test_a_damaged_checkpoint_file_is_named(finished, tmp_path, capsys, damage):
    scene, out = _copy(finished, tmp_path)
    npz = next((out / "checkpoint").glob("step_*/rank_0000.npz"))
    _damage(npz, damage, keep=npz.stat().st_size // 2, flip=64)
    code, err = _resume(scene, out, capsys)
    assert code == 2
    assert f"{npz} is damaged or unreadable" in err


@pytest.mark.parametrize("damage", ["truncated", "missing", "edited"])
def test_a_damaged_step_file_is_named(finished, tmp_path, capsys, damage):
    scene, out = _copy(finished, tmp_path)
    h5 = out / "solution" / "step_0001.h5"
    size = _damage(h5, damage)
    code, err = _resume(scene, out, capsys)
    assert code == 2
    why = {"truncated": f"has 100 bytes instead of {size}", "missing": "is missing",
           "edited": "changed since the step was written"}[damage]
    assert f"Output file {h5} {why}" in err


def test_a_damaged_latest_json_is_named(finished, tmp_path, capsys):
    scene, out = _copy(finished, tmp_path)
    latest = out / "checkpoint" / "latest.json"
    latest.write_text(latest.read_text()[:50])
    code, err = _resume(scene, out, capsys)
    assert code == 2 and f"Checkpoint {latest} is damaged" in err
