"""hwbounds.bounds: the same intervals as `hwbounds bounds --json` on the same inputs, the same validation
messages, progress reports, and a run stopped by Ctrl-C or by an exception leaves no worker process."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import scipy.io

import hwbounds
from conftest import CERONE_N300, cli_error, load_json, run_cli, without

SAMPLES = 60  # a prefix of the bundled recording: a few seconds per run at horizon 1, order 1


@pytest.fixture
def recording(tmp_path):
    data = np.loadtxt(CERONE_N300, delimiter=",", skiprows=1)[:SAMPLES]
    path = tmp_path / "rec.csv"
    with open(path, "w") as f:
        f.write("t,u,w,y,noise_bound\n")
        for row in data:
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    return str(path), {"u": data[:, 1], "y": data[:, 3], "noise_bound": data[:, 4]}


def test_default_order_is_the_minimal_order_as_in_the_cli(recording, tmp_path):
    path, rec = recording
    run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--params", "a1",
            "--solver", "csdp", "--threads", 2, "--quiet", "--json", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, parameters=["a1"], solver="csdp",
                         threads=2, source=path)
    assert py["order"] == cli["order"] == 1
    assert without(py, "timing") == without(cli, "timing")


def test_same_result_as_the_cli(recording, tmp_path):
    path, rec = recording
    run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 1, "--params", "a1,b1",
            "--solver", "csdp", "--threads", 2, "--quiet", "--json", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, parameters=["a1", "b1"],
                         solver="csdp", threads=2, source=path)
    assert [iv["parameter"] for iv in py["intervals"]] == ["a1", "b1"]
    assert py["intervals"][0]["lower"]["status"] == "guaranteed"
    assert py["intervals"][0]["lower"]["value"] < py["intervals"][0]["upper"]["value"]
    assert without(py, "timing") == without(cli, "timing")


def test_report_is_the_text_the_cli_prints(recording):
    path, rec = recording
    out, _ = run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 1,
                     "--params", "a1,b1", "--solver", "csdp", "--threads", 2, "--quiet")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, parameters=["a1", "b1"],
                         solver="csdp", threads=2, source=path, report=True)
    brief, full = py["brief_report"], py["full_report"]
    assert "\na1 " in brief and "\nb1 " in brief and "guaranteed" in brief, brief
    table = brief.split("\nWARNING")[0]  # warnings follow the run's summary in the full report
    assert table in out, (table, out)  # as the CLI prints it (a table holds no times)
    assert full.startswith(table) and "prior box (assumption): " in full, full
    assert "brief_report" not in hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1,
                                                 parameters=["a1"], solver="csdp", threads=2, source=path)


def test_cli_bounds_from_a_mat_file_equal_those_from_the_csv(recording, tmp_path):
    path, rec = recording
    mat = tmp_path / "rec.mat"
    scipy.io.savemat(mat, {"vir": rec["u"], "qm": rec["y"].reshape(-1, 1), "dy": rec["noise_bound"]})
    common = ("--noise-col", "noise_bound", "--horizon", 1, "--order", 1, "--params", "a1", "--solver", "csdp",
              "--threads", 2, "--quiet")
    run_cli("bounds", "--data", path, *common, "--json", tmp_path / "csv.json")
    run_cli("bounds", "--data", f"{mat}:u=vir,y=qm,noise_bound=dy", *common, "--json", tmp_path / "mat.json")
    assert without(load_json(tmp_path / "mat.json"), "timing", "data") == \
        without(load_json(tmp_path / "csv.json"), "timing", "data")


def test_validation_errors_carry_the_cli_message(recording):
    # Every option check against the CLI's: test_option_messages.py. Here: the exact texts, and the inputs.
    path, rec = recording
    args = ("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 1, "--quiet")
    with pytest.raises(ValueError) as e:
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, threads=-1)
    assert str(e.value) == "threads -1 is negative; give 0 (one job per core) or the number of jobs"
    assert cli_error(*args, "--threads", -1) == "--threads: " + str(e.value)
    with pytest.raises(ValueError) as e:
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], na=0, horizon=1, order=1)
    assert str(e.value) == "na must be >= 1" == cli_error(*args, "--na", 0)
    with pytest.raises(ValueError) as e:
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, solver="mosek")
    assert str(e.value) == ("solver 'mosek' unknown; expected auto (a backend per relaxation), csdp, sdpa, "
                            "dsdp") == cli_error(*args, "--solver", "mosek").removeprefix("--solver: ")
    with pytest.raises(ValueError, match=r"^order 0 is below the minimal order ceil\(\(n\+1\)/2\) = 1 of horizon 1; "):
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=0)
    with pytest.raises(ValueError, match=r"^noise_bound 0 is not a positive finite number"):
        hwbounds.bounds(rec["u"], rec["y"], 0.0, horizon=1, order=1)
    with pytest.raises(ValueError, match=r"^data: u has 60 samples but y has 59$"):
        hwbounds.bounds(rec["u"], rec["y"][:-1], 0.1, horizon=1, order=1)
    with pytest.raises(ValueError, match=r"^box: no parameter 'a9'; the parameters are: gamma2, gamma3, alpha2"):
        hwbounds.bounds(rec["u"], rec["y"], 0.1, horizon=1, order=1, box={"a9": (0, 1)})


def test_progress_reports_every_job(recording):
    _, rec = recording
    seen = []
    result = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, parameters=["a1"],
                             solver="csdp", threads=2, progress=seen.append, box=(-5, 5))
    assert seen and set(seen[0]) == {"phase", "done", "total", "from_cache", "elapsed_seconds", "eta_seconds"}
    assert seen[-1]["done"] == seen[-1]["total"]
    assert all(b["lo"] == -5 and b["hi"] == 5 for b in result["prior_box"])


def no_children_left():
    try:
        os.waitpid(-1, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


def test_exception_in_the_progress_callback_stops_the_run(recording):
    _, rec = recording

    def stop(p):
        if p["done"] >= 2:
            raise RuntimeError("stopped by the callback")

    with pytest.raises(RuntimeError, match="stopped by the callback"):
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, solver="csdp", threads=2,
                        progress=stop)
    assert no_children_left()


def test_ctrl_c_stops_a_long_run_promptly_and_cleanly():
    # Horizon 2, order 2 on all 300 samples takes many minutes; SIGINT arrives one second into it.
    script = textwrap.dedent(f"""
        import os, signal, threading, time
        import numpy as np
        import hwbounds
        d = np.loadtxt({CERONE_N300!r}, delimiter=",", skiprows=1)
        sent = []
        def progress(p):
            if not sent:
                sent.append(time.monotonic() + 1.0)
                threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT)).start()
        try:
            hwbounds.bounds(d[:, 1], d[:, 3], d[:, 4], horizon=2, order=2, threads=2, progress=progress)
            print("finished")
        except KeyboardInterrupt:
            try:
                os.waitpid(-1, os.WNOHANG)
                left = "yes"
            except ChildProcessError:
                left = "no"
            print(f"interrupted after {{time.monotonic() - sent[0]:.2f}} s, children left: {{left}}")
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert "interrupted after" in p.stdout and "children left: no" in p.stdout, p.stdout + p.stderr
    assert float(p.stdout.split("after ")[1].split(" s")[0]) < 3.0, p.stdout


def test_moment_witnesses_switch_as_in_the_cli(recording, tmp_path):
    # The relaxations are solved once, by the first CLI run into a run directory. The switch is not part of the run
    # cache's key, so the later runs read them back (any other setting that differed would solve them again, and
    # sdp_jobs would say so) and run only the work after them: the switch's stage.
    path, rec = recording
    run_dir = tmp_path / "run"
    args = ("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 2, "--params", "a1",
            "--solver", "csdp", "--threads", 2, "--no-moment-witnesses", "--quiet", "--run-dir", run_dir)
    run_cli(*args, "--json", tmp_path / "solved.json")
    run_cli(*args, "--json", tmp_path / "cli.json")
    solved, cli = load_json(tmp_path / "solved.json"), load_json(tmp_path / "cli.json")
    off = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=2, parameters=["a1"],
                          solver="csdp", threads=2, moment_witnesses=False, source=path, run_dir=str(run_dir))
    on = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=2, parameters=["a1"],
                         solver="csdp", threads=2, source=path, run_dir=str(run_dir))
    assert without(off, "timing") == without(cli, "timing")
    assert solved["counts"]["sdp_jobs"] > 0
    assert cli["counts"]["sdp_jobs"] == off["counts"]["sdp_jobs"] == on["counts"]["sdp_jobs"] == 0
    assert without(cli, "timing", "counts") == without(solved, "timing", "counts")  # read back as solved
    assert solved["counts"]["moment_witness_jobs"] == off["counts"]["moment_witness_jobs"] == 0
    assert on["counts"]["moment_witness_jobs"] > 0
    # The stage adds feasible points only: the bounds stay.
    for a, b in zip(on["intervals"], off["intervals"]):
        assert (a["lower"]["value"], a["upper"]["value"]) == (b["lower"]["value"], b["upper"]["value"])


def test_split_box_as_in_the_cli(recording, tmp_path):
    path, rec = recording
    run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 1, "--params", "a1",
            "--solver", "csdp", "--threads", 2, "--split", "a1=-0.5,1.8", "--quiet", "--json", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, parameters=["a1"],
                         solver="csdp", threads=2, split={"a1": [-0.5, 1.8]}, source=path)
    assert py["intervals"] == cli["intervals"]
    assert len(py["pieces"]) == 3
    assert [p["intervals"] for p in py["pieces"]] == [p["intervals"] for p in cli["pieces"]]
    assert [p["prior_box"][4]["hi"] for p in py["pieces"]] == [-0.5, 1.8, 10.0]


def test_auto_split_as_in_the_cli(recording, tmp_path):
    # Order 1 searches no feasible points: no round runs, and both say why (the rounds: box_split_test).
    path, rec = recording
    run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 1, "--params", "a1",
            "--solver", "csdp", "--threads", 2, "--auto-split", 1, "--quiet", "--json", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1, parameters=["a1"],
                         solver="csdp", threads=2, auto_split=1, source=path)
    assert py["intervals"] == cli["intervals"]
    assert [r["intervals"] for r in py["auto_split"]["rounds"]] == [r["intervals"] for r in cli["auto_split"]["rounds"]]
    assert py["auto_split"]["stopped"] == cli["auto_split"]["stopped"] == \
        "no interval has a range of certified feasible points to cut beyond"
    assert "auto_split" not in hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=1,
                                               parameters=["a1"], solver="csdp", threads=2, source=path)


def test_row_block_order_and_endpoint_refinements_as_in_the_cli(recording, tmp_path):
    path, rec = recording
    run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--order", 2, "--params", "a1",
            "--solver", "csdp", "--threads", 2, "--row-block-order", 0, "--endpoint-refinements", 1, "--quiet",
            "--json", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, order=2, parameters=["a1"],
                         solver="csdp", threads=2, row_block_order=0, endpoint_refinements=1, source=path)
    assert without(py, "timing") == without(cli, "timing")
    assert "mixed" in py["relaxation"], py["relaxation"]  # order 2 with data-row blocks of localizing order 0
    assert py["endpoints_refined"]["jobs"] > 0
