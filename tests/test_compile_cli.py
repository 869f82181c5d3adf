"""``fenics-contact compile``: after it, a run of the same scenes compiles nothing.

Each command runs in a fresh process with ``XDG_CACHE_HOME`` on an empty
folder, so the form cache starts empty; a run after ``compile`` must find
every form and expression it needs there (no new file in the cache).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

SCENES = Path(__file__).resolve().parents[1] / "scenes"


def _command(cache: Path, *args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, XDG_CACHE_HOME=str(cache))
    return subprocess.run([sys.executable, "-m", "fenics_contact.cli", *args], env=env,
                          capture_output=True, text=True, check=False)


def _cached(cache: Path) -> set[str]:
    return {p.name for p in cache.rglob("*") if p.is_file()}


def test_a_run_after_compile_compiles_nothing(tmp_path):
    cache = tmp_path / "cache"
    scenes = [str(SCENES / "paper_ex2.toml"), str(SCENES / "block_slide_friction.toml")]
    done = _command(cache, "compile", *scenes)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("forms compiled in") == 2, done.stdout
    compiled = _cached(cache)
    assert sum(name.endswith(".so") for name in compiled) >= 4
    for scene in scenes:  # with pictures, as a user runs it
        run = _command(cache, "run", scene, "--out", str(tmp_path / Path(scene).stem), "--quiet")
        assert run.returncode == 0, run.stderr
        assert _cached(cache) == compiled, (scene, sorted(_cached(cache) - compiled))
    # the forms hold the moduli as constants: other E and nu need no new compilation
    text = (SCENES / "paper_ex2.toml").read_text().replace('"../meshes', f'"{SCENES.parent}/meshes')
    assert "E = 210.0" in text and "nu = 0.3" in text
    other = tmp_path / "paper_ex2_soft.toml"
    other.write_text(text.replace("E = 210.0", "E = 21.0").replace("nu = 0.3", "nu = 0.35"))
    run = _command(cache, "run", str(other), "--out", str(tmp_path / "soft"), "--quiet")
    assert run.returncode == 0, run.stderr
    assert _cached(cache) == compiled, sorted(_cached(cache) - compiled)
    # the check can fail: a scene that was not compiled adds its forms
    run = _command(cache, "run", str(SCENES / "hertz_cylinder.toml"), "--out",
                   str(tmp_path / "hertz"), "--quiet", "--no-pictures")
    assert run.returncode == 0, run.stderr
    assert _cached(cache) > compiled


def test_a_bad_scene_stops_compile_before_any_build(tmp_path):
    cache = tmp_path / "cache"
    done = _command(cache, "compile", str(SCENES / "paper_ex2.toml"), str(tmp_path / "none.toml"))
    assert done.returncode == 2
    assert "none.toml does not exist" in done.stderr
    assert not cache.exists() or not _cached(cache)
