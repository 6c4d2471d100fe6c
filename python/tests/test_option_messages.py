"""The Python functions check their options as the CLI checks the same options: for every bad value below,
the function raises ValueError and the CLI, run on the same inputs, exits with code 2 and prints that
exact message (naming the option, with its own spelling where it has one)."""
import json

import numpy as np
import pytest

import hwbounds
from conftest import CERONE_N300, run_cli

SAMPLES = 60


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    data = np.loadtxt(CERONE_N300, delimiter=",", skiprows=1)[:SAMPLES]
    path = tmp_path_factory.mktemp("rec") / "rec.csv"
    with open(path, "w") as f:
        f.write("u,y\n")
        for row in data:
            f.write(f"{row[1]!r},{row[3]!r}\n")
    return str(path), data[:, 1], data[:, 3]


def cli_stderr(*args):
    """The CLI's stderr for bad input: exit code 2, and nothing computed."""
    _, err = run_cli(*args, expect_rc=2)
    return err


def expect_same_message(call, cli_args, option):
    with pytest.raises(ValueError) as e:
        call()
    message = str(e.value)
    err = cli_stderr(*cli_args)
    assert message in err, f"Python: {message!r}\nCLI: {err!r}"
    assert option in err, f"the CLI's message does not name {option}: {err!r}"


# (keyword arguments of hwbounds.bounds, the CLI's arguments for the same value, the CLI option named)
BOUNDS_CASES = [
    ({"order": 1}, ["--order", 1], "--order"),  # below the minimal order 2 of horizon 2
    ({"order": 0}, ["--order", 0], "--order"),
    ({"order": -3}, ["--order", -3], "--order"),
    ({"order": 21}, ["--order", 21], "--order"),
    ({"horizon": 0}, ["--horizon", 0], "--horizon"),
    ({"horizon": 21}, ["--horizon", 21], "--horizon"),
    ({"solver": "mosek"}, ["--solver", "mosek"], "--solver"),
    ({"executor": "cluster"}, ["--executor", "cluster"], "--executor"),
    ({"threads": -1}, ["--threads", -1], "--threads"),
    ({"contraction_passes": -1}, ["--contract-passes", -1], "--contract-passes"),
    ({"contraction_passes": 11}, ["--contract-passes", 11], "--contract-passes"),
    ({"row_block_order": -2}, ["--row-block-order", -2], "--row-block-order"),
    ({"stopped_short_refinements": -1}, ["--stopped-short-refinements", -1], "--stopped-short-refinements"),
    ({"endpoint_refinements": -1}, ["--endpoint-refinements", -1], "--endpoint-refinements"),
    ({"endpoint_refinements": 11}, ["--endpoint-refinements", 11], "--endpoint-refinements"),
    ({"noise_bound": -0.5}, ["--noise-bound", -0.5], "--noise-bound"),
    ({"noise_bound": 0.0}, ["--noise-bound", 0], "--noise-bound"),
    ({"noise_bound": float("inf")}, ["--noise-bound", "inf"], "--noise-bound"),
    ({"na": 0}, ["--na", 0], "na"),
    # The prior box: Python's pairs and the CLI's text are checked by one library check (dss::ValidBoxEntry).
    ({"box": (5, 1)}, ["--box", "5,1"], "--box"),
    ({"box": {"a1": (3, -3)}}, ["--box", "a1=3,-3"], "--box"),
    ({"box": {"zz": (0, 1)}}, ["--box", "zz=0,1"], "--box"),
    # The cuts of a split box: one library check (dss::ValidBoxCuts).
    ({"split": {"a1": 10}}, ["--split", "a1=10"], "--split"),
    ({"split": {"zz": 0}}, ["--split", "zz=0"], "--split"),
    ({"split": {"a1": [1, 1]}}, ["--split", "a1=1,1"], "--split"),
    # Automatic cuts: dss::ValidAutoSplitRounds.
    ({"auto_split": 6}, ["--auto-split", 6], "--auto-split"),
    ({"auto_split": -1}, ["--auto-split", -1], "--auto-split"),
]


@pytest.mark.parametrize("kwargs, cli_args, option", BOUNDS_CASES, ids=[str(c[0]) for c in BOUNDS_CASES])
def test_bounds_messages_are_the_clis(recording, kwargs, cli_args, option):
    path, u, y = recording
    py = {"executor": "inprocess", **kwargs}
    noise_bound = py.pop("noise_bound", 0.1)
    cli = ["bounds", "--data", path, "--params", "a1", "--quiet", *cli_args]
    if "--noise-bound" not in cli_args:
        cli += ["--noise-bound", 0.1]
    if "--executor" not in cli_args:
        cli += ["--executor", "inprocess"]
    expect_same_message(lambda: hwbounds.bounds(u, y, noise_bound, parameters=["a1"], source=path, **py), cli, option)


POP_PROBLEM = {"variables": ["x"], "minimize": "x^4 - x^2", "box": {"x": [-1, 1]}}


@pytest.mark.parametrize("kwargs, cli_args, option", [
    ({"order": 0}, ["--order", 0], "--order"),
    ({"order": -1}, ["--order", -1], "--order"),
    ({"order": 1}, ["--order", 1], "--order"),  # below the problem's minimal order 2
    ({"solver": "mosek"}, ["--solver", "mosek"], "--solver"),
])
def test_pop_messages_are_the_clis(tmp_path, kwargs, cli_args, option):
    problem = tmp_path / "p.json"
    problem.write_text(json.dumps(POP_PROBLEM))
    expect_same_message(lambda: hwbounds.pop(str(problem), **kwargs), ["pop", problem, *cli_args], option)


def test_simulate_refuses_an_unstable_model_as_the_cli(tmp_path):
    model = tmp_path / "unstable.json"
    model.write_text('{"type": "hammerstein_wiener", "linear": {"a": [-1.1], "b": [0, 1]}}')
    rec = tmp_path / "u.csv"
    rec.write_text("u\n" + "\n".join(["1"] * 20) + "\n")
    expect_same_message(lambda: hwbounds.simulate(str(model), np.ones(20)),
                        ["simulate", "--model", model, "--input", rec, "--out", tmp_path / "w.csv"],
                        "--allow-unstable")
    # Allowed, it runs on both sides.
    run_cli("simulate", "--model", model, "--input", rec, "--allow-unstable", "--out", tmp_path / "w.csv")
    assert hwbounds.simulate(str(model), np.ones(20), allow_unstable=True).size == 20


def test_diagnose_needs_one_nominal_model_as_the_cli(recording, tmp_path):
    path, _, _ = recording
    expect_same_message(lambda: hwbounds.diagnose(path, path),
                        ["diagnose", "--data", path, "--validate", path, "--out", tmp_path / "d"], "--fit")


def test_diagnose_reads_a_csv_spec_as_the_cli(recording, tmp_path):
    path, _, _ = recording
    expect_same_message(lambda: hwbounds.diagnose(f"{path}:u=vin", path, fit="linear:1,1"),
                        ["diagnose", "--data", f"{path}:u=vin", "--validate", path, "--fit", "linear:1,1",
                         "--out", tmp_path / "d"], "vin")


def test_esmaeilani_messages_are_the_clis(recording, tmp_path):
    path, _, _ = recording
    for kwargs, cli_args, option in [({"order": 0}, ["--order", 0], "order"),
                                     ({"grid_f": 1}, ["--grid-f", 1], "grid")]:
        expect_same_message(lambda: hwbounds.esmaeilani_estimate(path, **kwargs),
                            ["esmaeilani", "--data", path, *cli_args, "--out", tmp_path / "m.json"], option)


@pytest.fixture(scope="module")
def step_plan(tmp_path_factory):
    d = tmp_path_factory.mktemp("brouri")
    run_cli("brouri", "plan", "steps", "--levels-up", "-0.6,-0.3,0,0.3,0.6,0.9,1.2",
            "--levels-down", "1.0,0.6,0.2,-0.2,-0.6,-1.0,-1.4", "--reset", -0.9, "--settling-time", 40,
            "--average-samples", 50, "--out-dir", d)
    run_cli("brouri", "simulate", "--plan", d / "plan.json", "--seed", 3)
    return str(d / "plan.json"), d


@pytest.mark.parametrize("kwargs, cli_args, option", [
    ({"degree": 16}, ["--degree", 16], "degree"),
    ({"max_degree": 0}, ["--max-degree", 0], "max degree"),
    ({"harmonic": 16}, ["--harmonic", 16], "harmonic"),
    ({"plateau_sigmas": 0}, ["--plateau-sigmas", 0], "plateau_sigmas"),
])
def test_brouri_messages_are_the_clis(step_plan, kwargs, cli_args, option):
    plan, d = step_plan
    expect_same_message(lambda: hwbounds.brouri_estimate(plan, **kwargs),
                        ["brouri", "estimate", "--plan", plan, *cli_args, "--out", d / "r.json"], option)


def test_brouri_rejects_what_is_not_a_plan_as_the_cli(tmp_path):
    plan = tmp_path / "plan.json"
    plan.write_text('{"method": "esmaeilani"}')
    expect_same_message(lambda: hwbounds.brouri_estimate(str(plan)),
                        ["brouri", "estimate", "--plan", plan, "--out", tmp_path / "r.json"], str(plan))
