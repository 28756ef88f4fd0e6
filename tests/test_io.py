"""Atomic writes: whole files or nothing, and never a device replaced by a file."""

from __future__ import annotations

import os
import stat

import pytest

from designkit._io import atomic_write_bytes, atomic_write_text


def test_a_write_replaces_a_regular_file_whole(tmp_path):
    p = tmp_path / "a" / "b.txt"
    atomic_write_text(p, "one")
    atomic_write_text(p, "two")
    assert p.read_text() == "two" and [q.name for q in p.parent.iterdir()] == ["b.txt"]


def test_a_device_or_fifo_is_written_to_not_replaced(tmp_path):
    atomic_write_bytes("/dev/null", b"nothing")  # as root, a rename here replaced the device with a file
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    r = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
    try:
        atomic_write_bytes(fifo, b"through the pipe")
        assert os.read(r, 100) == b"through the pipe" and stat.S_ISFIFO(os.stat(fifo).st_mode)
    finally:
        os.close(r)


def test_a_folder_is_refused(tmp_path):
    with pytest.raises(IsADirectoryError, match="is a folder"):
        atomic_write_bytes(tmp_path, b"x")
