"""The committed Tables I-III outputs (paper_examples/results) hold every property when re-checked from their JSON
by paper_examples/check_tables.py, their witnesses re-certify, the grid page is current, and the checker catches
each kind of broken table."""
import json
import os
import shutil
import subprocess
import sys

from conftest import CLI, SOURCE_DIR

CHECKER = os.path.join(SOURCE_DIR, "paper_examples", "check_tables.py")
RESULTS = os.path.join(SOURCE_DIR, "paper_examples", "results")


def check(*args):
    p = subprocess.run([sys.executable, CHECKER, "--hwbounds", CLI, *map(str, args)], capture_output=True,
                       text=True, timeout=240)
    return p.returncode, p.stdout + p.stderr


def test_every_committed_table_holds_and_its_witnesses_recertify(tmp_path):
    rc, out = check(RESULTS, "--grid", tmp_path / "grid.md")
    assert rc == 0, out
    assert "every property holds" in out and "re-certified" in out, out
    with open(os.path.join(RESULTS, "grid.md")) as committed:
        assert (tmp_path / "grid.md").read_text() == committed.read(), \
            "paper_examples/results/grid.md is stale: regenerate it with the command on its first lines"


def broken_copy(tmp_path, edit):
    """A copy of one committed two-horizon, two-order table with `edit(table)` applied."""
    source = os.path.join(RESULTS, "cerone_n23_snr45_delta3", "tables.json")
    with open(source) as f:
        table = json.load(f)
    edit(table)
    folder = tmp_path / "broken"
    folder.mkdir()
    (folder / "tables.json").write_text(json.dumps(table))
    return folder / "tables.json"


def row(table, n, parameter):
    case = next(c for c in table["cases"] if c["n"] == n)
    return next(r for r in case["rows"] if r["parameter"] == parameter)


def test_a_bound_excluding_the_truth_is_reported(tmp_path):
    def edit(t):
        row(t, 2, "a1")["outer"]["3"]["lower"] = 1.81  # the truth is 1.8
    rc, out = check(broken_copy(tmp_path, edit), "--no-witnesses")
    assert rc == 1 and "n = 2: a1: truth 1.8 outside order-3 outer" in out and "(Property 2)" in out, out


def test_a_higher_order_wider_than_the_lower_is_reported(tmp_path):
    def edit(t):
        row(t, 2, "b1")["outer"]["3"]["upper"] = 9.0
    rc, out = check(broken_copy(tmp_path, edit), "--no-witnesses")
    assert rc == 1 and "b1: order-3 outer" in out and "(Property 3)" in out, out


def test_a_longer_horizon_wider_than_the_shorter_is_reported(tmp_path):
    def edit(t):
        row(t, 3, "gamma3")["outer"]["2"]["lower"] = -1.0
        row(t, 3, "gamma3")["outer"]["3"]["lower"] = -1.0
    rc, out = check(broken_copy(tmp_path, edit), "--no-witnesses")
    assert rc == 1 and "n = 3: gamma3: order-2 outer" in out and "(Property 4)" in out, out


def test_a_bound_excluding_a_witness_of_another_run_is_reported(tmp_path):
    # the n = 2, 45 dB runs of cerone_n2_snr45_delta3 have witnesses below this a2 lower bound
    def edit(t):
        for n in (2, 3):
            r = row(t, n, "a2")
            for order in ("2", "3"):
                r["outer"][order]["lower"] = r["inner"]["lower"] + 1e-3
            r["inner"]["lower"] += 1e-3
            r["inner"]["lower_witness"]["point"][5] += 1e-3
    broken = broken_copy(tmp_path, edit)
    other = tmp_path / "other"
    shutil.copytree(os.path.join(RESULTS, "cerone_n2_snr45_delta3"), other)
    rc, out = check(broken, other / "tables.json", "--no-witnesses")
    assert rc == 1 and "excludes" in out and f"the a2 lower witness of n = 2 in {other / 'tables.json'}" in out, out


def test_a_witness_outside_the_set_fails_recertification(tmp_path):
    def edit(t):
        r = row(t, 2, "alpha2")
        r["inner"]["upper_witness"]["point"][2] += 0.5  # beyond the true hull: outside D^ss(2)
        r["inner"]["upper"] += 0.5
        for order in ("2", "3"):
            r["outer"][order]["upper"] += 0.5
    rc, out = check(broken_copy(tmp_path, edit))
    assert rc == 1 and "alpha2: inner upper witness outside D^ss(2)" in out, out


SPLIT_RUN = "cerone_n2_snr31_delta3_seed3_refined"  # its folder holds a `hwbounds bounds --split gamma2=0` result


def broken_split(tmp_path, edit):
    """A copy of the committed split run's folder with `edit(split)` applied to its split result."""
    folder = tmp_path / "split"
    shutil.copytree(os.path.join(RESULTS, SPLIT_RUN), folder)
    with open(folder / "split_gamma2.json") as f:
        split = json.load(f)
    edit(split)
    (folder / "split_gamma2.json").write_text(json.dumps(split))
    return folder / "tables.json"


def interval(result, parameter):
    return next(iv for iv in result["intervals"] if iv["parameter"] == parameter)


def test_a_split_that_is_not_the_hull_of_its_pieces_is_reported(tmp_path):
    def edit(split):
        interval(split, "gamma3")["upper"]["value"] += 0.5
    rc, out = check(broken_split(tmp_path, edit), "--no-witnesses")
    assert rc == 1 and "gamma3: the split's [" in out and "is not the hull" in out, out


def test_split_pieces_that_do_not_tile_its_box_are_reported(tmp_path):
    def edit(split):
        del split["pieces"][0]  # the half gamma2 < 0, proven empty
    rc, out = check(broken_split(tmp_path, edit), "--no-witnesses")
    assert rc == 1 and "the pieces do not tile the split's prior box" in out, out


def test_a_split_excluding_a_witness_of_the_realisation_is_reported(tmp_path):
    with open(os.path.join(RESULTS, SPLIT_RUN, "tables.json")) as f:
        inner_upper = row(json.load(f), 2, "gamma3")["inner"]["upper"]

    def edit(split):  # the split and its live piece both end below the highest gamma3 witness
        for result in [split] + [p for p in split["pieces"] if not p["invalidated"]]:
            interval(result, "gamma3")["upper"]["value"] = inner_upper - 1e-3
    rc, out = check(broken_split(tmp_path, edit), "--no-witnesses")
    assert rc == 1 and "gamma3: the split's [" in out and "excludes" in out and "upper witness of n = 2" in out, out
    assert "is not the hull" not in out, out


def test_bad_usage_is_an_error_naming_the_fix(tmp_path):
    rc, out = check("--grids", tmp_path)
    assert rc == 2 and "unknown option '--grids'" in out and "--grid OUT.md" in out, out
    rc, out = check(tmp_path)
    assert rc == 2 and "no tables.json" in out, out
    (tmp_path / "tables.json").write_text("{\"cases\": []}")
    rc, out = check(tmp_path / "tables.json")
    assert rc == 2 and "not a cerone_tables output" in out, out
