#!/usr/bin/python3
"""Derive the bundled EMPS recordings (force -> velocity at 100 Hz) from the benchmark's MATLAB files.

Usage: /usr/bin/python3 make_emps_csv.py DIR_WITH_DATA_EMPS_MAT [OUT_DIR]
Needs Debian's python3-numpy and python3-scipy. Checks the sha256 of both inputs first, so the
derived files can only come from the published recordings (README.md in this folder).

Processing, as in the benchmark's own scripts (Simulation_EMPS.m): the motor position qm (1 kHz) is
low-passed by a 4th-order Butterworth filter at 100 Hz, forward and backward (no phase shift), and
differentiated by central differences; the force is gtau * vir. The validation run's force pulses
are already inside vir (gtau * vir jumps by about 180 N where the marker pulses_N, 0 or 5, switches on),
so pulses_N is not added again. Force, position and velocity are then decimated by 10 to 100 Hz with
scipy.signal.decimate (order-8 Chebyshev anti-alias filter, forward and backward).
"""
import hashlib
import os
import sys

import numpy as np
import scipy.io
import scipy.signal

OUTPUTS = {"DATA_EMPS.mat": "emps_estimation_100hz.csv", "DATA_EMPS_PULSES.mat": "emps_validation_100hz.csv"}
DECIMATE = 10


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def convert(mat_path, out_path):
    m = scipy.io.loadmat(mat_path)
    t = m["t"][:, 0]
    qm = m["qm"][:, 0]
    force = m["gtau"][0, 0] * m["vir"][:, 0]
    dt = t[1] - t[0]
    b, a = scipy.signal.butter(4, 100.0 / (0.5 / dt))
    qf = scipy.signal.filtfilt(b, a, qm)
    v = np.gradient(qf, dt)  # central differences inside, one-sided at the ends
    dec = lambda s: scipy.signal.decimate(s, DECIMATE, ftype="iir", zero_phase=True)
    td = t[::DECIMATE][: len(dec(v))]
    rows = np.column_stack([td, dec(force), dec(qf), dec(v)])
    with open(out_path, "w") as f:
        f.write("t,force,position,velocity\n")
        for r in rows:
            f.write("{:.3f},{:.7g},{:.7g},{:.7g}\n".format(*r))
    return len(rows)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    src = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else os.path.dirname(os.path.abspath(__file__))
    expected = {}
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "SHA256SUMS")) as f:
        for line in f:
            digest, name = line.split()
            expected[name] = digest
    for name, csv_name in OUTPUTS.items():
        path = os.path.join(src, name)
        got = sha256(path)
        if expected.get(name) != got:
            sys.exit(f"{path}: sha256 {got} differs from SHA256SUMS ({expected.get(name)}); not the published file")
        n = convert(path, os.path.join(out, csv_name))
        print(f"wrote {csv_name}: {n} rows")


if __name__ == "__main__":
    main()
