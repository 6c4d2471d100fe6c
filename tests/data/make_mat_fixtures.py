#!/usr/bin/python3
"""Writes the .mat fixtures of tests/recording_test.cpp and their CSV twin (Debian's python3-scipy, python3-h5py):

    /usr/bin/python3 tests/data/make_mat_fixtures.py

recording.csv        t,u,y (40 samples, every value printed exactly)
recording_v5.mat     MATLAB v5, written by scipy.io.savemat: time (1x40), vir (40x1), qm (1x40)
recording_v73.mat    MATLAB v7.3 (HDF5 with MATLAB's 512-byte header), written by h5py as MATLAB does:
                     time (40x1), vir (40x1), qm (1x40), each dataset with its MATLAB_class attribute
recording_v73_nullpad.mat  the same, but MATLAB_class written as h5py writes a bytes attribute (null-padded,
                     not null-terminated), which libmatio does not recognise; the libhdf5 reader does
"""
import os

import h5py
import numpy as np
import scipy.io

HERE = os.path.dirname(os.path.abspath(__file__))
N = 40


def samples():
    rng = np.random.default_rng(17)
    t = np.arange(N) * 0.05
    u = rng.uniform(-2.0, 2.0, N)
    y = np.tanh(u) + 0.01 * rng.standard_normal(N)
    return t, u, y


def write_csv(path, t, u, y):
    with open(path, "w") as f:
        f.write("t,u,y\n")
        for row in zip(t, u, y):
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def matlab_v73_header():
    """The 128-byte text header MATLAB puts in the HDF5 user block: text, subsystem offset, version 0x0200, 'IM'."""
    text = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    return text.ljust(116, b" ") + b"\0" * 8 + b"\x00\x02" + b"IM"


def set_matlab_class(dataset, name):
    """MATLAB_class as MATLAB writes it: a fixed-length, null-terminated string of exactly len(name) bytes."""
    tid = h5py.h5t.C_S1.copy()
    tid.set_size(len(name))
    tid.set_strpad(h5py.h5t.STR_NULLTERM)
    attr = h5py.h5a.create(dataset.id, b"MATLAB_class", tid, h5py.h5s.create(h5py.h5s.SCALAR))
    attr.write(np.array(name.encode(), dtype=f"S{len(name)}"), mtype=tid)


def write_v73(path, variables, matlab_style=True):
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, array in variables.items():
            # HDF5 is row-major and MATLAB column-major: a MATLAB r x c array is stored as c x r.
            ds = f.create_dataset(name, data=np.ascontiguousarray(array.T))
            if matlab_style:
                set_matlab_class(ds, "double")
            else:
                ds.attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as f:
        f.write(matlab_v73_header())


def main():
    t, u, y = samples()
    write_csv(os.path.join(HERE, "recording.csv"), t, u, y)
    scipy.io.savemat(os.path.join(HERE, "recording_v5.mat"),
                     {"time": t, "vir": u.reshape(N, 1), "qm": y}, oned_as="row")
    v73 = {"time": t.reshape(N, 1), "vir": u.reshape(N, 1), "qm": y.reshape(1, N)}
    write_v73(os.path.join(HERE, "recording_v73.mat"), v73)
    write_v73(os.path.join(HERE, "recording_v73_nullpad.mat"), v73, matlab_style=False)


if __name__ == "__main__":
    main()
