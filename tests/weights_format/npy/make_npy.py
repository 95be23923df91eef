"""Writes the .npy files the C++ reader is tested on (tests/weights_format/test_npy.cpp),
with numpy's own writer, so the reader meets real numpy output. Every value is one the
C++ test restates exactly. Rerunning it gives the same bytes:

    /usr/bin/python3 tests/weights_format/npy/make_npy.py
"""

import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def arrays():
    """file name -> array written with np.save (format version 1.0)."""
    return {
        "f4.npy": ((np.arange(24) - 12) / 4).astype("<f4").reshape(2, 3, 4),
        "f8.npy": np.array([0.1, -2.5, 1e-3, 12345.678, 0.0], dtype="<f8"),
        "f2.npy": (np.arange(6) / 8 - 0.25).astype("<f2").reshape(3, 2),
        "u1.npy": (np.arange(16) * 17).astype("|u1").reshape(4, 4),
        "u2.npy": np.array([0, 1000, 65535], dtype="<u2"),
        "i4.npy": np.array([[-2147483648, -1], [0, 2147483647]], dtype="<i4"),
        "i8.npy": np.array([-(1 << 40), 7, 1 << 53], dtype="<i8"),
        "b1.npy": np.array([True, False, True, True, False]),
        "scalar.npy": np.array(3.25, dtype="<f4"),
        "empty.npy": np.zeros((0, 3), dtype="<f4"),
        "fortran.npy": np.asfortranarray(np.arange(6, dtype="<f4").reshape(2, 3)),
        "big_endian.npy": np.arange(3, dtype=">f4"),
    }


def write_version(name, array, version):
    with open(os.path.join(HERE, name), "wb") as f:
        np.lib.format.write_array(f, array, version=version)


if __name__ == "__main__":
    for name, array in arrays().items():
        np.save(os.path.join(HERE, name), array)
    six = np.arange(6, dtype="<f4").reshape(2, 3)
    write_version("v2.npy", six, (2, 0))
    write_version("v3.npy", six, (3, 0))
