"""HDF5 artifacts: round trip, atomic replacement, no partial files."""

import os

import numpy as np
import pytest

from toolkit.store import h5


def test_round_trip_nested(tmp_path):
    data = {"a": np.arange(6.0).reshape(2, 3), "s": "hello", "g": {"b": np.array([1, 2]), "names": np.array(["x", "yy"])}}
    path = h5.write(tmp_path / "sub" / "f.h5", data, attrs={"seed": 3, "note": "prov"})
    back = h5.read(path)
    np.testing.assert_array_equal(back["a"], data["a"])
    assert back["s"] == "hello"
    np.testing.assert_array_equal(back["g"]["b"], [1, 2])
    assert list(back["g"]["names"]) == ["x", "yy"]
    assert h5.read_attrs(path) == {"seed": 3, "note": "prov"}


def test_failed_write_leaves_previous_file_intact(tmp_path):
    path = h5.write(tmp_path / "f.h5", {"v": np.ones(3)})

    class Boom:
        def __array__(self, *a, **k):
            raise RuntimeError("interrupted mid-write")

    with pytest.raises(RuntimeError):
        h5.write(path, {"v": np.zeros(3), "w": Boom()})
    np.testing.assert_array_equal(h5.read(path)["v"], np.ones(3))
    assert [p.name for p in tmp_path.iterdir()] == ["f.h5"], "temp file left behind"


def test_no_file_until_complete(tmp_path):
    class Boom:
        def __array__(self, *a, **k):
            raise RuntimeError("stop")

    with pytest.raises(RuntimeError):
        h5.write(tmp_path / "new.h5", {"w": Boom()})
    assert not os.listdir(tmp_path)
