"""The tradeoff and stability sweeps on tiny grids: files and columns.

``fenics-contact tradeoff|stability`` take scene files; the project's own
grids (``benchmarks/research/tradeoff.py``, ``benchmarks/robustness/
stability_grid.py``) run the same machinery on the lab's scenes.
"""

import csv
import json
from pathlib import Path

import pytest

from benchmarks.research import tradeoff as lab_tradeoff
from benchmarks.robustness.stability_grid import full_grid
from fenics_contact.cli import main
from fenics_contact.cli.stability import run_cases
from fenics_contact.solvers.stepping import RAISE_TOLERANCE

SCENES = Path(__file__).resolve().parents[1] / "scenes"


def read_csv(path):
    with path.open() as f:
        return list(csv.DictReader(f))


def test_tradeoff_command_on_a_scene_writes_json_csv_table_and_plot(tmp_path):
    code = main(["tradeoff", str(SCENES / "paper_ex2.toml"), "--name", "bar", "--methods",
                 "gnrm,auto", "--r", "1,1e10", "--repeats", "1", "--out", str(tmp_path)])
    assert code == 0
    rows = read_csv(tmp_path / "tradeoff.csv")
    columns = {"scene", "mesh", "displacement_dofs", "method", "r_relative", "status", "iterations",
               "linear_solves", "wall_s", "repeats", "max_penetration", "u_error", "p0_error",
               "pareto_u"}
    assert columns <= set(rows[0])
    assert len(rows) == 4
    status = {(r["method"], float(r["r_relative"])): r["status"] for r in rows}
    assert status[("auto", 1e10)] == "converged" and status[("gnrm", 1e10)] != "converged"
    assert any(r["pareto_u"] == "True" for r in rows)
    assert len(json.loads((tmp_path / "tradeoff.json").read_text())) == 4
    table = (tmp_path / "table.md").read_text()
    assert "| bar | paper_ex2 | Auto |" in table
    # GNRM converged at r = 1 E/h only: the reference's own point, and marked so
    gnrm = next(line for line in table.splitlines() if "| GNRM |" in line)
    assert "(the reference's own path)" in gnrm
    # auto at r = 1 and 1e10 E/h works at r = 1 E/h: the reference's own run too
    auto = next(line for line in table.splitlines() if "| Auto |" in line)
    assert "(the reference's own path)" in auto
    assert (tmp_path / "tradeoff.png").stat().st_size > 10_000


def test_stability_command_on_a_scene_and_the_lab_grid(tmp_path):
    code = main(["stability", str(SCENES / "paper_ex2.toml"), "--r", "1e12", "--methods",
                 "gnrm,auto", "--out", str(tmp_path / "scene")])
    assert code == 0
    rows = read_csv(tmp_path / "scene" / "stability.csv")
    status = {(r["case"], r["method"]): r["status"] for r in rows}
    assert status == {("paper-ex2-r1e+12", "gnrm"): "diverged",
                      ("paper-ex2-r1e+12", "auto"): "converged"}
    code = run_cases(full_grid(), ["--cases", "bar-r1e12,bar-no-contact", "--methods",
                                   "gnrm,auto", "--out", str(tmp_path / "grid")], tmp_path)
    assert code == 0
    rows = read_csv(tmp_path / "grid" / "stability.csv")
    columns = {"case", "group", "method", "status", "iterations", "steps_completed",
               "max_penetration", "contact_force", "max_abs_u", "atol", "switches"}
    assert columns <= set(rows[0])
    status = {(r["case"], r["method"]): r["status"] for r in rows}
    assert status == {
        ("bar-r1e12", "gnrm"): "diverged", ("bar-r1e12", "auto"): "converged",
        ("bar-no-contact", "gnrm"): "converged", ("bar-no-contact", "auto"): "converged",
    }
    assert all("nan" not in v.lower() and "inf" not in v.lower()
               for r in rows for v in r.values())
    assert (tmp_path / "grid" / "stability.png").stat().st_size > 5_000
    assert len(list((tmp_path / "grid" / "cases").glob("*.json"))) == 4


def test_tradeoff_friction_group_scores_the_coulomb_law(tmp_path):
    code = lab_tradeoff.main(["--scene", "friction", "--mu", "0.3", "--methods", "penalty,gnrm",
                              "--r", "1,1e4", "--meshes", "1", "--repeats", "1",
                              "--out", str(tmp_path)])
    assert code == 0
    rows = {(r["method"], float(r["r_relative"])): r for r in read_csv(tmp_path / "tradeoff.csv")}
    assert len(rows) == 4
    assert {"mu", "ft_error", "stick_slip", "t_residual"} <= set(rows[("gnrm", 1.0)])
    for r in (1.0, 1e4):  # GNRM: the nodal Coulomb law holds whatever r (measured 3e-16)
        gnrm = rows[("gnrm", r)]
        assert gnrm["status"] == "converged" and float(gnrm["mu"]) == 0.3
        assert float(gnrm["ft_error"]) < 1e-12 and float(gnrm["stick_slip"]) < 1e-12
        assert float(gnrm["u_error"]) < 1e-12 and float(gnrm["t_residual"]) < 1e-8
    # penalty at r = 1 E/h (r_t = 2 E/L = 0.2 E/h): sticking nodes creep (measured 1.3e-3 against a
    # 0.02 slide) and it slides fully later than the reference (F_t 15 % below mu N there)
    penalty = rows[("penalty", 1.0)]
    assert penalty["status"] == "converged" and penalty["t_residual"] == "nan"  # no lam_t
    assert float(penalty["stick_slip"]) > 1e-4 and float(penalty["ft_error"]) > 0.05
    table = (tmp_path / "table.md").read_text()
    assert "| slide | 10x5 | 0.3 | GNRM | 1 - 10000 |" in table
    assert (tmp_path / "tradeoff.png").stat().st_size > 10_000


def test_stability_two_body_friction_records_coulomb_ratio_and_reference(tmp_path, capsys):
    """Sliding blocks with friction: F_t / (mu N) and the reference (GNRM at r = 1 E/h).

    At r = 1e12 E/h auto reaches the reference: it solves at r = 1 E/h, and the
    reported forces read the converged multipliers (the transmitted traction at the
    user's r would carry the round-off eps r g of the gap, 15 % of p: F_t then
    missed mu N by 1-5 %).
    """
    with pytest.raises(SystemExit):
        run_cases(full_grid(), ["--help"], tmp_path)
    assert "friction-r,two-body-friction,two-body-friction-r," in "".join(
        capsys.readouterr().out.split())
    code = run_cases(full_grid(), ["--cases", "blocks-mu0.3,blocks-r1e12", "--methods",
                                   "gnrm,auto", "--out", str(tmp_path)], tmp_path)
    assert code == 0
    rows = {(r["case"], r["method"]): r for r in read_csv(tmp_path / "stability.csv")}
    assert {"mu", "tangential_force", "ft_ratio", "reference", "reference_deviation",
            "reference_reached"} <= set(rows[("blocks-mu0.3", "gnrm")])
    for method in ("gnrm", "auto"):  # the reference itself; full slip: int |t| = mu N
        row = rows[("blocks-mu0.3", method)]
        assert row["status"] == "converged" and float(row["mu"]) == 0.3
        assert float(row["ft_ratio"]) == pytest.approx(1.0, abs=1e-12)
        assert row["reference"] == "gnrm r=1" and row["reference_reached"] == "True"
        assert float(row["reference_deviation"]) < 1e-12
    gnrm, auto = rows[("blocks-r1e12", "gnrm")], rows[("blocks-r1e12", "auto")]
    assert gnrm["status"] == "diverged" and gnrm["reference_reached"] == "False"
    assert auto["status"] == "converged" and auto["reference_reached"] == "True"
    assert float(auto["reference_deviation"]) < 1e-10
    assert float(auto["ft_ratio"]) == pytest.approx(1.0, abs=1e-10)


def test_study_beside_another_scene_with_relative_r_fills_the_table(tmp_path):
    """--relative --beside: each scene's rows at the r asked (relative to its own E/h)."""
    code = main(["study", str(SCENES / "block_on_block_node_to_segment.toml"), "--beside",
                 str(SCENES / "block_on_block.toml"), "--methods", "gnrm", "--r", "0.1,10",
                 "--relative", "--out", str(tmp_path)])
    assert code == 0
    lines = (tmp_path / "table.md").read_text().splitlines()
    assert lines[0] == "| Method | source | r = 0.1 E/h | r = 10 E/h |"
    rows = [line.split("|")[3:5] for line in lines[2:]]
    assert len(rows) == 2  # one per scene, every cell an iteration count
    assert all(cell.strip().isdigit() for row in rows for cell in row), lines


def test_sweeps_on_a_frictional_scene_with_several_contacts(tmp_path):
    """block_floor_wall: a frictionless floor and a frictional wall (mu = 0.2).

    ``tradeoff`` used to stop with AttributeError (it read stick/slip from
    the first contact, the floor); ``stability`` divided the wall's F_t by
    mu times every contact's N (0.085). Both now take F_t / (mu N) over the
    frictional contacts, F_t as int |t| dA: every wall node slips, so 1; the
    vector sum of the tractions, whose directions differ along the wall, is
    0.98 of mu N (read before as a friction error of 2 %).
    """
    code = main(["tradeoff", str(SCENES / "block_floor_wall.toml"), "--methods", "gnrm",
                 "--r", "1", "--repeats", "1", "--out", str(tmp_path / "trade")])
    assert code == 0
    (row,) = read_csv(tmp_path / "trade" / "tradeoff.csv")
    assert row["status"] == "converged" and float(row["stick_slip"]) < 1e-12
    code = main(["stability", str(SCENES / "block_floor_wall.toml"), "--methods", "gnrm",
                 "--r", "1", "--out", str(tmp_path / "stab")])
    assert code == 0
    (row,) = read_csv(tmp_path / "stab" / "stability.csv")
    record = json.loads((tmp_path / "stab" / "stability.json").read_text())[0]
    wall = record["steps"][-1]["contacts"]["wall"]
    assert record["mus"] == {"wall": 0.2}
    assert float(row["ft_ratio"]) == pytest.approx(
        wall["tangential_magnitude"] / (0.2 * wall["normal_force"]), rel=1e-12)
    assert float(row["ft_ratio"]) == pytest.approx(1.0, abs=1e-10)
    assert wall["tangential_force"] / (0.2 * wall["normal_force"]) == pytest.approx(
        0.98138, abs=1e-4)


@pytest.mark.parametrize("contact_set", ["sign", "exact"])
def test_stability_counts_match_run_with_the_same_contact_set(tmp_path, contact_set):
    """The help's promise: `run` with predictor "previous" and the same contact set.

    Before, the sweeps always took the sign rule, while a scene's default is
    the exact set: a user's 3D quarter model read "diverged" at r = 1e4 E/h
    where `run` converged in 10 iterations. --contact-set chooses.
    """
    text = (SCENES / "hertz_cylinder.toml").read_text()
    assert 'method = "gnrm"' in text
    text = text.replace('method = "gnrm"', f'method = "gnrm"\npredictor = "previous"\n'
                        f'contact_set = "{contact_set}"')
    text = text.replace('"../meshes/', f'"{SCENES.parent / "meshes"}/')
    scene = tmp_path / "hertz.toml"
    scene.write_text(text)
    assert main(["run", str(scene), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    run = json.loads((tmp_path / "run" / "summary.json").read_text())
    code = main(["stability", str(scene), "--methods", "gnrm", "--r", "1",
                 "--contact-set", contact_set, "--out", str(tmp_path / "stab")])
    assert code == 0
    (row,) = read_csv(tmp_path / "stab" / "stability.csv")
    assert row["status"] == "converged"
    assert int(row["iterations"]) == sum(s["iterations"] for s in run["steps"])


BALL_ON_BLOCK = """
[scene]
name = "blk-ball"
dimension = 2

[mesh]
generator = "rectangle"
origin = [-1.0, 0.0]
size = [2.0, 1.0]
cells = [8, 4]

[material]
law = "neo-hookean"
E = 1000.0
nu = 0.3

[[dirichlet]]
tag = "top"
value = [0.0, 0.0]

[obstacle]
type = "ball"
centre = [0.0, -2.0]
radius = 2.0
motion = [0.0, {lift}]

[contact]
tag = "bottom"
r = {r}

[solver]
method = "gnrm"
steps = 4
{solver}
"""


def _ball_scene(path: Path, r: float = 1.0, solver: str = "", lift: float = 0.08) -> Path:
    path.write_text(BALL_ON_BLOCK.format(r=r, solver=solver, lift=lift))
    return path


def _run_iterations(scene: Path, out: Path) -> int:
    assert main(["run", str(scene), "--out", str(out), "--quiet", "--no-pictures"]) in (0, 1)
    return sum(s["iterations"] for s in json.loads((out / "summary.json").read_text())["steps"])


def _help(command: str, capsys) -> str:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return " ".join(capsys.readouterr().out.split())


def test_study_counts_match_run_with_rtol_zero_as_its_help_says(tmp_path, capsys):
    """GNRM at r = 100 E/h on the ball: study 19; run 15 with the scene rtol 1e-10, 19 with 0."""
    said = _help("study", capsys)
    assert 'contact_set = "sign", atol = --tol and rtol = 0' in said
    assert main(["study", str(_ball_scene(tmp_path / "ball.toml")), "--methods", "gnrm",
                 "--r", "100", "--relative", "--out", str(tmp_path / "study")]) == 0
    (row,) = read_csv(tmp_path / "study" / "study.csv")
    same = 'predictor = "previous"\ncontact_set = "sign"\natol = 1e-8\nmax_cutbacks = 0\n'
    exact = _run_iterations(_ball_scene(tmp_path / "a.toml", 100, same + "rtol = 0.0"),
                            tmp_path / "a")
    scene_rtol = _run_iterations(_ball_scene(tmp_path / "b.toml", 100, same), tmp_path / "b")
    assert (int(row["iterations"]), exact, scene_rtol) == (19, 19, 15)


def test_tradeoff_counts_match_run_with_its_atol_as_its_help_says(tmp_path, capsys):
    """Its atol, max(1e-10 E h^(d-1), floor) = 2.5e-8 here, is looser than the scene's 1e-8."""
    said = _help("tradeoff", capsys)
    assert "tighter than a scene" not in said and "that atol and rtol = 0" in said
    assert main(["tradeoff", str(_ball_scene(tmp_path / "ball.toml")), "--methods", "gnrm",
                 "--r", "1", "--repeats", "1", "--out", str(tmp_path / "trade")]) == 0
    (row,) = read_csv(tmp_path / "trade" / "tradeoff.csv")
    assert float(row["atol"]) == pytest.approx(2.5e-8) and float(row["r_working"]) == 1.0
    same = (f'predictor = "previous"\ncontact_set = "sign"\natol = {row["atol"]}\n'
            "rtol = 0.0\nmax_cutbacks = 0\n")
    assert int(row["iterations"]) == _run_iterations(
        _ball_scene(tmp_path / "a.toml", 1.0, same), tmp_path / "a")


def test_stability_shows_a_converged_run_off_the_reference_and_names_a_loose_tolerance(
        tmp_path, capsys):
    """A ball grazing the block (N = 0.0585) at r = 1e10 E/h: atol 0.0544, its round-off floor.

    The penalty method converged 1.4 % off the reference; it was shown as converged.
    """
    scene = _ball_scene(tmp_path / "graze.toml", lift=0.0001)
    assert main(["stability", str(scene), "--r", "1e10", "--methods", "penalty,auto",
                 "--out", str(tmp_path / "stab")]) == 0
    out = " ".join(capsys.readouterr().out.split())
    rows = {r["method"]: r for r in read_csv(tmp_path / "stab" / "stability.csv")}
    penalty, auto = rows["penalty"], rows["auto"]
    assert penalty["status"] == "converged" and penalty["reference_reached"] == "False"
    assert penalty["outcome"] == "converged, off the reference by 1.4e-02"
    assert auto["outcome"] == "converged" and auto["reference_reached"] == "True"
    assert float(penalty["atol_share"]) == pytest.approx(0.93, abs=0.01)
    assert "blk-ball-r1e+10: atol = 0.0544 is 93 % of the reference's contact force 0.0585" in out
    assert "penalty converged, off the reference by 1.4e-02" in out


def test_a_stall_in_a_study_names_its_tol(tmp_path):
    """Penalty at r = 1e6 E/h stalls at round-off above --tol: the failure names --tol.

    It used to say "raise atol ... (or leave it out of the scene: the default
    follows E)", the scene's key, which a study does not read.
    """
    assert main(["study", str(_ball_scene(tmp_path / "ball.toml")), "--methods", "penalty",
                 "--r", "1e6", "--relative", "--out", str(tmp_path / "study")]) == 0
    (row,) = read_csv(tmp_path / "study" / "study.csv")
    assert row["status"] == "cycling"
    assert row["message"].endswith(f"{RAISE_TOLERANCE} 5e-06 (study's --tol)")
    assert "[solver]" not in row["message"] and "scene" not in row["message"]
