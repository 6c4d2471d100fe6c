"""`FILE.mat:...,t=NAME` names a recording's time in every command that reads a recording (bounds, simulate,
esmaeilani, diagnose, brouri estimate) and in the Python functions that take recordings. The time is checked
everywhere: as long as u and y and strictly increasing, or an error naming the file and the variable; the
commands that run on the sample index (bounds, esmaeilani) use it for nothing else, simulate writes it as its
output's t, diagnose and brouri use it as before."""
import json

import numpy as np
import pytest
import scipy.io

import hwbounds
from conftest import CERONE_N300, cli_error, esmaeilani_signals, load_json, run_cli, without

N = 60
MODEL = {"type": "hammerstein_wiener", "input_nonlinearity": {"kind": "polynomial", "coefficients": [1, 0.3]},
         "linear": {"a": [-1.2, 0.5], "b": [0, 0.5, 0.3], "delay": 0}, "output_nonlinearity": {"kind": "identity"}}


def time_variants(n, dt=0.01):
    """The good time vector of n samples and two bad ones: one sample short, and one that steps back."""
    t = np.arange(n) * dt
    t_back = t.copy()
    t_back[4] = t_back[2]
    return {"time": t, "tshort": t[:-1], "tback": t_back}


@pytest.fixture(scope="module")
def cerone_mat(tmp_path_factory):
    """A prefix of the bundled recording as CSV (t, u, y) and as .mat (vir, qm and the time variants)."""
    d = tmp_path_factory.mktemp("time")
    data = np.loadtxt(CERONE_N300, delimiter=",", skiprows=1)[:N]
    u, y = data[:, 1], data[:, 3]
    mat = d / "rec.mat"
    scipy.io.savemat(mat, {"vir": u, "qm": y, **time_variants(N)})
    csv = d / "rec.csv"
    with open(csv, "w") as f:
        f.write("u,y\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(u, y)))
    return str(mat), str(csv), d


BAD_TIME = [("tshort", "variable 'tshort' has 59 samples but 'vir' has 60; the variables of one recording must "
                       "have the same length"),
            ("tback", "variable 'tback' sample 5 is 0.02 after 0.03; the time t of a recording must increase "
                      "strictly from sample to sample")]


def test_bounds_accepts_t_and_its_result_is_that_without_it(cerone_mat):
    mat, csv, d = cerone_mat
    common = ("--noise-bound", 0.3, "--horizon", 1, "--order", 1, "--params", "a1", "--solver", "csdp",
              "--threads", 2, "--quiet")
    run_cli("bounds", "--data", f"{mat}:u=vir,y=qm,t=time", *common, "--json", d / "with_t.json")
    run_cli("bounds", "--data", csv, *common, "--json", d / "csv.json")
    assert without(load_json(d / "with_t.json"), "timing", "data") == without(load_json(d / "csv.json"), "timing",
                                                                              "data")
    for variable, message in BAD_TIME:
        err = cli_error("bounds", "--data", f"{mat}:u=vir,y=qm,t={variable}", *common)
        assert err == f"{mat}: {message}"


def test_simulate_writes_the_inputs_time(cerone_mat, tmp_path):
    mat, _, _ = cerone_mat
    model = tmp_path / "model.json"
    model.write_text(json.dumps(MODEL))
    run_cli("simulate", "--model", model, "--input", f"{mat}:u=vir,t=time", "--out", tmp_path / "w.csv")
    out = hwbounds.read_recording(str(tmp_path / "w.csv"), ["t", "u", "w"], [])
    np.testing.assert_allclose(out["t"], time_variants(N)["time"], rtol=1e-11)
    # Without a time, t is the sample index, as before.
    run_cli("simulate", "--model", model, "--input", f"{mat}:u=vir", "--out", tmp_path / "w0.csv")
    np.testing.assert_array_equal(hwbounds.read_recording(str(tmp_path / "w0.csv"), ["t"], [])["t"], np.arange(N))
    for variable, message in BAD_TIME:
        err = cli_error("simulate", "--model", model, "--input", f"{mat}:u=vir,t={variable}", "--out",
                        tmp_path / "bad.csv")
        assert err == f"{mat}: {message}"
    assert not (tmp_path / "bad.csv").exists()


@pytest.fixture(scope="module")
def esmaeilani_mats(tmp_path_factory):
    d = tmp_path_factory.mktemp("esm_time")
    paths = []
    for i, (u, y) in enumerate(esmaeilani_signals(MODEL)):
        path = d / f"seg{i}.mat"
        scipy.io.savemat(path, {"vin": u, "vout": y, **time_variants(u.size)})
        paths.append(str(path))
    return paths, d


# f and g^-1 normalised by two known points each (the true f(u) = u + 0.3 u^2 and g^-1(y) = y).
KNOWN = {"f": {"points": [[0, 0], [1, 1.3]]}, "g_inverse": {"points": [[0, 0], [1, 1]]}}


def test_esmaeilani_accepts_t_from_the_cli_and_from_python(esmaeilani_mats):
    paths, d = esmaeilani_mats
    (d / "known.json").write_text(json.dumps(KNOWN))
    opts = ("--order", 2, "--grid-f", 5, "--grid-g", 5, "--max-iterations", 10, "--constraints", d / "known.json")
    run_cli("esmaeilani", "--data", *[f"{p}:u=vin,y=vout,t=time" for p in paths], *opts, "--out", d / "t.json")
    run_cli("esmaeilani", "--data", *[f"{p}:u=vin,y=vout" for p in paths], *opts, "--out", d / "no_t.json")
    with_t, no_t = load_json(d / "t.json"), load_json(d / "no_t.json")
    assert without(with_t, "esmaeilani") == without(no_t, "esmaeilani")  # the record names the segments
    py = hwbounds.esmaeilani_estimate([f"{p}:u=vin,y=vout,t=time" for p in paths], order=2, grid_f=5, grid_g=5,
                                      max_iterations=10, constraints=KNOWN)
    assert without(py["model"], "esmaeilani") == without(with_t, "esmaeilani")
    for variable, message in BAD_TIME:
        spec = f"{paths[0]}:u=vin,y=vout,t={variable}"
        message = message.replace("'vir' has 60", "'vin' has 200").replace("59 samples", "199 samples")
        assert cli_error("esmaeilani", "--data", spec, *opts, "--out", d / "bad.json") == f"{paths[0]}: {message}"
        with pytest.raises(ValueError) as e:
            hwbounds.esmaeilani_estimate(spec, order=2)
        assert str(e.value) == f"{paths[0]}: {message}"
    # Arrays from Python: the same check on t.
    rec = hwbounds.read_recording(f"{paths[0]}:u=vin,y=vout")
    with pytest.raises(ValueError, match=r"^segments\[0\]: t sample 5 is 0.02 after 0.03; the time t"):
        hwbounds.esmaeilani_estimate([{**rec, "t": time_variants(200)["tback"]}], order=2)


def test_diagnose_checks_t_with_the_same_message(tmp_path):
    sc = hwbounds.scenario("none", samples=300, seed=4)
    mat = tmp_path / "pair.mat"
    ident = sc["ident"]
    scipy.io.savemat(mat, {"u": ident["u"], "y": ident["y"], **time_variants(ident["u"].size)})
    for variable, message in BAD_TIME:
        spec = f"{mat}:u=u,y=y,t={variable}"
        message = message.replace("'vir' has 60", "'u' has 300").replace("59 samples", "299 samples")
        err = cli_error("diagnose", "--data", spec, "--validate", spec, "--fit", "linear:1,1", "--out", tmp_path / "d")
        assert err == f"{mat}: {message}"
        with pytest.raises(ValueError) as e:
            hwbounds.diagnose(spec, spec, fit="linear:1,1")
        assert str(e.value) == err


def test_brouri_reads_a_plan_recording_with_t(tmp_path):
    run_cli("brouri", "plan", "steps", "--levels-up", "-0.6,-0.3,0,0.3,0.6,0.9,1.2",
            "--levels-down", "1.0,0.6,0.2,-0.2,-0.6,-1.0,-1.4", "--reset", -0.9, "--settling-time", 40,
            "--average-samples", 50, "--out-dir", tmp_path)
    plan_path = tmp_path / "plan.json"
    run_cli("brouri", "simulate", "--plan", plan_path, "--seed", 3)
    run_cli("brouri", "estimate", "--plan", plan_path, "--out", tmp_path / "csv.json")
    rec = hwbounds.read_recording(str(tmp_path / "steps.csv"), ["y"], ["u", "t"])
    scipy.io.savemat(tmp_path / "steps.mat", {"vin": rec["u"], "qm": rec["y"], "time": rec["t"]})
    plan = load_json(plan_path)
    plan["file"] = "steps.mat:y=qm,u=vin,t=time"
    plan_path.write_text(json.dumps(plan))
    run_cli("brouri", "estimate", "--plan", plan_path, "--out", tmp_path / "mat.json")
    assert load_json(tmp_path / "mat.json") == load_json(tmp_path / "csv.json")
    assert hwbounds.brouri_estimate(str(plan_path)) == load_json(tmp_path / "csv.json")
