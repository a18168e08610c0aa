# SPDX-License-Identifier: MIT
"""The options and functions the package gained with rch_ffi ABI 2, each
against the CLI run on the same files: several data files, validation,
effects, no prior, evaluate, export (URDF and DH CSV byte for byte), the
report, __version__, and the refusals the CLI makes."""
import json
import os

import pytest

import rcal

DATA = "data/sim_irb120.csv"


def cli_json(run_cli, *args):
    return json.loads(run_cli(*args).stdout)


def close(mine, theirs):
    return abs(mine.rmse_mm - theirs["rmse_full_mm"]) <= 1e-9 and mine.n == theirs["n"]


def test_version_is_the_c_library(run_cli):
    assert rcal.__version__ == run_cli("--version").stdout.split()[1]


@pytest.fixture()
def halves(tmp_path):
    lines = open(DATA).read().splitlines()
    a, b, v = tmp_path / "a.csv", tmp_path / "b.csv", tmp_path / "v.csv"
    a.write_text("\n".join([lines[0]] + lines[1:251]) + "\n")
    b.write_text("\n".join([lines[0]] + lines[251:501]) + "\n")
    v.write_text("\n".join([lines[0]] + lines[501:]) + "\n")
    return str(a), str(b), str(v)


def test_several_files_and_validation(run_cli, halves):
    a, b, v = halves
    c = cli_json(run_cli, "calibrate", "--data", a, "--data", b, "--validate", v, "--json")
    r = rcal.calibrate([a, b], validate=v)
    assert r.n_data == 500
    assert close(r.after, c["after"]) and close(r.before, c["before"])
    assert r.validation is not None and r.validation.n == 100
    assert r.json()["validation"] == c["validation"]


@pytest.mark.parametrize("opts,flags", [({"effects": ["length_offset"]}, ["--effects", "length_offset"]),
                                        ({"prior": False}, ["--no-prior"]),
                                        ({"method": "ltlm", "seed": 3}, ["--method", "ltlm", "--seed", "3"]),
                                        ({"holdout_groups": True}, ["--holdout-groups"])])
def test_options_reach_the_pipeline(run_cli, opts, flags):
    c = cli_json(run_cli, "calibrate", "--data", DATA, "--json", *flags)
    r = rcal.calibrate(DATA, **opts)
    assert close(r.after, c["after"]) and close(r.train_after, c["train_after"])
    assert [p.name for p in r.params] == [p["name"] for p in c["params"]]
    assert r.figure("prior") == (0.0 if opts.get("prior") is False else 1.0)


def test_standard_errors_and_classes(run_cli):
    c = cli_json(run_cli, "calibrate", "--data", DATA, "--json")
    r = rcal.calibrate(DATA)
    for p, q in zip(r.params, c["uncertainty"]["parameters"]):
        assert float("%.6g" % p.std_error) == q["std_error"]
        assert (p.identifiability, p.compensation) == (q["class"], q["compensation"])
        assert p.data_vs_prior == q.get("data_vs_prior")
    assert {p.data_vs_prior for p in r.params} >= {"determined", "partly"}
    assert r.predicted["position95_workspace_median_mm"] > 0


def test_evaluate_equals_cli(run_cli, tmp_path):
    model = str(tmp_path / "m.json")
    rcal.calibrate(DATA).write(model)
    for refit in (False, True):
        c = cli_json(run_cli, "evaluate", "--model", model, "--data", DATA, "--json",
                     *(["--refit-encoder"] if refit else []))
        e = rcal.evaluate(model, DATA, refit_encoder=refit)
        assert e.metrics.n == c["n"] == 600
        for k in ("rmse_mm", "mean_abs_mm", "sd_mm", "mean_mm", "max_mm"):
            assert abs(getattr(e.metrics, k) - c["residual"][k]) <= 1e-12, k  # the CLI prints %.17g
        assert e.encoder_refitted == c["encoder_refitted"] == refit
        assert e.poses == c["iso9283"]["poses"]


@pytest.mark.parametrize("fmt", ["urdf", "dh-csv"])
def test_export_byte_for_byte(run_cli, tmp_path, fmt):
    model = str(tmp_path / "m.json")
    r = rcal.calibrate(DATA)
    r.write(model)
    mine, theirs = tmp_path / ("py." + fmt), tmp_path / ("cli." + fmt)
    info = rcal.export(model, str(mine), format=fmt)
    run_cli("export", "--model", model, "--format", fmt, "--out", str(theirs))
    assert mine.read_bytes() == theirs.read_bytes()
    assert info["written"] == (7 if fmt == "urdf" else len(theirs.read_text().splitlines()) - 1)
    assert rcal.export(r, str(tmp_path / ("r." + fmt)), format=fmt) == info  # from the Result
    with pytest.raises(rcal.RcalError):
        rcal.export(model, model, format=fmt)  # never over an input


def test_report_into_a_directory(tmp_path):
    r = rcal.calibrate(DATA)
    g = rcal.diagnose(DATA)
    paths = r.report(str(tmp_path / "rep"), diagnosis=g)
    names = sorted(os.path.basename(p) for p in paths)
    assert "report.html" in names and "report.calibration.json" in names and "report.diagnosis.json" in names
    assert any(n.startswith("report_") and n.endswith(".csv") for n in names)
    html = (tmp_path / "rep" / "report.html").read_text()
    assert "<html" in html.lower() and "a2" in html
    assert json.loads((tmp_path / "rep" / "report.calibration.json").read_text())["n_train"] == 540
    # the verdict against a tolerance: the demo's largest 95 % radius over the data is about 0.016 mm
    r.report(str(tmp_path / "pass"), tolerance_mm=1.0)
    assert "<b>PASS</b> against the tolerance of 1 mm" in (tmp_path / "pass" / "report.html").read_text()
    r.report(str(tmp_path / "fail"), tolerance_mm=0.001)
    assert "<b>FAIL</b> against the tolerance of 0.001 mm" in (tmp_path / "fail" / "report.html").read_text()


def test_diagnosis_figures_and_residuals(run_cli):
    c = cli_json(run_cli, "diagnose", "--data", DATA, "--json")
    g = rcal.diagnose(DATA)
    assert g.effect == c["effect"] and g.n == c["n"] == 600
    before, after, floor = g.residuals()
    assert len(before) == len(after) == len(floor) == 600
    rms = (sum(x * x for x in after) / len(after)) ** 0.5
    assert abs(rms - g.rmse_after_mm) <= 1e-9
    assert g.next_command.startswith("rcal calibrate --data " + DATA)


def test_compensate_details_and_tool(tmp_path):
    model = str(tmp_path / "m.json")
    rcal.calibrate(DATA).write(model)
    q = [[10, 20, -30, 40, 50, 60], [0, 0, 0, 0, 30, 0]]
    flange = rcal.compensate(model, q, details=True)
    tcp = rcal.compensate(model, q, tool_mm=(0, 0, 150), details=True)
    assert flange.status == tcp.status == [0, 0]
    assert all(u > 0 for u in tcp.u95_mm) and max(tcp.u95_mm) > max(flange.u95_mm)  # off the flange: wider
    m = rcal.Model.load(model)
    one = rcal.compensate(m, q[0])
    assert len(one) == 6 and one == flange.q_deg[0]


def test_refusals_as_the_cli(run_cli, halves):
    a, _, _ = halves
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate([a, a])
    assert "same file" in str(e.value)
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(DATA, validate=DATA)
    assert "same file" in str(e.value)
    with pytest.raises(rcal.RcalError) as e:
        rcal.calibrate(DATA, effects="no_such_effect")
    p = run_cli("calibrate", "--data", DATA, "--effects", "no_such_effect", check=False)
    assert p.returncode != 0 and e.value.message in p.stderr
    with pytest.raises(ValueError):
        rcal.export(DATA, "x.urdf", format="sdf")


def test_cases_residuals_and_plots(run_cli, tmp_path):
    c = cli_json(run_cli, "calibrate", "--data", DATA, "--cases", "3", "--samples", "200", "--json")
    r = rcal.calibrate(DATA, cases=3, samples=200)
    assert r.figure("cases_done") == c["protocol"]["cases"] == 3
    assert float("%.6f" % r.figure("cases_after_rmse_mean_mm")) == c["protocol"]["after_rmse_mean_mm"]
    mine, theirs = tmp_path / "py_res.csv", tmp_path / "cli_res.csv"
    rcal.calibrate(DATA, residuals=str(mine), plots=str(tmp_path / "py_plots"))
    run_cli("calibrate", "--data", DATA, "--residuals", str(theirs))
    assert mine.read_bytes() == theirs.read_bytes()
    assert (tmp_path / "py_plots" / "uncertainty_position.svg").exists()
    with pytest.raises(rcal.RcalError):
        rcal.calibrate(DATA, residuals=str(tmp_path / "x.csv"), jumps=True)  # as the CLI: not with jumps


def test_arrays_with_groups_equal_the_file(tmp_path):
    import csv
    rows = list(csv.DictReader(open(DATA)))
    q = [[float(r["q%d" % j]) for j in range(1, 7)] for r in rows]
    L = [float(r["L"]) for r in rows]
    group = [i // 20 for i in range(len(rows))]
    f = tmp_path / "g.csv"
    f.write_text("q1,q2,q3,q4,q5,q6,L,group\n" + "".join(
        ",".join(r["q%d" % j] for j in range(1, 7)) + ",%s,%d\n" % (r["L"], g) for r, g in zip(rows, group)))
    a, b = rcal.calibrate(q_deg=q, L_mm=L, group=group), rcal.calibrate(str(f))
    assert a.after == b.after and a.figure("groups") == b.figure("groups") == 30


def test_diagnosis_carries_the_nuisance(run_cli, tmp_path):
    # a 2 mm drift over the run: time_drift, a nuisance, is named, in the Next command, in effects and
    # nuisance, and calibrate takes the effects as they are
    lines = open(DATA).read().splitlines()
    n = len(lines) - 1
    rows = [lines[0]] + ["%s,%.4f" % (ln.rsplit(",", 1)[0], float(ln.rsplit(",", 1)[1]) + 2.0 * k / (n - 1))
                         for k, ln in enumerate(lines[1:])]
    drift = str(tmp_path / "drift.csv")
    open(drift, "w").write("\n".join(rows) + "\n")
    g = rcal.diagnose(drift)
    text = run_cli("diagnose", "--data", drift).stdout
    nxt = [ln[len("Next: "):] for ln in text.splitlines() if ln.startswith("Next: ")]
    assert g.effect == "time_drift" and nxt and g.next_command == nxt[0]
    assert "time_drift" in g.effects and g.nuisance == ["time_drift"]
    r = rcal.calibrate(drift, effects=",".join(g.effects))
    assert r.after.rmse_mm < 0.05  # 0.010 mm; without the drift fitted 0.44 mm
