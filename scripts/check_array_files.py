"""Loads the sample.npz and sample.mat that tests/suite/array_files.rs writes into DIR with
numpy.load and scipy.io.loadmat (the formats' reference readers) and checks names, order,
shapes, dtypes or MATLAB classes and values against the expectations below, written here
independently of the Rust writer.

Usage: python check_array_files.py DIR     (exit status 0 and "... ok" lines when all hold)
"""

import math
import sys
from pathlib import Path

import numpy as np
import scipy.io

# 2x3x4 array, T[i, j, k] = 100 i + 10 j + k.
CUBE = np.fromfunction(lambda i, j, k: 100 * i + 10 * j + k, (2, 3, 4), dtype=float)

REAL = {
    "A": np.array([[1.0, 2.0], [3.0, 0.1], [-2.5e-7, 1e300]]),
    "T": CUBE,
    "freq_hz": np.array([0.5, 1.25, 2.0]),
    "mass_kg": np.array(12.5),
    "special": np.array([math.inf, -math.inf, math.nan, -0.0, 5e-324]),
    "E": np.zeros((0, 3)),
}
STRINGS = {
    "state_names": ["eta_1", "eta_dot_1", "x"],
    "input_names": ["F_x", "θ_ü"],
    "no_names": [],
}
TEXT = {
    "units": "rad/s",
    "title": "Bode: θ → 𝜔",
    "empty_text": "",
}
ORDER = [
    "A", "T", "freq_hz", "mass_kg", "special", "E",
    "state_names", "input_names", "no_names",
    "units", "title", "empty_text",
]


def same_floats(got, want, what):
    """Exact equality, NaN equal to NaN, and the sign of zero kept."""
    assert got.dtype == np.float64, f"{what}: dtype {got.dtype}"
    assert got.shape == want.shape, f"{what}: shape {got.shape}, expected {want.shape}"
    assert np.array_equal(got, want, equal_nan=True), f"{what}: {got!r} != {want!r}"
    assert np.array_equal(np.signbit(got), np.signbit(want)), f"{what}: sign of zero"


def check_npz(path):
    with np.load(path) as npz:  # allow_pickle=False: plain arrays only
        assert npz.files == ORDER, f"npz names/order: {npz.files}"
        for name, want in REAL.items():
            same_floats(npz[name], want, f"npz {name}")
        for name, want in STRINGS.items():
            got = npz[name]
            width = max([len(s) for s in want] + [1])
            assert got.dtype == np.dtype(f"<U{width}"), f"npz {name}: dtype {got.dtype}"
            assert got.shape == (len(want),), f"npz {name}: shape {got.shape}"
            assert got.tolist() == want, f"npz {name}: {got!r}"
        for name, want in TEXT.items():
            got = npz[name]
            assert got.shape == (), f"npz {name}: shape {got.shape}"
            assert got.dtype == np.dtype(f"<U{max(len(want), 1)}"), f"npz {name}: {got.dtype}"
            assert got.item() == want and str(got) == want, f"npz {name}: {got!r}"
    # The data of every entry start at a multiple of 64 bytes (NumPy's ARRAY_ALIGN).
    import zipfile

    with zipfile.ZipFile(path) as z:
        for info in z.infolist():
            assert info.compress_type == zipfile.ZIP_STORED, info
            assert info.date_time == (1980, 1, 1, 0, 0, 0), info
            with z.open(info) as f:
                version = np.lib.format.read_magic(f)
                assert version == (1, 0), f"{info.filename}: NPY version {version}"
                np.lib.format.read_array_header_1_0(f)
                assert f.tell() % 64 == 0, f"{info.filename}: data at {f.tell()}"
    print("numpy.load: ok")


def matlab_shape(a):
    """The MATLAB shape of a NumPy array as the writer maps it: 0-d 1x1, 1-d a column."""
    if a.ndim == 0:
        return (1, 1)
    if a.ndim == 1:
        return (a.shape[0], 1)
    return a.shape


def char_row(got, want, what):
    """A MATLAB char row vector as loadmat gives it (chars_as_strings): shape (1,) holding
    the string, or for the empty string an empty array."""
    if want == "":
        assert got.size == 0 or got.tolist() == [""], f"{what}: {got!r}"
    else:
        assert got.dtype.kind == "U", f"{what}: dtype {got.dtype}"
        assert got.tolist() == [want], f"{what}: {got!r}"


def check_mat(path):
    info = scipy.io.whosmat(path)
    assert [name for name, _, _ in info] == ORDER, f"mat names/order: {info}"
    classes = {name: (shape, cls) for name, shape, cls in info}
    for name, want in REAL.items():
        assert classes[name] == (matlab_shape(want), "double"), f"whosmat {name}: {classes[name]}"
    for name, want in STRINGS.items():
        assert classes[name] == ((1, len(want)), "cell"), f"whosmat {name}: {classes[name]}"
    for name in TEXT:
        # (whosmat reports char shapes with the string axis folded, as loadmat returns them.)
        assert classes[name][1] == "char", f"whosmat {name}: {classes[name]}"

    mat = scipy.io.loadmat(path)
    assert mat["__header__"].startswith(
        b"MATLAB 5.0 MAT-file, Platform: any, Created by: flexcraft test"
    ), mat["__header__"]
    assert mat["__version__"] == "1.0", mat["__version__"]
    for name, want in REAL.items():
        same_floats(mat[name], want.reshape(matlab_shape(want)), f"mat {name}")
    for name, want in STRINGS.items():
        got = mat[name]
        assert got.dtype == object and got.shape == (1, len(want)), f"mat {name}: {got!r}"
        for j, s in enumerate(want):
            char_row(got[0, j], s, f"mat {name}[{j}]")
    for name, want in TEXT.items():
        # The writer replaces characters beyond the BMP by U+FFFD in MATLAB files.
        want = "".join(c if ord(c) <= 0xFFFF else "\ufffd" for c in want)
        char_row(mat[name], want, f"mat {name}")

    # The way most users will read it: simplify_cells gives plain Python strings and lists.
    simple = scipy.io.loadmat(path, simplify_cells=True)
    assert list(simple["state_names"]) == STRINGS["state_names"], simple["state_names"]
    assert list(simple["input_names"]) == STRINGS["input_names"], simple["input_names"]
    assert simple["units"] == "rad/s", simple["units"]
    assert simple["title"] == "Bode: θ → \ufffd", simple["title"]
    print("scipy.io.loadmat: ok")


def main():
    folder = Path(sys.argv[1])
    check_npz(folder / "sample.npz")
    check_mat(folder / "sample.mat")


if __name__ == "__main__":
    main()
