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


def test_preview_lists_groups_datasets_shapes_and_attributes(tmp_path):
    path = h5.write(tmp_path / "f.h5", {"root": np.zeros((100, 7)), "g": {"names": np.array(["a", "bb"]), "k": 3}},
                    attrs={"format": "jt.test/1"})
    lines = h5.preview(path).splitlines()
    assert lines[0].startswith("f.h5: HDF5, ")
    assert "@format = jt.test/1" in lines
    assert "root  100×7 float64" in lines  # a big dataset: shape and type, no values
    assert "g/" in lines and "  names  2 |S2  = ['a' 'bb']" in lines and "  k  scalar int64  = 3" in lines
    import h5py

    with h5py.File(tmp_path / "e.h5", "w") as f:  # what h5py writes for an empty value
        f.create_dataset("nothing", data=h5py.Empty("f8"))
    assert "nothing  empty float64" in h5.preview(tmp_path / "e.h5")
    many = h5.write(tmp_path / "m.h5", {f"d{i}": i for i in range(50)})
    assert h5.preview(many, max_lines=10).splitlines()[-1] == "… 42 more lines"
