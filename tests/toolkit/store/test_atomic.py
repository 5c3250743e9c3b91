"""Atomic writes (``toolkit.store.atomic``): the target is replaced whole or not at all, and no
temp file is ever left behind."""

import os

import pytest

from toolkit.store import atomic


def test_writes_through_a_pid_temp_file_next_to_the_target(tmp_path):
    target = tmp_path / "sub" / "f.txt"
    with atomic.atomic_write(target) as tmp:
        assert tmp == target.with_name(f"f.txt.tmp-{os.getpid()}") and tmp.parent.is_dir()
        tmp.write_text("new")
        assert not target.exists()  # nothing at the target until the body is done
    assert target.read_text() == "new"
    assert os.listdir(target.parent) == ["f.txt"]


def test_an_exception_inside_leaves_the_old_file_intact_and_no_temp_file(tmp_path):
    target = atomic.write_text(tmp_path / "f.txt", "old")
    with pytest.raises(RuntimeError, match="cut off"):
        with atomic.atomic_write(target) as tmp:
            tmp.write_text("half of the new")
            raise RuntimeError("cut off")
    assert target.read_text() == "old"
    assert os.listdir(tmp_path) == ["f.txt"], "temp file left behind"


def test_an_exception_before_anything_is_written_creates_nothing(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        with atomic.atomic_write(tmp_path / "new.txt"):
            raise KeyboardInterrupt
    assert os.listdir(tmp_path) == []


def test_write_text_replaces_an_existing_file(tmp_path):
    target = atomic.write_text(tmp_path / "f.txt", "a")
    assert atomic.write_text(target, "b") == target and target.read_text() == "b"
    assert os.listdir(tmp_path) == ["f.txt"]
