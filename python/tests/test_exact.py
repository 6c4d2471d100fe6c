"""hwbounds.bounds(set="exact"): the exact set D after D^ss(n), as `hwbounds bounds --set exact --json`."""
import pytest

import hwbounds
from conftest import load_json, run_cli

from test_bounds import recording  # noqa: F401 (the fixture: a 60-sample prefix of the bundled recording)


def test_exact_set_as_the_cli(recording, tmp_path):
    path, rec = recording
    run_cli("bounds", "--data", path, "--noise-col", "noise_bound", "--horizon", 1, "--set", "exact",
            "--lp-budget", 3, "--sweeps", 1, "--threads", 2, "--quiet", "--json", tmp_path / "cli.json")
    cli = load_json(tmp_path / "cli.json")
    py = hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, set="exact", lp_budget=3, sweeps=1,
                         threads=2, source=path)
    assert py["set"] == cli["set"] == "exact"
    assert [iv["lower"]["value"] for iv in py["intervals"]] == [iv["lower"]["value"] for iv in cli["intervals"]]
    assert [iv["upper"]["value"] for iv in py["intervals"]] == [iv["upper"]["value"] for iv in cli["intervals"]]
    assert len(py["outer_set_intervals"]) == len(py["intervals"]) == 8
    # The exact set lies inside the outer set's box.
    for exact, outer in zip(py["intervals"], py["outer_set_intervals"]):
        assert exact["lower"]["value"] >= outer["lower"]["value"]
        assert exact["upper"]["value"] <= outer["upper"]["value"]
    assert "increases on the data range" in py["assumption"]["assumption"]


def test_unknown_set_is_a_value_error(recording):
    _, rec = recording
    with pytest.raises(ValueError, match="set 'exactly' unknown"):
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, set="exactly")


def test_unknown_lp_solver_is_a_value_error_before_any_work(recording):
    _, rec = recording
    with pytest.raises(ValueError, match="LP solver 'highs' unknown; expected one of: clp, glpk"):
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, set="exact", lp_solver="highs")


def test_target_ratio_below_one_is_a_value_error_before_any_work(recording):
    _, rec = recording
    with pytest.raises(ValueError, match="target_ratio must be >= 1"):
        hwbounds.bounds(rec["u"], rec["y"], rec["noise_bound"], horizon=1, set="exact", target_ratio=0.9)
