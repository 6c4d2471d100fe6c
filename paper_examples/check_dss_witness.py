#!/usr/bin/env python3
"""Independent check that parameter points lie in D^ss(n) of paper 001 (Cerone, Piga, Regruto), Result 1.

Plain Python (standard library only), written from the paper and NOT sharing code with hwbounds' C++
HwOuterSet, so that a bug there cannot hide here. Reading used (the same as docs/setmembership.md's): eq. (3)
z_t = -a1 z_{t-1} - a2 z_{t-2} + b1 x_{t-1} + b2 x_{t-2}; companion matrix A = [[-a1, -a2], [1, 0]];
for horizon s: z_t - sum_h [A^s](1,h) z_{t-s-h+1} = sum_{k=1..s} [A^{s-k}](1,1) v_{t-s+k}, v = b1 x_{t-1} + b2 x_{t-2};
every term kappa * alpha_j * w_tau^j of the left side is bounded independently over |eta_tau| <= dy_tau.
A point is in D^ss(n) iff for every (t, s): upper bound of the left side >= right side >= lower bound.

Usage: check_dss_witness.py RECORDING.csv INNER.json N
  RECORDING.csv  from `hwbounds simulate --example cerone2011 ...` (columns u, y, noise_bound)
  INNER.json     from `cerone_inner --out DIR` (DIR/inner.json: rows with min_point / max_point)
  N              dynamic horizon n of the rows to check
Prints the smallest relative slack of the truth and of every witness (>= 0: inside D^ss(n)); exits 1 if
any witness is outside.
"""
import csv
import json
import sys

NAMES = ["gamma2", "gamma3", "alpha2", "alpha3", "a1", "a2", "b1", "b2"]


def load(path):
    rows = list(csv.DictReader(open(path)))
    return ([float(r["u"]) for r in rows], [float(r["y"]) for r in rows],
            [float(r["noise_bound"]) for r in rows])


def power_range(y, dy, j):
    """Range of w^j over [y - dy, y + dy] (stationary point 0 for even j)."""
    lo, hi = y - dy, y + dy
    vals = [lo ** j, hi ** j]
    if j % 2 == 0 and lo < 0.0 < hi:
        vals.append(0.0)
    return min(vals), max(vals)


def min_relative_slack(p, u, y, dy, n):
    g2, g3, al2, al3, a1, a2, b1, b2 = p
    gamma, alpha, b = [1.0, g2, g3], [1.0, al2, al3], {1: b1, 2: b2}
    x = [sum(gamma[i] * uu ** (i + 1) for i in range(3)) for uu in u]
    A = [[-a1, -a2], [1.0, 0.0]]
    powers = [[[1.0, 0.0], [0.0, 1.0]]]
    for _ in range(n):
        M = powers[-1]
        powers.append([[sum(M[i][k] * A[k][j] for k in range(2)) for j in range(2)] for i in range(2)])
    worst, count = float("inf"), 0
    for t in range(len(y)):
        for s in range(1, n + 1):
            taus = [(t, 1.0)] + [(t - s - h + 1, -powers[s][0][h - 1]) for h in (1, 2)]
            if min(tau for tau, _ in taus) < 0 or t - s + 1 - 2 < 0:
                continue
            rhs = sum(powers[s - k][0][0] * sum(b[j] * x[t - s + k - j] for j in (1, 2)) for k in range(1, s + 1))
            upper = lower = 0.0
            for tau, kappa in taus:
                for j in range(3):
                    c = kappa * alpha[j]
                    f0, f1 = power_range(y[tau], dy[tau], j + 1)
                    upper += max(c * f0, c * f1)
                    lower += min(c * f0, c * f1)
            scale = max(1.0, abs(rhs))
            worst = min(worst, (upper - rhs) / scale, (rhs - lower) / scale)
            count += 2
    return worst, count


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    u, y, dy = load(sys.argv[1])
    n = int(sys.argv[3])
    truth = [0.4, -0.1, 0.8, 3.2, 1.8, 0.9, 1.6, 2.1]
    slack, count = min_relative_slack(truth, u, y, dy, n)
    print(f"n = {n}: {count} inequalities; truth: min relative slack {slack:+.3e}")
    outside = 0
    for row in json.load(open(sys.argv[2]))["rows"]:
        if row["n"] != n:
            continue
        for side in ("min", "max"):
            point = row.get(side + "_point")
            if not point:
                continue
            slack, _ = min_relative_slack(point, u, y, dy, n)
            inside = slack >= 0.0
            outside += not inside
            value = point[NAMES.index(row["parameter"])]
            print(f"{row['parameter']:<7} {side} witness {value:9.4f}: min relative slack {slack:+.3e}  "
                  f"{'inside D^ss' if inside else 'OUTSIDE'}")
    sys.exit(1 if outside else 0)


if __name__ == "__main__":
    main()
