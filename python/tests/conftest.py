"""Shared helpers of the Python tests: where the CLI and the sources are, running the CLI, comparing JSON.

CTest sets PYTHONPATH (the module in build/python), HWBOUNDS_CLI and HWBOUNDS_SOURCE_DIR; run by hand:
    PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests
"""
import json
import os
import subprocess

SOURCE_DIR = os.environ.get("HWBOUNDS_SOURCE_DIR",
                            os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
CLI = os.environ.get("HWBOUNDS_CLI", os.path.join(SOURCE_DIR, "build", "cli", "hwbounds"))
TEST_DATA = os.path.join(SOURCE_DIR, "tests", "data")
CERONE_N300 = os.path.join(SOURCE_DIR, "paper_examples", "data", "cerone2011_N300.csv")


def run_cli(*args, expect_rc=0):
    """Runs `hwbounds ARGS`; returns (stdout, stderr) and checks the exit code."""
    p = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == expect_rc, f"hwbounds {' '.join(map(str, args))}: rc {p.returncode}\n{p.stderr}"
    return p.stdout, p.stderr


def cli_error(*args):
    """The message of a CLI input error (exit code 2), without the 'error: ' prefix."""
    _, err = run_cli(*args, expect_rc=2)
    assert err.startswith("error: "), err
    return err[len("error: "):].strip()


def load_json(path):
    with open(path) as f:
        return json.load(f)


def without(d, *keys):
    return {k: v for k, v in d.items() if k not in keys}


def esmaeilani_signals(model, segments=2, seed=5):
    """Piecewise-constant inputs (20 levels held 10 samples) and the model's output plus 0.01 noise, per segment."""
    import numpy as np
    import hwbounds
    rng = np.random.default_rng(seed)
    signals = []
    for _ in range(segments):
        u = np.repeat(rng.uniform(-1, 1, 20), 10)
        signals.append((u, hwbounds.simulate(model, u) + 0.01 * rng.standard_normal(u.size)))
    return signals
