#!/usr/bin/python3
"""Guaranteed parameter intervals of paper 001's example from the bundled recording, from Python.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/bounds_cerone.py [--out DIR]

Reads paper_examples/data/cerone2011_N300.csv with numpy, runs hwbounds.bounds at horizon 1 and order 1 on
four parameters (seconds; scripts/run_example.sh runs the CLI at horizon 2, order 2), prints every interval
with its status and whether the true value lies inside, and, when matplotlib is installed, plots the
intervals against the truth to DIR/bounds_cerone.png. The CLI equivalent:

    hwbounds bounds --data paper_examples/data/cerone2011_N300.csv --noise-col noise_bound \\
        --horizon 1 --order 1 --params a1,a2,b1,b2 --json bounds.json
"""
import argparse
import os
import sys

import numpy as np

import hwbounds

HERE = os.path.dirname(os.path.abspath(__file__))
RECORDING = os.path.join(HERE, "..", "..", "paper_examples", "data", "cerone2011_N300.csv")
# Paper 001, Section VI, in hwbounds' layout (core/cerone_example.hpp).
TRUTH = {"gamma2": 0.4, "gamma3": -0.1, "alpha2": 0.8, "alpha3": 3.2, "a1": 1.8, "a2": 0.9, "b1": 1.6, "b2": 2.1}


def progress(p):
    print(f"\r[{p['phase']}] {p['done']}/{p['total']} jobs, {p['elapsed_seconds']:.0f} s", end="", file=sys.stderr)
    if p["done"] == p["total"]:
        print(file=sys.stderr)


def plot(intervals, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed (apt-get install python3-matplotlib): no plot")
        return
    names = [iv["parameter"] for iv in intervals]
    fig, ax = plt.subplots(figsize=(6, 3))
    for k, iv in enumerate(intervals):
        ax.plot([k, k], [iv["lower"]["value"], iv["upper"]["value"]], lw=6, color="tab:blue", solid_capstyle="butt")
        ax.plot(k, TRUTH[iv["parameter"]], "k_", ms=18, mew=2)
    ax.set_xticks(range(len(names)), names)
    ax.set_ylabel("guaranteed interval (bar), truth (line)")
    ax.set_title("paper 001 example, N = 300, horizon 1, order 1")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="directory for the plot")
    args = parser.parse_args()
    data = np.genfromtxt(RECORDING, delimiter=",", names=True)
    result = hwbounds.bounds(data["u"], data["y"], data["noise_bound"], na=2, nb=2, input_basis="poly:3",
                             output_basis="poly:3", horizon=1, order=1, parameters=["a1", "a2", "b1", "b2"],
                             progress=progress, source=RECORDING)
    print(f"{'parameter':<10} {'lower':>10} {'upper':>10}  {'status':<11} {'verified':<9} truth")
    for iv in result["intervals"]:
        lo, hi, truth = iv["lower"]["value"], iv["upper"]["value"], TRUTH[iv["parameter"]]
        status = "guaranteed" if iv["lower"]["status"] == iv["upper"]["status"] == "guaranteed" else "see notes"
        inside = "inside" if lo <= truth <= hi else "OUTSIDE"
        print(f"{iv['parameter']:<10} {lo:>10.4f} {hi:>10.4f}  {status:<11} {iv['lower']['verification']:<9} "
              f"{truth} {inside}")
    counts = result["counts"]
    print(f"{counts['orthants_proven_empty']} of {counts['orthants_total']} sign orthants proven empty, "
          f"{counts['sdp_solves']} SDP solves, {result['timing']['wall_seconds']:.1f} s")
    os.makedirs(args.out, exist_ok=True)
    plot(result["intervals"], os.path.join(args.out, "bounds_cerone.png"))


if __name__ == "__main__":
    main()
