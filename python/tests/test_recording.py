"""MATLAB recordings through the shared spec: files written by scipy.io.savemat (v5) and h5py (v7.3) read
back to the samples of their CSV twin, from Python and from the CLI; bad input names file, variable, fault."""
import os

import h5py
import numpy as np
import pytest
import scipy.io

import hwbounds
from conftest import TEST_DATA, cli_error, run_cli

N = 50


@pytest.fixture
def twin(tmp_path):
    """A recording as CSV (all digits) and its arrays."""
    rng = np.random.default_rng(3)
    rec = {"t": np.arange(N) * 0.1, "u": rng.normal(size=N), "y": rng.normal(size=N)}
    path = tmp_path / "rec.csv"
    with open(path, "w") as f:
        f.write("t,u,y\n")
        for i in range(N):
            f.write(",".join(repr(float(rec[k][i])) for k in ("t", "u", "y")) + "\n")
    return str(path), rec


def write_v73(path, variables):
    """A MATLAB v7.3 file as MATLAB writes it: HDF5 with a 512-byte user block holding the MAT header, every
    dataset transposed (MATLAB is column-major) with a null-terminated MATLAB_class attribute."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, array in variables.items():
            ds = f.create_dataset(name, data=np.atleast_2d(array))
            tid = h5py.h5t.C_S1.copy()
            tid.set_size(6)
            tid.set_strpad(h5py.h5t.STR_NULLTERM)
            attr = h5py.h5a.create(ds.id, b"MATLAB_class", tid, h5py.h5s.create(h5py.h5s.SCALAR))
            attr.write(np.array(b"double", dtype="S6"), mtype=tid)
    with open(path, "r+b") as f:
        f.write(b"MATLAB 7.3 MAT-file, written by the hwbounds tests".ljust(116) + b"\0" * 8 + b"\x00\x02IM")


def test_savemat_v5_reads_back_like_its_csv_twin(twin, tmp_path):
    csv, rec = twin
    mat = tmp_path / "rec_v5.mat"
    scipy.io.savemat(mat, {"time": rec["t"], "vir": rec["u"].reshape(N, 1), "qm": rec["y"]})
    got = hwbounds.read_recording(f"{mat}:u=vir,y=qm,t=time")
    want = hwbounds.read_recording(csv)
    for k in ("t", "u", "y"):
        np.testing.assert_array_equal(got[k], want[k])
        np.testing.assert_array_equal(got[k], rec[k])


def test_h5py_v73_reads_back_like_its_csv_twin(twin, tmp_path):
    csv, rec = twin
    mat = tmp_path / "rec_v73.mat"
    write_v73(mat, {"u": rec["u"], "y": rec["y"], "t": rec["t"]})
    got = hwbounds.read_recording(str(mat))  # variables named as the columns: no map needed
    for k in ("t", "u", "y"):
        np.testing.assert_array_equal(got[k], rec[k])


def write_h5py_as_a_user_would(path, variables, matlab_header, attribute="str"):
    """A v7.3 file as h5py users write one: numpy vectors as they are (1-D, not transposed), MATLAB_class set
    the h5py way -- "str": a variable-length UTF-8 string (h5py's default for a str), "bytes": null-padded fixed
    length, None: no attribute -- and, with matlab_header, MATLAB's 512-byte user block and header."""
    with h5py.File(path, "w", userblock_size=512 if matlab_header else 0) as f:
        for name, array in variables.items():
            ds = f.create_dataset(name, data=array)
            if attribute == "str":
                ds.attrs["MATLAB_class"] = "double"
            elif attribute == "bytes":
                ds.attrs["MATLAB_class"] = np.bytes_("double")
    if matlab_header:
        with open(path, "r+b") as f:
            f.write(b"MATLAB 7.3 MAT-file, written by h5py".ljust(116) + b"\0" * 8 + b"\x00\x02IM")


MODEL_JSON = ('{"type": "hammerstein_wiener", "input_nonlinearity": {"kind": "polynomial", '
              '"coefficients": [1, 0.2]}, "linear": {"a": [-0.6], "b": [0, 1]}}')


def assert_bad_mat_reported(mat, spec, message, tmp_path):
    """read_recording raises the message with the file name; the CLI says the same, with exit code 2 (diagnose
    reads u, y and optionally t, as read_recording's default)."""
    with pytest.raises(ValueError) as e:
        hwbounds.read_recording(f"{mat}{spec}")
    assert str(mat) in str(e.value)
    assert message in str(e.value)
    assert message in cli_error("diagnose", "--data", f"{mat}{spec}", "--validate", f"{mat}{spec}",
                                "--fit", "linear:1,1", "--out", tmp_path / "d")


@pytest.mark.parametrize("matlab_header", [True, False], ids=["with-header", "no-header"])
@pytest.mark.parametrize("attribute", ["str", "bytes", None], ids=["vlen-attr", "bytes-attr", "no-attr"])
def test_h5py_files_as_users_write_them_read_like_their_csv_twin(twin, tmp_path, matlab_header, attribute):
    csv, rec = twin
    mat = tmp_path / "user.mat"
    write_h5py_as_a_user_would(mat, {"vir": rec["u"], "qm": rec["y"], "time": rec["t"]}, matlab_header, attribute)
    got = hwbounds.read_recording(f"{mat}:u=vir,y=qm,t=time")
    want = hwbounds.read_recording(csv)
    for k in ("t", "u", "y"):
        np.testing.assert_array_equal(got[k], want[k])
    # The CLI reads it too: simulate on the .mat input writes the file it writes from the CSV (whose t column
    # it copies, as it copies the time the spec names).
    model = tmp_path / "model.json"
    model.write_text(MODEL_JSON)
    run_cli("simulate", "--model", model, "--input", csv, "--out", tmp_path / "from_csv.csv")
    run_cli("simulate", "--model", model, "--input", f"{mat}:u=vir,t=time", "--out", tmp_path / "from_mat.csv")
    assert (tmp_path / "from_mat.csv").read_text() == (tmp_path / "from_csv.csv").read_text()


@pytest.mark.parametrize("variables, spec, message", [
    pytest.param({"m": np.ones((3, 4)), "y": np.ones(3)}, ":u=m", "variable 'm' is a 4x3 double array; a recording variable "
                                                      "must be a vector", id="matrix"),
    pytest.param({"flags": np.array([True, False, True]), "y": np.ones(3)}, ":u=flags", "variable 'flags' is a 3x1 logical array; "
                                                                            "a recording variable must be numeric", id="bool"),
    pytest.param({"z": np.array([1 + 1j, 2, 3]), "y": np.ones(3)}, ":u=z", "variable 'z' is a 3x1 double array of complex numbers",
                 id="complex"),
    pytest.param({"u": np.array([1.0, np.inf]), "y": np.ones(2)}, "", "variable 'u' sample 2 is inf; every sample must be a finite",
                 id="inf"),
    pytest.param({"u": np.ones(4), "y": np.ones(3)}, "", "variable 'y' has 3 samples but 'u' has 4", id="lengths"),
    pytest.param({"vir": np.ones(4)}, ":u=vin,y=vir", "no variable 'vin'; the file has: vir (4x1 double)",
                 id="missing"),
])
def test_bad_h5py_input_names_file_variable_and_fault(tmp_path, variables, spec, message):
    mat = tmp_path / "bad.mat"
    with h5py.File(mat, "w") as f:
        for name, array in variables.items():
            f[name] = array
    assert_bad_mat_reported(mat, spec, message, tmp_path)


def test_hdf5_file_that_is_not_readable_names_the_file(tmp_path):
    mat = tmp_path / "cut.mat"
    write_h5py_as_a_user_would(mat, {"u": np.arange(1000.0), "y": np.arange(1000.0)}, True)
    data = mat.read_bytes()
    mat.write_bytes(data[:len(data) // 2])  # a truncated copy
    with pytest.raises(ValueError) as e:
        hwbounds.read_recording(str(mat))
    assert str(e.value).startswith(f"{mat}: ")


def test_committed_fixtures_match_their_csv_twin():
    want = hwbounds.read_recording(os.path.join(TEST_DATA, "recording.csv"))
    for name in ("recording_v5.mat", "recording_v73.mat", "recording_v73_nullpad.mat"):
        got = hwbounds.read_recording(os.path.join(TEST_DATA, name) + ":u=vir,y=qm,t=time")
        for k in ("t", "u", "y"):
            np.testing.assert_array_equal(got[k], want[k])


def test_cli_reads_the_mat_file_like_the_csv(twin, tmp_path):
    csv, rec = twin
    mat = tmp_path / "rec.mat"
    scipy.io.savemat(mat, {"vin": rec["u"]})
    model = tmp_path / "model.json"
    model.write_text('{"type": "hammerstein_wiener", "input_nonlinearity": {"kind": "polynomial", '
                     '"coefficients": [1, 0.2]}, "linear": {"a": [-0.6], "b": [0, 1]}}')
    run_cli("simulate", "--model", model, "--input", csv, "--out", tmp_path / "a.csv")
    run_cli("simulate", "--model", model, "--input", f"{mat}:u=vin", "--out", tmp_path / "b.csv")
    a = hwbounds.read_recording(str(tmp_path / "a.csv"), ["w"], [])
    b = hwbounds.read_recording(str(tmp_path / "b.csv"), ["w"], [])
    np.testing.assert_array_equal(a["w"], b["w"])


@pytest.mark.parametrize("variables, spec, message", [
    ({"vir": np.ones(5)}, ":u=vin,y=vir", "no variable 'vin'; the file has: vir (1x5 double)"),
    ({"m": np.ones((3, 4)), "y": np.ones(3)}, ":u=m", "variable 'm' is a 3x4 double array; a recording variable "
                                                      "must be a vector"),
    ({"u": "text", "y": np.ones(4)}, "", "variable 'u' is a 1x4 char array; a recording variable must be numeric"),
    ({"u": np.array([1.0, np.nan, 2.0]), "y": np.ones(3)}, "", "variable 'u' sample 2 is nan; every sample must be "
                                                             "a finite number"),
    ({"u": np.ones(4), "y": np.ones(3)}, "", "variable 'y' has 3 samples but 'u' has 4"),
    ({"u": np.ones(3)}, "", "no variable 'y' for the column y; name its variable as"),
])
def test_bad_mat_input_names_file_variable_and_fault(tmp_path, variables, spec, message):
    mat = tmp_path / "bad.mat"
    scipy.io.savemat(mat, variables)
    assert_bad_mat_reported(mat, spec, message, tmp_path)


def test_arrays_from_python_are_checked_like_recordings():
    model = {"linear": {"a": [-0.5], "b": [0, 1]}}
    with pytest.raises(ValueError, match=r"u: sample 3 is nan; every sample must be a finite number"):
        hwbounds.simulate(model, [1.0, 2.0, float("nan")])
    with pytest.raises(ValueError, match=r"u: expected a 1-D array \(a vector\), got shape \(2, 3\)"):
        hwbounds.simulate(model, np.ones((2, 3)))
    np.testing.assert_array_equal(hwbounds.simulate(model, np.ones((4, 1))), hwbounds.simulate(model, np.ones(4)))
    with pytest.raises(ValueError, match=r"ident: unknown key 'z'; expected u, y and optionally t"):
        hwbounds.diagnose({"u": np.ones(80), "y": np.ones(80), "z": np.ones(80)}, "x.csv", fit="linear:1,1")
    with pytest.raises(ValueError, match=r"ident: 'y' has 79 samples but 'u' has 80"):
        hwbounds.diagnose({"u": np.ones(80), "y": np.ones(79)}, "x.csv", fit="linear:1,1")
