"""pop, simulate, scenario, diagnose, esmaeilani_estimate and brouri_estimate from Python give the CLI's JSON
on the same inputs, and their option errors are ValueErrors with the CLI's message."""
import json
import os

import numpy as np
import pytest
import scipy.io

import hwbounds
from conftest import SOURCE_DIR, cli_error, esmaeilani_signals, load_json, run_cli, without

PROBLEM = os.path.join(SOURCE_DIR, "paper_examples", "problems", "gloptipoly_constrained.json")
MODEL = {"type": "hammerstein_wiener", "name": "test",
         "input_nonlinearity": {"kind": "polynomial", "coefficients": [1, 0.3]},
         "linear": {"a": [-1.2, 0.5], "b": [0, 0.5, 0.3], "delay": 0},
         "output_nonlinearity": {"kind": "identity"}}


def write_csv(path, columns):
    names = list(columns)
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in zip(*columns.values()):
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    return str(path)


def test_pop_equals_cli_json(capfd):
    out, _ = run_cli("pop", PROBLEM, "--order", 2, "--solver", "csdp", "--json")
    cli = json.loads(out)
    capfd.readouterr()
    assert hwbounds.pop(PROBLEM, 2, "csdp") == cli
    # The module's CSDP options replaced libsdp.so's defaults (sdp/CMakeLists.txt), which print an iteration log.
    assert capfd.readouterr().out == ""
    with open(PROBLEM) as f:
        assert hwbounds.pop(json.load(f), order=2, solver="csdp") == cli
    with pytest.raises(ValueError) as e:
        hwbounds.pop({"variables": ["x"], "minimize": "x^4", "box": {"x": [-1, 1]}}, order=1)
    assert str(e.value) == "order 1 is below this problem's minimal order 2; leave the order unset for the minimal order"


def test_simulate_equals_cli(tmp_path):
    u = np.sin(np.arange(200) * 0.1)
    rec = write_csv(tmp_path / "u.csv", {"u": u})
    model = tmp_path / "model.json"
    model.write_text(json.dumps(MODEL))
    run_cli("simulate", "--model", model, "--input", rec, "--out", tmp_path / "w.csv")
    cli_w = hwbounds.read_recording(str(tmp_path / "w.csv"), ["w"], [])["w"]  # written with 12 digits
    np.testing.assert_allclose(hwbounds.simulate(MODEL, u), cli_w, rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(hwbounds.simulate(str(model), u), hwbounds.simulate(MODEL, u))


@pytest.fixture(scope="module")
def backlash_pair(tmp_path_factory):
    d = tmp_path_factory.mktemp("scenario")
    run_cli("scenario", "--hidden-effect", "backlash", "--samples", 600, "--seed", 2, "--out", d / "s")
    return str(d / "s_ident.csv"), str(d / "s_valid.csv"), d


def test_scenario_equals_cli(backlash_pair):
    ident, valid, _ = backlash_pair
    sc = hwbounds.scenario("backlash", samples=600, seed=2)
    for name, path in (("ident", ident), ("valid", valid)):
        cli = hwbounds.read_recording(path)
        for k in ("t", "u", "y"):
            np.testing.assert_array_equal(sc[name][k], cli[k])


def test_diagnose_equals_cli_report_also_from_a_mat_file(backlash_pair):
    ident, valid, d = backlash_pair
    run_cli("diagnose", "--data", ident, "--validate", valid, "--fit", "linear:2,2", "--out", d / "report")
    cli = without(load_json(d / "report" / "report.json"), "run_time_seconds")
    py = hwbounds.diagnose(ident, valid, fit="linear:2,2")
    assert without(py, "run_time_seconds") == cli
    # The same recordings from one MATLAB file, each signal under its own name.
    a, b = hwbounds.read_recording(ident), hwbounds.read_recording(valid)
    mat = d / "pair.mat"
    scipy.io.savemat(mat, {"u_id": a["u"], "y_id": a["y"], "t_id": a["t"],
                           "u_val": b["u"], "y_val": b["y"], "t_val": b["t"]})
    from_mat = hwbounds.diagnose(f"{mat}:u=u_id,y=y_id,t=t_id", f"{mat}:u=u_val,y=y_val,t=t_val", fit="linear:2,2")
    assert from_mat["verdict"] == cli["verdict"]
    assert from_mat["findings"] == cli["findings"]
    # Arrays in, too.
    from_arrays = hwbounds.diagnose(a, (b["u"], b["y"]), fit="linear:2,2")
    assert from_arrays["findings"] == cli["findings"]


def test_diagnose_option_errors_are_the_clis(backlash_pair):
    ident, valid, d = backlash_pair
    with pytest.raises(ValueError) as e:
        hwbounds.diagnose(ident, valid, fit="linear:2,2", holdout_fraction=0.9)
    assert str(e.value) == cli_error("diagnose", "--data", ident, "--validate", valid, "--fit", "linear:2,2",
                                     "--holdout", 0.9, "--out", d / "x")
    with pytest.raises(ValueError) as e:
        hwbounds.diagnose(ident, valid, fit="linear:2,2", effects=["backlash@output"])
    assert str(e.value) == cli_error("diagnose", "--data", ident, "--validate", valid, "--fit", "linear:2,2",
                                     "--effects", "backlash@output", "--out", d / "x")
    with pytest.raises(ValueError, match="exactly one of model"):
        hwbounds.diagnose(ident, valid)


@pytest.fixture(scope="module")
def esmaeilani_segments(tmp_path_factory):
    d = tmp_path_factory.mktemp("esm")
    paths = [write_csv(d / f"seg{i}.csv", {"u": u, "y": y}) for i, (u, y) in enumerate(esmaeilani_signals(MODEL))]
    return paths, d


# f and g^-1 normalised by two known points each (the true f(u) = u + 0.3 u^2 and g^-1(y) = y).
KNOWN = {"f": {"points": [[0, 0], [1, 1.3]]}, "g_inverse": {"points": [[0, 0], [1, 1]]}}


def test_esmaeilani_equals_cli_model(esmaeilani_segments):
    paths, d = esmaeilani_segments
    (d / "known.json").write_text(json.dumps(KNOWN))
    run_cli("esmaeilani", "--data", *paths, "--order", 2, "--grid-f", 5, "--grid-g", 5, "--max-iterations", 15,
            "--constraints", d / "known.json", "--validate", paths[1], "--out", d / "model.json")
    cli = load_json(d / "model.json")
    py = hwbounds.esmaeilani_estimate(paths, order=2, grid_f=5, grid_g=5, max_iterations=15, constraints=KNOWN,
                                      validate=[paths[1]])
    assert py["model"] == cli
    assert py["summary"]["status"] in ("converged", "max_iterations")
    assert py["validation"][0]["fit_percent"] > 50
    segs = [hwbounds.read_recording(p, ["u", "y"], []) for p in paths]
    assert hwbounds.esmaeilani_estimate(segs, order=2, grid_f=5, grid_g=5, max_iterations=15,
                                        constraints=str(d / "known.json"))["model"] == cli
    with pytest.raises(ValueError) as e:
        hwbounds.esmaeilani_estimate(paths, order=0)
    assert str(e.value) == cli_error("esmaeilani", "--data", *paths, "--order", 0, "--out", d / "x.json")


def test_brouri_steps_equal_cli(tmp_path):
    run_cli("brouri", "plan", "steps", "--levels-up", "-0.6,-0.3,0,0.3,0.6,0.9,1.2",
            "--levels-down", "1.0,0.6,0.2,-0.2,-0.6,-1.0,-1.4", "--reset", -0.9, "--settling-time", 40,
            "--average-samples", 50, "--out-dir", tmp_path)
    plan = str(tmp_path / "plan.json")
    run_cli("brouri", "simulate", "--plan", plan, "--seed", 3)
    run_cli("brouri", "estimate", "--plan", plan, "--out", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    assert hwbounds.brouri_estimate(plan) == cli
    rec = hwbounds.read_recording(str(tmp_path / "steps.csv"), ["y"], ["u", "t"])
    assert hwbounds.brouri_estimate(load_json(plan), rec) == cli
    rec["t"] = rec["t"] * 2
    with pytest.raises(ValueError, match=r"recordings\[0\]: row 2: time step 1 differs from the planned sample time"):
        hwbounds.brouri_estimate(plan, rec)
    with pytest.raises(ValueError, match="descending-border method 'middle' must be"):
        hwbounds.brouri_estimate(plan, down_border="middle")
