# SPDX-License-Identifier: MIT
"""A Python session that calibrates the demo data and matches the CLI.

The CLI prints metrics with %.6f and parameters with %.9g: the Python value,
printed the same way, must give the CLI's number exactly (difference 0, so
within 1e-9 mm), and the full-precision value must lie within half a unit of
the last printed digit. The model files both write must be byte-identical
(%.9g of every parameter)."""
import csv
import json

import pytest

import rcal

DATA = "data/sim_irb120.csv"
METRICS = ("rmse_mm", "mean_abs_mm", "sd_mm", "mean_mm", "max_mm")


@pytest.fixture(scope="module")
def cli(run_cli):
    return json.loads(run_cli("calibrate", "--data", DATA, "--json").stdout)


@pytest.fixture(scope="module")
def py():
    import os
    from conftest import ROOT
    cwd = os.getcwd()
    os.chdir(ROOT)  # module-scoped: the autouse chdir is function-scoped
    try:
        return rcal.calibrate(data_csv=DATA)
    finally:
        os.chdir(cwd)


def same_printed(value, cli_value, fmt, half_unit):
    return float(fmt % value) == cli_value and abs(value - cli_value) <= half_unit * (1 + 1e-9)


def test_counts_and_solver_match(py, cli):
    assert (py.n_train, py.n_test) == (cli["n_train"], cli["n_test"]) == (540, 60)
    assert py.method == cli["method"] == "lm"
    assert py.converged is cli["converged"] is True
    assert py.exit == cli["exit"]
    assert (py.iterations, py.cost_evals) == (cli["iterations"], cli["cost_evals"])


@pytest.mark.parametrize("which", ["before", "after", "train_before", "train_after"])
def test_every_metric_matches(py, cli, which):
    mine, theirs = getattr(py, which), cli[which]
    assert mine.n == theirs["n"]
    for key in METRICS:
        v = getattr(mine, key)
        assert same_printed(v, theirs[key], "%.6f", 5e-7), (which, key, v, theirs[key])
        assert abs(float("%.6f" % v) - theirs[key]) <= 1e-9


def test_calibration_improves(py):
    assert py.after.rmse_mm < py.before.rmse_mm / 10


def test_every_parameter_matches(py, cli):
    assert [p.name for p in py.params] == [p["name"] for p in cli["params"]]
    for mine, theirs in zip(py.params, cli["params"]):
        assert mine.unit == theirs["unit"]
        for key in ("value", "delta"):
            v, c = getattr(mine, key), theirs[key]
            assert float("%.9g" % v) == c, (mine.name, key, v, c)
            assert abs(v - c) <= 5e-9 * max(1.0, abs(c)), (mine.name, key, v, c)
    assert len(cli["encoder_mm"]) == 3
    for v, c in zip(py.encoder_mm, cli["encoder_mm"]):
        assert abs(float("%.6f" % v) - c) <= 1e-9


def test_model_file_identical_to_cli(py, run_cli, tmp_path):
    mine, theirs = tmp_path / "py.json", tmp_path / "cli.json"
    py.write(str(mine))
    run_cli("calibrate", "--data", DATA, "--json", "--out", str(theirs))
    # byte for byte, but for the date of the run (it may differ by a second)
    import re as _re
    undate = lambda b: _re.sub(rb'"date": "[^"]*"', b'"date": ""', b)
    assert undate(mine.read_bytes()) == undate(theirs.read_bytes())
    back = rcal.Model.load(mine)
    assert back.has_nominal
    for (name, unit, v), p in zip(back.params(), py.params):
        assert name == p.name and abs(v - p.value) <= 1e-6


def read_samples(path):
    q, L = [], []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            q.append([float(row["q%d" % j]) for j in range(1, 7)])
            L.append(float(row["L"]))
    return q, L


def assert_same_result(a, b):
    for which in ("before", "after", "train_before", "train_after"):
        assert getattr(a, which) == getattr(b, which), which
    assert [p[1:] for p in a.params] == [p[1:] for p in b.params]
    assert (a.iterations, a.exit) == (b.iterations, b.exit)


def test_arrays_give_the_file_result_bit_for_bit(py):
    q, L = read_samples(DATA)
    assert_same_result(rcal.calibrate(q_deg=q, L_mm=L), py)


def test_arrays_need_no_temporary_file(py, tmp_path, monkeypatch):
    # issue 50: the arrays reach the calibration in memory: with TMPDIR a directory that does not exist (no
    # temporary CSV can be made there) the result is still the file's, bit for bit
    monkeypatch.setenv("TMPDIR", str(tmp_path / "absent"))
    q, L = read_samples(DATA)
    assert_same_result(rcal.calibrate(q_deg=q, L_mm=L), py)
    assert not (tmp_path / "absent").exists()


def test_numpy_arrays(py):
    np = pytest.importorskip("numpy")
    q, L = read_samples(DATA)
    assert_same_result(rcal.calibrate(q_deg=np.array(q), L_mm=np.array(L)), py)


def test_options_reach_the_pipeline(run_cli):
    cli = json.loads(run_cli("calibrate", "--data", DATA, "--json", "--method", "ltlm", "--seed", "7",
                             "--test-fraction", "0.2", "--fix", "a1,theta6").stdout)
    r = rcal.calibrate(data_csv=DATA, method="ltlm", seed=7, test_fraction=0.2, fix=["a1", "theta6"])
    assert (r.n_train, r.n_test) == (cli["n_train"], cli["n_test"])
    assert float("%.6f" % r.after.rmse_mm) == cli["after"]["rmse_mm"]
    assert r.param("a1").delta == 0.0 and r.param("theta6").delta == 0.0
    for mine, theirs in zip(r.params, cli["params"]):
        assert float("%.9g" % mine.value) == theirs["value"], mine.name


def test_identified_model_handle(py):
    m = py.model
    assert m.has_nominal
    q = [10.0, 20.0, -30.0, 40.0, 50.0, 60.0]
    assert m.fk(q) != m.fk(q, nominal=True)
    assert [round(v, 12) for (_, _, v) in m.params()][:24] == [round(p.value, 12) for p in py.params][:24]


def test_json_report_is_the_cli_one(py, cli):
    mine = py.json()
    for doc in (mine, cli):
        assert doc.pop("time_ms") >= 0.0
        assert doc.pop("command").startswith("rcal calibrate")  # the CLI's has its options
        # the date of the run may differ by a second between the two runs
        assert doc["provenance"].pop("date").endswith("Z")
    assert mine == cli


def test_truth_figures_match_cli(run_cli):
    truth = "data/sim_irb120_truth.json"
    cli = json.loads(run_cli("calibrate", "--data", DATA, "--truth", truth, "--json").stdout)["truth_flange"]
    r = rcal.calibrate(data_csv=DATA, truth=truth)
    assert set(r.truth_flange) == set(cli)
    for key, v in r.truth_flange.items():
        assert float("%.6f" % v) == cli[key], key
    assert r.truth_flange["after_rms_mm"] < r.truth_flange["before_rms_mm"] / 10
    assert rcal.calibrate(data_csv=DATA).truth_flange is None


def test_write_never_over_an_input(tmp_path):
    data = tmp_path / "data.csv"
    data.write_bytes(open(DATA, "rb").read())
    r = rcal.calibrate(data_csv=str(data))
    with pytest.raises(rcal.RcalError) as e:
        r.write(str(data))
    assert e.value.kind == "output failed"
    assert data.read_bytes() == open(DATA, "rb").read()
