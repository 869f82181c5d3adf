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
    # auto at r = 1 and 1e10 E/h works at r = 1 E/h: the reference to round-off
    auto = next(line for line in table.splitlines() if "| Auto |" in line)
    assert "(the reference's answer to round-off)" in auto
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
    assert lines[0] == "| Method | source | r = 0.1 | r = 10 |"
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
