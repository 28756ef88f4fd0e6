"""A shipped table edited in place is refused, whatever its zip directory says (issue 36, class 1).

A copy of ``svm-fine`` (stored uncompressed: its arrays are mapped from the file) keeps the shipped
header and zip directory when bytes are edited in place, so its files digest still names the shipped
table. Each array's bytes, mapped or decompressed, and its npy header are checked when it is first read:
no edit is answered. On c8fe4cc ``delta_up`` halved in place answered ``min-contact`` with exit 0.
"""

from __future__ import annotations

import os
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

from designkit.tables import store
from designkit.tables.store import load_table


@pytest.fixture(scope="module")
def fine(tmp_path_factory) -> Path:
    """A copy of svm-fine (a shipped table stored uncompressed), in a folder of its own."""
    src = load_table("svm-fine").path
    folder = tmp_path_factory.mktemp("fine")
    for suffix in (".npz", ".json"):
        shutil.copyfile(src.with_suffix(suffix), folder / f"copy{suffix}")
    return folder / "copy.npz"


def _members(path: Path) -> dict[str, tuple[int, int]]:
    """Array name -> (offset of its .npy in the file, its length), for members stored uncompressed."""
    import struct

    out = {}
    with zipfile.ZipFile(path) as z, open(path, "rb") as fh:
        for info in z.infolist():
            fh.seek(info.header_offset)
            local = fh.read(30)
            n, extra = struct.unpack("<HH", local[26:30])
            out[info.filename[:-4]] = (info.header_offset + 30 + n + extra, info.file_size)
    return out


class _Edit:
    """Write ``data`` at ``offset`` of ``path`` in place (same size, same directory); undo restores it."""

    _tick = 0

    def __init__(self, path: Path, offset: int, data: bytes):
        self.path, self.offset, self.data = path, offset, data

    def _write(self, data: bytes) -> bytes:
        with open(self.path, "r+b") as fh:
            fh.seek(self.offset)
            old = fh.read(len(data))
            fh.seek(self.offset)
            fh.write(data)
        _Edit._tick += 1  # a new mtime each time: timestamps are coarser than two edits in a row
        os.utime(self.path, ns=(10**18 + _Edit._tick * 10**6, 10**18 + _Edit._tick * 10**6))
        return old

    def __enter__(self):
        self.old = self._write(self.data)
        return self

    def __exit__(self, *exc):
        self._write(self.old)


def _read_every_array(path: Path) -> None:
    t = load_table(path)
    for name in t.arrays:
        np.asarray(t.arrays[name]).sum()


def _refused(path: Path) -> str:
    with pytest.raises(ValueError) as info:
        _read_every_array(path)
    message = str(info.value)
    assert "\n" not in message and "copy.npz" in message, message
    return message


def test_the_unedited_copy_is_the_shipped_content_and_answers(fine):
    t = load_table(fine)
    assert t.shipped and isinstance(t.arrays, store._NpzArrays)
    _read_every_array(fine)


def test_delta_up_halved_in_place_is_refused_by_min_contact(fine, cli):
    offset, size = _members(fine)["delta_up"]
    with open(fine, "rb") as fh:
        fh.seek(offset)
        npy = fh.read(size)
    header_len = size - 2720000
    data = np.frombuffer(npy[header_len:], dtype="<f8") / 2
    from designkit.query.table import clear_table_cache

    # a fresh process, as from a shell: answers this process computed from the shipped content (keyed by its
    # content hash, which the copy's header claims) are forgotten
    clear_table_cache()
    with _Edit(fine, offset + header_len, data.tobytes()):
        r = cli("min-contact", "--m1", "copper", "--m2", "glass", "--table", str(fine))
        assert r.exit_code == 2, r.output
        assert "delta_up differs from the shipped table's" in r.output and r.output.count("\n") == 1, r.output
    r = cli("min-contact", "--m1", "copper", "--m2", "glass", "--table", str(fine))
    assert r.exit_code == 0, r.output  # restored: answered again


def _npy_header_edits(fine: Path) -> list[tuple[str, int, bytes]]:
    """(what, offset, new bytes) for edits of each array's npy header that keep its length."""
    edits = []
    for name, (offset, size) in _members(fine).items():
        with open(fine, "rb") as fh:
            fh.seek(offset)
            head = fh.read(128)
        text = head.decode("latin1")
        dict_at = text.index("{")
        for old, new in (("'<f8'", "'>f8'"), ("'<i8'", "'>i8'"), ("'<f8'", "'<i8'"), ("'<i8'", "'<f8'"),
                         ("False", "True ")):
            at = text.find(old)
            if at >= 0:
                edits.append((f"{name}: {old} -> {new}", offset + at, new.encode("latin1")))
        shape_at = text.index("'shape': (") + len("'shape': (")
        shape_txt = text[shape_at:text.index(")", shape_at)]
        dims = [d.strip() for d in shape_txt.split(",") if d.strip()]
        if len(dims) >= 2 and dims[0] != dims[1]:  # permuted shape, same length of text
            perm = ", ".join([dims[1], dims[0], *dims[2:]]) + ("," if len(dims) == 1 else "")
            perm = perm.ljust(len(shape_txt))[:len(shape_txt)]
            edits.append((f"{name}: shape ({shape_txt}) -> ({perm})", offset + shape_at, perm.encode()))
        edits.append((f"{name}: magic", offset + 1, b"X"))
        edits.append((f"{name}: header dict", offset + dict_at, b"["))
    return edits


def test_npy_header_edits_are_refused(fine):
    edits = _npy_header_edits(fine)
    assert len(edits) >= 30
    for what, offset, data in edits:
        with _Edit(fine, offset, data):
            _refused(fine)


def test_250_byte_edits_across_every_array_are_refused(fine):
    """Bytes changed at positions spread over every array (header and data): none is answered."""
    rng = np.random.default_rng(36)
    members = _members(fine)
    accepted = []
    n = 0
    for name, (offset, size) in members.items():
        positions = rng.integers(0, size, 32)
        for pos in positions:
            with open(fine, "rb") as fh:
                fh.seek(offset + int(pos))
                old = fh.read(1)
            new = bytes([old[0] ^ int(rng.integers(1, 256))])
            with _Edit(fine, offset + int(pos), new):
                n += 1
                try:
                    np.asarray(load_table(fine).arrays[name]).sum()  # the edited array, as a question reads it
                except ValueError as exc:
                    assert "\n" not in str(exc)
                else:
                    accepted.append((name, int(pos)))
    assert n >= 250 and not accepted, accepted


def test_a_compressed_shipped_table_edited_with_a_matching_crc_is_refused(tmp_path):
    """The zip CRC is no content check: an array rewritten with its CRC (and sizes) kept is refused."""
    src = load_table("svm-paper").path
    shutil.copyfile(src.with_suffix(".json"), tmp_path / "t.json")
    with zipfile.ZipFile(src) as z:
        infos = z.infolist()
        raw = {i.filename: z.read(i) for i in infos}
    name = "delta_up.npy"
    arr = np.load(src)["delta_up"]
    import io

    buf = io.BytesIO()
    np.lib.format.write_array(buf, arr * 0.5, allow_pickle=False)
    raw[name] = buf.getvalue()
    # rebuild the zip; its directory (CRCs) now differs, so the files digest no longer names the shipped
    # table: the long way refuses it by the content hash
    with zipfile.ZipFile(tmp_path / "t.npz", "w", zipfile.ZIP_DEFLATED) as z:
        for i in infos:
            z.writestr(i.filename, raw[i.filename])
    with pytest.raises(ValueError, match="content check"):
        load_table(tmp_path / "t.npz")


def test_an_array_checked_once_is_not_hashed_again_in_this_process(fine, monkeypatch):
    t = load_table(fine)
    np.asarray(t.arrays["fits"])  # every row read: every row checked
    calls = []
    real = store.member_digest
    monkeypatch.setattr(store, "member_digest", lambda b: calls.append(1) or real(b))
    again = load_table(fine)
    np.asarray(again.arrays["fits"])
    assert not calls
    with _Edit(fine, _members(fine)["fits"][0] + 200, b"\x07"):  # a new identity: hashed again, refused
        with pytest.raises(ValueError, match="fits differs"):
            np.asarray(load_table(fine).arrays["fits"])
    assert calls


def test_a_question_hashes_only_the_rows_it_reads_and_an_edit_in_them_is_refused(fine):
    """A mapped array is checked row by row (first axis) as rows are read: min-contact at noise 0.05 °C and
    dT 10 °C reads one noise row of svm-fine's 17; an edit in another row is refused when that row is read."""
    from designkit.query import min_contact
    from designkit.query.table import clear_table_cache

    clear_table_cache()
    t = load_table(fine)
    assert min_contact(35000, 20000, noise_c=0.05, delta_t_c=10, table=t).value > 0
    read = {name: sorted(a._checked) for name, a in t.arrays._loaded.items()}
    assert read and all(rows == [8] for rows in read.values()), read
    offset, size = _members(fine)["delta_up"]
    row_bytes, data_at = 40 * 500 * 8, offset + size - 17 * 40 * 500 * 8
    with _Edit(fine, data_at + 3 * row_bytes + 16, b"\x07"):  # row 3: not read by the question
        clear_table_cache()
        t = load_table(fine)
        assert min_contact(35000, 20000, noise_c=0.05, delta_t_c=10, table=t).value > 0
        with pytest.raises(ValueError, match=r"delta_up differs from the shipped table's .*row 3"):
            t.arrays["delta_up"][2:4, 0]
        with pytest.raises(ValueError, match="delta_up differs"):
            np.asarray(t.arrays["delta_up"]) + 1
    with _Edit(fine, data_at + 8 * row_bytes + 16, b"\x07"):  # row 8: the question's own
        clear_table_cache()
        with pytest.raises(ValueError, match="delta_up differs"):
            min_contact(35000, 20000, noise_c=0.05, delta_t_c=10, table=load_table(fine))
    clear_table_cache()
