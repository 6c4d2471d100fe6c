"""The two scripts of examples/python run as a reader would run them and produce what they promise."""
import os
import subprocess
import sys

from conftest import SOURCE_DIR

EXAMPLES = os.path.join(SOURCE_DIR, "examples", "python")


def run_example(name, out):
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), "--out", str(out)], capture_output=True,
                       text=True, timeout=240, env={**os.environ, "MPLBACKEND": "Agg"})
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_bounds_example_covers_the_truth_and_plots(tmp_path):
    out = run_example("bounds_cerone.py", tmp_path)
    rows = [line.split() for line in out.splitlines() if line.split()[:1] in (["a1"], ["a2"], ["b1"], ["b2"])]
    assert len(rows) == 4 and all(r[3] == "guaranteed" and r[-1] == "inside" for r in rows), out
    assert (tmp_path / "bounds_cerone.png").stat().st_size > 0


def test_diagnose_example_finds_the_backlash_in_the_mat_file(tmp_path):
    out = run_example("diagnose_mat.py", tmp_path)
    assert "verdict: backlash@input" in out, out
    assert (tmp_path / "backlash_pair.mat").exists() and (tmp_path / "report" / "report.json").exists()
