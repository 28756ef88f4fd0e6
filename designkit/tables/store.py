"""Lookup tables on disk: one documented format, loaded without pickle.

A table ``NAME`` is two files side by side: ``NAME.npz``, numpy arrays (``delta_up``, ``delta_down``, their
Monte Carlo ends and the ideal observer's; shape ``[scene axes..., contact, effusivity]``, effusivity in
J s^-1/2 K^-1 m^-2, NaN where no distinguishable partner lies inside the grid; read with
``allow_pickle=False``), and ``NAME.json``, the header (grid, axes, sensor, model, sweep config, the
arrays' shapes, units and meanings) with ``content_hash``: SHA-256 over the header, less the fields that
change no answer, and every array. The hash is verified on load, and the header is checked against its
schema and the arrays: a corrupted, truncated or edited table is refused. Schema version 2 (this one)
hashes the header with the arrays; a version-1 table (arrays only) is refused with the remedy
(``python benchmarks/rehash_tables.py TABLE.json`` after checking its header, or a rebuild). Every field:
tables/README.md, "File format" (installed as ``designkit/shipped_tables/README.md``).
"""

from __future__ import annotations

import datetime as _dt
import functools
import io
import json
import math
import struct
import zipfile
import zlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import xxhash

from .._validation import InputError

__all__ = [
    "SHIPPED_CONTENT_HASHES",
    "SHIPPED_FILE_DIGESTS",
    "file_digest",
    "member_digest",
    "member_digests",
    "shipped_member_digests",
    "SCHEMA_VERSION",
    "Table",
    "content_hash",
    "list_tables",
    "load_table",
    "resolve_table",
    "UNHASHED_FIELDS",
    "check_table",
    "table_header",
    "write_table",
]

SCHEMA_VERSION = 2
#: Header fields outside the content hash: they change no answer (when it was built, how long it took).
UNHASHED_FIELDS = ("content_hash", "created", "stats")
FORMAT = "designkit-table"
E_UNITS = "J s^-1/2 K^-1 m^-2"

_ARRAY_DOCS = {
    "delta_up": (E_UNITS, "smallest distinguishable difference towards higher effusivity"),
    "delta_down": (E_UNITS, "smallest distinguishable difference towards lower effusivity"),
    "delta_up_lo": (E_UNITS, "lower end of the Monte Carlo interval of delta_up"),
    "delta_up_hi": (E_UNITS, "upper end of the Monte Carlo interval of delta_up (NaN: not confidently reached in the grid)"),
    "delta_down_lo": (E_UNITS, "lower end of the Monte Carlo interval of delta_down"),
    "delta_down_hi": (E_UNITS, "upper end of the Monte Carlo interval of delta_down"),
    "delta_up_ideal": (E_UNITS, "ideal observer's delta towards higher effusivity"),
    "delta_down_ideal": (E_UNITS, "ideal observer's delta towards lower effusivity"),
    "fits": ("1", "SVM fits (including repeats) per scene point and contact"),
    "chunk_wall_s": ("s", "compute time per scene point and contact, summed over chunks"),
    "f1_matrix": ("1", "F1 of every pair of intervals"),
}

_AXIS_DOCS = {
    "noise_ratio": ("1 (sigma / dT)", "log", "noise sigma over sensor-object temperature difference"),
    "noise_c": ("degC", "log", "noise sigma per sample"),
    "delta_t_c": ("degC", "linear", "sensor minus object temperature before contact"),
    "contact_s": ("s", "linear", "contact time"),
    "e_ref": (E_UNITS, "linear", "reference interval centre"),
}


def content_hash(arrays: Mapping[str, np.ndarray], header: Mapping[str, Any] | None = None) -> str:
    """SHA-256 over a table's identity: ``header`` (if given; canonical JSON without
    :data:`UNHASHED_FIELDS`), then every array's name, dtype, shape and C-order bytes, in name order."""
    import hashlib  # here, not at the top: a shipped table's question never computes it

    h = hashlib.sha256()
    if header is not None:
        ident = {k: v for k, v in header.items() if k not in UNHASHED_FIELDS}
        try:
            text = json.dumps(ident, sort_keys=True, separators=(",", ":"), allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise InputError(f"table header cannot be hashed: {exc}") from None
        h.update(b"designkit-table-header\0")
        h.update(text.encode("utf-8"))
        h.update(b"\0arrays\0")
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        h.update(name.encode())
        h.update(a.dtype.str.encode())
        h.update(repr(tuple(a.shape)).encode())
        h.update(a if a.size else b"")  # the array's buffer itself: the bytes of tobytes() without copying them
    return "sha256:" + h.hexdigest()


def table_header(cfg, arrays: Mapping[str, np.ndarray], *, run: Mapping[str, Any] | None = None) -> dict:
    """The JSON header of a table built from sweep config ``cfg``."""
    from .. import __version__

    sensor = cfg.resolved_sensor()
    axes = []
    for name, values in cfg.scene_axes + [("contact_s", cfg.contact_s)]:
        units, scale, meaning = _AXIS_DOCS[name]
        axes.append({"name": name, "units": units, "scale": scale, "meaning": meaning,
                     "values": [float(v) for v in values]})
    units, scale, meaning = _AXIS_DOCS["e_ref"]
    axes.append({"name": "e_ref", "units": units, "scale": scale, "meaning": meaning,
                 "values": [float(v) for v in cfg.centres]})
    fits = np.asarray(arrays.get("fits", 0))
    # compute seconds: the run's statistics (sweeps since the engine kept timings out of the hashed
    # arrays), else a chunk_wall_s array (tables built before)
    run_wall = (run or {}).get("chunk_wall_s")
    wall = np.asarray(run_wall if run_wall is not None else arrays.get("chunk_wall_s", 0.0), dtype=np.float64)
    return {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "name": cfg.name,
        "fidelity": cfg.fidelity,
        "sensor": sensor.to_dict(),
        "model": _model_of(cfg).to_dict(),
        "effusivity": {"min": cfg.e_min, "max": cfg.e_max, "intervals": cfg.intervals,
                       "width": cfg.width, "units": E_UNITS},
        "fixed_initial_conditions": not cfg.varied,
        "axes": axes,
        "arrays": {name: {"shape": list(np.shape(a)), "dtype": str(np.asarray(a).dtype),
                          "units": _ARRAY_DOCS.get(name, ("", ""))[0],
                          "meaning": _ARRAY_DOCS.get(name, ("", ""))[1]}
                   for name, a in sorted(arrays.items())},
        "threshold": cfg.threshold,
        "trials": cfg.trials,
        "folds": cfg.folds,
        "seed": cfg.seed,
        "max_repeats": cfg.max_repeats,
        "z": cfg.z,
        "designkit_version": __version__,
        "created": _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat(),
        "config": cfg.to_dict(),
        "stats": {
            "svm_fits_total": int(fits.sum()),
            "svm_fits_per_scene_mean": float(fits.mean()) if fits.size else 0.0,
            "compute_s_total": float(wall.sum()),
            "compute_s_per_scene_mean": float(wall.mean()) if wall.size else 0.0,
            **({"run": dict(run)} if run else {}),
        },
    }


def _model_of(cfg):
    """The forward model a sweep config names (configs from before the seam: the semi-infinite model)."""
    from ..models import get_model

    return get_model(getattr(cfg, "model", None))


def write_table(path: str | Path, header: dict, arrays: Mapping[str, np.ndarray], *, compress: bool = True) -> Path:
    """Write ``path`` (.npz) and its .json header atomically; returns the .npz path.

    ``compress=False`` stores the arrays uncompressed (``np.savez``): larger on disk, but a shipped table
    stored so is mapped from the file and a question reads only the slices it needs (:class:`_NpzArrays`).
    The content hash is the same either way.

    The arrays are written first, the header (with the content hash) last, so
    a crash leaves either the old table or a header-less npz that loading
    refuses.
    """
    from .._io import atomic_write_bytes, atomic_write_text

    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_suffix(".npz")
    for parent in (path.parent, *path.parent.parents):
        if parent.exists():
            if not parent.is_dir():
                raise InputError(f"cannot write table {path}: {parent} is not a folder")
            break
    arrays = {k: np.ascontiguousarray(v) for k, v in arrays.items()}
    for name, a in arrays.items():
        if a.dtype == object:
            raise InputError(f"table array {name} has dtype object; tables hold numbers only")
    header = json.loads(json.dumps(dict(header), allow_nan=False))  # the JSON the reader will hash
    header["schema_version"] = SCHEMA_VERSION
    header["content_hash"] = content_hash(arrays, header)
    buf = io.BytesIO()
    (np.savez_compressed if compress else np.savez)(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())
    atomic_write_text(path.with_suffix(".json"), json.dumps(header, indent=1, allow_nan=False) + "\n")
    return path


def _zip_members(z: zipfile.ZipFile) -> dict[str, zipfile.ZipInfo]:
    return {i.filename[:-4]: i for i in z.infolist() if i.filename.endswith(".npy")}


class _EditedArray(ValueError):
    """An array whose npy header or bytes differ from what the table's header (or shipped digest) says."""


def _check_npy_header(name: str, shape: tuple, fortran: bool, dtype: np.dtype, spec: Mapping[str, Any] | None) -> None:
    """The npy header of array ``name`` against its entry in the JSON header (``spec``: shape, dtype).

    :func:`write_table` writes C-ordered arrays of the listed shape and dtype; anything else (a byte-swapped
    dtype, a permuted shape, ``fortran_order``) is an edit, refused whatever the zip directory says.
    """
    if dtype.hasobject:
        raise _EditedArray(f"array {name} holds Python objects; tables hold numbers only")
    if fortran:
        raise _EditedArray(f"array {name} is stored in Fortran order; tables are written in C order")
    if spec is None:
        return  # unlisted: check_table names it
    try:
        want = np.dtype(str(spec["dtype"]))
        want_shape = tuple(int(n) for n in spec["shape"])
    except (TypeError, ValueError, KeyError):
        raise _EditedArray(f"array {name}: the header's dtype/shape entry is not one") from None
    if dtype != want or dtype.str != want.str or tuple(shape) != want_shape:
        raise _EditedArray(f"array {name} is stored as {dtype.str}{list(shape)}, the header says "
                           f"{want.str}{list(want_shape)}")


#: Member digests this process has checked, by file identity: ``(device, inode, size, mtime_ns, ctime_ns,
#: member) -> digest``. A table read again (another question, another view) is not hashed again; a file
#: rewritten, even in place, has another identity. Bounded (a long-lived process reading many tables).
_VERIFIED: dict[tuple, str] = {}
_VERIFIED_MAX = 4096


def _verified(key: tuple, digest: str) -> bool:
    return _VERIFIED.get(key) == digest


def _remember(key: tuple, digest: str) -> None:
    if len(_VERIFIED) >= _VERIFIED_MAX:
        _VERIFIED.clear()
    _VERIFIED[key] = digest


def member_digest(npy_bytes) -> str:
    """XXH3-128 of one member of a table's .npz: its whole ``.npy`` (header and data), decompressed.

    What :func:`shipped_member_digests` lists, and what a shipped table's array is checked against when it is
    first read (the npy header included: dtype, shape and order as well as every byte). XXH3 (the xxhash
    library) rather than SHA-256: a fresh question hashes every byte of the arrays it reads (about 22 MB of
    the fine table: SHA-256 took 12-18 ms of a 375 ms start, XXH3 about 1 ms), and a cryptographic digest
    buys nothing here: it detects a changed byte no better, and a deliberately crafted table given by path
    passes the long way's checks anyway (its content hash is its own), so a shipped digest is a shortcut
    to trust, never a signature. The content hash (:func:`content_hash`) stays SHA-256.

    >>> member_digest(b"")
    'xxh3_128:99aa06d3014798d86001c324468d497f'
    """
    return "xxh3_128:" + xxhash.xxh3_128_hexdigest(npy_bytes)


def member_digests(path: str | Path) -> dict[str, str | tuple[str, ...]]:
    """The shipped digests of every array of the .npz at ``path``, by array name (to list a shipped table).

    A member stored uncompressed with two or more axes (mapped from the file: a question reads a few rows of
    it) gets one :func:`member_digest` for its npy header's bytes, then one for each row (first axis), so
    that a question hashes the rows it reads and no other (:class:`_CheckedRows`); any other member gets one
    :func:`member_digest` of its whole ``.npy``."""
    out: dict[str, str | tuple[str, ...]] = {}
    with zipfile.ZipFile(path) as z:
        for name, info in sorted(_zip_members(z).items()):
            raw = z.read(info)
            out[name] = member_digest(raw)
            if info.compress_type == zipfile.ZIP_STORED:
                buf = io.BytesIO(raw)
                shape, fortran, dtype = _npy_header(buf, np.lib.format.read_magic(buf))
                if len(shape) >= 2 and not fortran and math.prod(shape):
                    a = np.frombuffer(raw, dtype=dtype, count=math.prod(shape), offset=buf.tell()).reshape(shape)
                    out[name] = (member_digest(raw[:buf.tell()]), *(member_digest(row) for row in a))
    return out


def _read_member(path: Path, info: zipfile.ZipInfo, spec: Mapping[str, Any] | None = None,
                 digest: str | tuple[str, ...] | None = None) -> "np.ndarray | _CheckedRows":
    """One array of an .npz, read-only, its npy header checked against ``spec`` (the JSON header's entry).

    A member stored uncompressed is mapped from the file, so that only the pages a question touches are
    read; a compressed one is decompressed (its CRC checked). With ``digest`` (a shipped table's
    :func:`member_digest`) the member's bytes as read or mapped are hashed and compared first: the zip
    directory is not trusted for them. A member checked once in this process is not hashed again while its
    file keeps its identity (device, inode, size, mtime, ctime). A mapped member listed row by row (``digest``
    a tuple: :func:`member_digests`) has its npy header's bytes checked here and each row when it is first
    read (:class:`_CheckedRows`).
    """
    import mmap
    import os

    name = info.filename[:-4]
    with open(path, "rb") as fh:
        st = os.fstat(fh.fileno())
        key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns, info.filename)
        if info.compress_type != zipfile.ZIP_STORED:
            with zipfile.ZipFile(fh) as z:
                raw = z.read(info)  # decompressed, CRC-checked
            if isinstance(digest, tuple):  # listed row by row: a member stored uncompressed, as shipped
                raise _EditedArray(f"array {name} is compressed; the shipped table's is stored")
            if digest is not None and not _verified(key, digest):
                if member_digest(raw) != digest:
                    raise _EditedArray(f"array {name} differs from the shipped table's (digest mismatch)")
                _remember(key, digest)
            buf = io.BytesIO(raw)
            version = np.lib.format.read_magic(buf)
            shape, fortran, dtype = _npy_header(buf, version)
            _check_npy_header(name, shape, fortran, dtype, spec)
            offset = buf.tell()
            size = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
            if offset + size != len(raw):
                raise ValueError(f"{info.filename} does not hold its shape")
            return np.frombuffer(raw, dtype=dtype, count=int(np.prod(shape, dtype=np.int64)),
                                 offset=offset).reshape(shape)
        fh.seek(info.header_offset)
        local = fh.read(30)
        if len(local) != 30 or local[:4] != b"PK\x03\x04":
            raise zipfile.BadZipFile(f"no local header for {info.filename}")
        name_len, extra_len = struct.unpack("<HH", local[26:30])
        start = info.header_offset + 30 + name_len + extra_len
        if start + info.file_size > st.st_size:
            raise ValueError(f"{info.filename} is shorter than its directory says")
        fh.seek(start)
        version = np.lib.format.read_magic(fh)
        shape, fortran, dtype = _npy_header(fh, version)
        _check_npy_header(name, shape, fortran, dtype, spec)
        offset = fh.tell()
        size = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        if offset + size != start + info.file_size:
            raise ValueError(f"{info.filename} does not hold its shape")
        if info.file_size == 0 or st.st_size == 0:
            raise ValueError(f"{info.filename} is empty")
        mm = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)
    if isinstance(digest, tuple):
        if len(digest) != 1 + (shape[0] if shape else 0) or size == 0:
            raise _EditedArray(f"array {name} has not the shipped table's rows")
        head = key + ("npy header",)
        if not _verified(head, digest[0]):
            if member_digest(memoryview(mm)[start:offset]) != digest[0]:
                raise _EditedArray(f"array {name} differs from the shipped table's (digest mismatch)")
            _remember(head, digest[0])
        return _CheckedRows(path, name, np.ndarray(shape, dtype=dtype, buffer=mm, offset=offset, order="C"),
                            digest[1:], key)
    if digest is not None and not _verified(key, digest):
        if member_digest(memoryview(mm)[start:start + info.file_size]) != digest:
            raise _EditedArray(f"array {name} differs from the shipped table's (digest mismatch)")
        _remember(key, digest)
    if size == 0:
        return np.zeros(shape, dtype=dtype)
    return np.ndarray(shape, dtype=dtype, buffer=mm, offset=offset, order="C")


def _npy_header(fh, version) -> tuple:
    read_header = {(1, 0): np.lib.format.read_array_header_1_0,
                   (2, 0): np.lib.format.read_array_header_2_0}.get(version)
    if read_header is None:
        raise ValueError(f"npy format version {version}")
    return read_header(fh)


def _read_error(path: Path, name: str, exc: BaseException) -> InputError:
    if isinstance(exc, _EditedArray):
        return InputError(f"table {path.name}: {exc}: edited or corrupted; rebuild it with designkit sweep "
                          f"(or restore the shipped file)")
    return InputError(f"table {path.name}: array {name} is corrupted or truncated "
                      f"({type(exc).__name__}); rebuild it with designkit sweep")


_READ_ERRORS = (zipfile.BadZipFile, ValueError, OSError, EOFError, zlib.error, KeyError, NotImplementedError,
                struct.error)


class _CheckedRows(np.lib.mixins.NDArrayOperatorsMixin):
    """A shipped array mapped from its file whose rows (first axis) are each checked against their shipped
    digest (:func:`member_digests`) when first read: a fresh ``min-contact`` reads one noise row of svm-fine's
    17, so it hashes (and pages in) that row only, not the table's 22 MB.

    Indexing checks the rows its first index names (an integer, a slice, integer arrays; anything else:
    every row) and returns numpy's result; ``np.asarray``, ufuncs, operators and every other ndarray
    attribute check every row first. No byte of an unchecked row leaves it. A row checked once in this
    process is not hashed again while the file keeps its identity.
    """

    def __init__(self, path: Path, name: str, array: np.ndarray, digests: tuple[str, ...], key: tuple):
        self._path, self._name, self._a, self._digests, self._key = path, name, array, digests, key
        self._checked: set[int] = set()

    shape = property(lambda self: self._a.shape)
    dtype = property(lambda self: self._a.dtype)
    ndim = property(lambda self: self._a.ndim)
    size = property(lambda self: self._a.size)

    def __len__(self) -> int:
        return len(self._a)

    def _check(self, rows) -> None:
        for r in rows:
            if r in self._checked:
                continue
            key, digest = self._key + (r,), self._digests[r]
            if not _verified(key, digest):
                if member_digest(self._a[r]) != digest:
                    raise _read_error(self._path, self._name, _EditedArray(
                        f"array {self._name} differs from the shipped table's (digest mismatch in row {r})"))
                _remember(key, digest)
            self._checked.add(r)

    def _rows(self, index):
        """The rows (first axis) ``self._a[index]`` reads: those its first index names, else every row. (Cheap:
        a question indexes each array it reads a few times, with small integer arrays.)"""
        n = len(self._a)
        if type(index) is tuple:
            if not index:
                return range(n)
            index = index[0]
        if isinstance(index, (np.ndarray, list)):
            flat = np.asarray(index)
            if flat.dtype.kind not in "iu":
                return range(n)  # a mask, or anything else: every row
            flat = flat.astype(np.int64, copy=False).ravel()
            if flat.size > 64:  # one entry per row named (np.unique imports numpy.ma)
                flat = np.flatnonzero(np.bincount(flat[(flat >= -n) & (flat < n)] % n, minlength=n))
            return {r % n for r in flat.tolist() if -n <= r < n}  # out of range: numpy says so
        if isinstance(index, (int, np.integer)) and not isinstance(index, (bool, np.bool_)):
            return (int(index) % n,) if -n <= index < n else ()
        if isinstance(index, slice):
            return range(*index.indices(n))
        return range(n)  # Ellipsis, a new axis, anything else: every row

    def __getitem__(self, index):
        self._check(self._rows(index))
        return self._a[index]

    def __array__(self, dtype=None, copy=None):
        self._check(range(len(self._a)))
        a = self._a if dtype is None else self._a.astype(dtype, copy=False)
        return a.copy() if copy else a

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        inputs = tuple(np.asarray(x) if isinstance(x, _CheckedRows) else x for x in inputs)
        return getattr(ufunc, method)(*inputs, **kwargs)

    def __iter__(self):
        return iter(np.asarray(self))

    def __getattr__(self, attr):  # every other ndarray attribute: every row checked first
        if attr.startswith("_"):
            raise AttributeError(attr)
        return getattr(np.asarray(self), attr)

    def __repr__(self) -> str:
        return f"<{self._name} {self.dtype}{list(self.shape)} mapped from {self._path.name}, checked row by row>"


class _NpzArrays(Mapping):
    """A shipped table's arrays, each read when a question first asks for it.

    A question reads a few slices of a few arrays (min-contact: the noise slices around its own, of
    ``delta_*`` and their intervals). Members stored uncompressed (the fine shipped table,
    :func:`write_table` with ``compress=False``) are mapped from the file, so only those pages are
    read (decompressing the whole table would cost a fresh question more than its answer). Each member's
    bytes, mapped or decompressed, are checked against the shipped table's :func:`shipped_member_digests`
    when first read (once per process and file; a mapped member's row by row, :class:`_CheckedRows`), and
    its npy header against the JSON header. Plain data: picklable.
    """

    def __init__(self, path: Path, members: Mapping[str, zipfile.ZipInfo],
                 specs: Mapping[str, Any] | None = None,
                 digests: Mapping[str, str | tuple[str, ...]] | None = None):
        self._path = Path(path)
        self._members = dict(members)
        self._specs = dict(specs or {})
        self._digests = dict(digests or {})
        self._loaded: dict[str, np.ndarray] = {}

    def __getitem__(self, name: str) -> np.ndarray:
        a = self._loaded.get(name)
        if a is None:
            info = self._members.get(name)
            if info is None:
                raise KeyError(name)
            digest = self._digests.get(name)
            if digest is None:  # every shipped member has one: a member without is not the shipped file
                raise InputError(f"table {self._path.name}: array {name} is not one of the shipped table's; "
                                 f"rebuild it with designkit sweep")
            try:
                a = self._loaded[name] = _read_member(self._path, info, self._specs.get(name), digest)
            except _READ_ERRORS as exc:
                raise _read_error(self._path, name, exc) from None
        return a

    def __iter__(self):
        return iter(self._members)

    def __len__(self) -> int:
        return len(self._members)

    def __contains__(self, name) -> bool:
        return name in self._members

    def __getstate__(self):  # the mapped arrays stay behind (a worker maps its own)
        return {"_path": self._path, "_members": self._members, "_specs": self._specs,
                "_digests": self._digests, "_loaded": {}}


@dataclass(frozen=True)
class Table:
    """A loaded lookup table: header plus arrays, verified."""

    name: str
    path: Path
    header: dict
    #: name -> array (a shipped table's: each read on first use, :class:`_NpzArrays`)
    arrays: Mapping[str, np.ndarray]
    #: Loaded content was schema-checked already: a shipped table's, or one whose content hash this designkit
    #: recorded when it checked it (a registered sensor table: :func:`load_table`'s ``checked_hash``).
    checked: bool = field(default=False, compare=False)

    @property
    def shipped(self) -> bool:
        """Loaded content is a shipped table's, verified (its hash is in :data:`SHIPPED_CONTENT_HASHES`)."""
        return self.checked and self.header.get("content_hash") in SHIPPED_CONTENT_HASHES

    @property
    def fidelity(self) -> str:
        return self.header["fidelity"]

    @property
    def threshold(self) -> float:
        return float(self.header["threshold"])

    # axes, sensor and model are parsed once per loaded table (a table query reads them several times:
    # parsing the sensor through its schema on every read cost a fifth of a query); read-only arrays
    @functools.cached_property
    def axes(self) -> dict[str, np.ndarray]:
        out = {a["name"]: np.asarray(a["values"], dtype=np.float64) for a in self.header["axes"]}
        for v in out.values():
            v.flags.writeable = False
        return out

    @property
    def axis_names(self) -> list[str]:
        return [a["name"] for a in self.header["axes"]]

    @functools.cached_property
    def sensor(self):
        from ..sensor import Sensor

        return Sensor.from_dict(self.header["sensor"], source=f"table {self.name}",
                                schema=not self.checked)

    @property
    def fixed_initial_conditions(self) -> bool:
        return bool(self.header.get("fixed_initial_conditions", True))

    @functools.cached_property
    def model(self):
        """The forward model the table was built with (tables from before the header recorded it:
        the paper's semi-infinite model, the only one there was)."""
        from ..models import get_model

        return get_model(self.header.get("model"))

    def summary(self) -> dict[str, Any]:
        """What `designkit tables show` prints."""
        h = self.header
        return {
            "name": self.name,
            "path": str(self.path),
            "fidelity": h["fidelity"],
            "sensor": h["sensor"],
            "model": self.model.to_dict(),
            # docs/schema.md: a unit is `unit` (a string) everywhere; the effusivity classes are a grid
            "effusivity_grid": {("unit" if k == "units" else k): v for k, v in h["effusivity"].items()},
            "axes": [{"name": a["name"], "unit": a["units"], "scale": a["scale"]} | {
                "min": min(a["values"]), "max": max(a["values"]), "points": len(a["values"]),
                **({"values": a["values"]} if len(a["values"]) <= 40 else {})} for a in h["axes"]],
            "arrays": sorted(h["arrays"]),
            "initial_conditions": {
                "fixed": self.fixed_initial_conditions,
                "sensor_temp_spread_c": float(h.get("config", {}).get("sensor_temp_spread_c") or 0.0),
                "ambient_temp_spread_c": float(h.get("config", {}).get("ambient_temp_spread_c") or 0.0)},
            "threshold": h["threshold"],
            "trials": h["trials"],
            "folds": h["folds"],
            "seed": h["seed"],
            "designkit_version": h["designkit_version"],
            "created": h["created"],
            "content_hash": h["content_hash"],
            "stats": h.get("stats", {}),
            "size_bytes": self.path.stat().st_size + self.path.with_suffix(".json").stat().st_size,
        }


def list_tables(folder: Path | None = None) -> list[str]:
    """Names of the tables in ``folder`` (default: the shipped tables); a missing folder is an error."""
    from .._resources import shipped_tables_dir

    if folder is not None:
        if str(folder) == "":
            raise InputError("table folder: the path is empty")
        if not Path(folder).exists():
            raise InputError(f"table folder {folder} does not exist")
        if not Path(folder).is_dir():
            raise InputError(f"table folder {folder} is not a folder")
    folder = shipped_tables_dir() if folder is None else Path(folder)
    return sorted(p.stem for p in folder.glob("*.json")
                  if p.with_suffix(".npz").is_file() and _looks_like_table(p))


def _looks_like_table(p: Path) -> bool:
    try:
        with p.open() as fh:
            return FORMAT in fh.read(200)
    except OSError:
        return False


def resolve_table(name_or_path: str | Path) -> Path:
    """The .npz path of a shipped table name or of a path (with or without suffix)."""
    from .._resources import shipped_tables_dir

    s = str(name_or_path)
    if not s.strip():
        raise InputError("table name is empty (see 'designkit tables list' for the shipped tables)")
    if "\0" in s:
        raise InputError(f"table name {s!r} holds a NUL character")
    p = Path(s)
    if p.suffix.lower() in (".yaml", ".yml"):  # was read as a zip: "corrupted or truncated (ValueError)"
        raise InputError(f"{s} is a sweep config, not a table: build its table with 'designkit sweep --config "
                         f"{s}', or give the table's .npz")
    candidates = [p, p.with_suffix(".npz")] if p.suffix in ("", ".json", ".npz") else [p]
    if p.suffix == "" and "/" not in s:
        candidates.insert(0, shipped_tables_dir() / f"{s}.npz")
    for c in candidates:
        c = c.with_suffix(".npz") if c.suffix == ".json" else c
        if c.is_file() and c.with_suffix(".json").is_file():
            return c
    shipped = ", ".join(list_tables()) or "none"
    raise InputError(f"no table {s!r} (shipped tables: {shipped}; or give a path to a .npz with its .json)")


#: Each shipped table (``tables/*.json``): its content hash, then the digest of its files as shipped.
#: Rebuilding a shipped table: put its new pair here (tests/test_tables.py and tests/test_startup.py name
#: the hash and the digest of a table missing from it).
SHIPPED_TABLES: dict[str, tuple[str, str]] = {
    "evidence-gradient-slope": (
        "sha256:b992e905af3f0312038aee27fcf71f1e96d444a9346caabd2bda2b9504f0399e",
        "xxh3_128:c2089ec1723258089fff5be2639cffde"),
    "f1-matrix-2s": (
        "sha256:60fa880ce4e50749e3aad5c48d061e41f743d89a6ca512f840793d16ade75c37",
        "xxh3_128:964c420ee6f9392bee2d8275ca9f87f2"),
    "f1-matrix-500-r0p01": ("sha256:fb4b48404a6ee109f1f24fe1f63935839f10f7097e87944ee9dac187f3fc5b65",
        "xxh3_128:82164ee19ad895f5a156ab66e5b1d4ed"),
    "f1-matrix-500-r0p02": ("sha256:a490cabcf1d28fda41f89a1e757325911544b7bf4fe31b36d66f8076d931ee5f",
        "xxh3_128:3acbaf20c1db0d99e462943af8936d58"),
    "f1-matrix-500-r0p005": ("sha256:e7e0cf174687bab40a6b3249fe771dc2701661744ce2d76263bc061e7a6ea708",
        "xxh3_128:c9d6e99399122208ad7fd1d49983bc6f"),
    "f1-matrix-500-r0p002": ("sha256:10cd27049c815fa3e7605958855603653575c982c46824e8bf0190955a435f6f",
        "xxh3_128:0ed1492909def9ff9d1e76ace2693848"),
    "f1-matrix-500-r0p001": ("sha256:66c441f90996e16d0d46415100dddfbb1564ca8c7dbd6fe8c63eee9711e66b6f",
        "xxh3_128:73ce269e3ba988145aeffa5e44260fe1"),
    "f1-matrix-fine-low": (
        "sha256:f4ecf487aec590490a63ec41215c6511218f038794ad33b52d5077bc1e5cf7ca",
        "xxh3_128:c20f14f97df8b20b488705711d1fd1ad"),
    "f1-matrix-paper": (
        "sha256:6290aff2cd7e4de3f9d1dc5ef445e66fdbb24a7cadd8e448a8733f373d111a60",
        "xxh3_128:bdcb2235357b45589de4dc1fbf83c454"),
    "ideal-paper": (
        "sha256:1820bf01e2ffe9e79d35e4c0b9f8b310b10bbe7c8d481db47c9c09aa57564bae",
        "xxh3_128:3f18fe49a25089bbd73bac9590327e88"),
    "svm-paper": (
        "sha256:55fdcf465d925b26f0ad45119eed7b7493efc8e6fb3d4983a86950354f136cab",
        "xxh3_128:63c9ba1136666bb584ceb3c72f732ff5"),
    "svm-paper-varied": (
        "sha256:7d72c28a50ff7ab6de9bfb6a3366e5c4dc5a4f6ed750a70de91c8b0098abd7b5",
        "xxh3_128:8ffcfa0e5f3372adccf7f4f3507478fc"),
    "svm-fine": (
        "sha256:579969bb66d390b4c6b48c5e25b586ece1db27ed9da0fa7b51224e4d56278c90",
        "xxh3_128:5648f2d380bfb36a16d80ffd81bdcbdb"),
}

#: Content hashes of the shipped tables. Their headers passed the schema when they were built and a test
#: checks that each still does; a table whose header and arrays hash to one of these *is* that content, so
#: loading it skips the schema step (importing pydantic and building the schemas cost a fresh ``designkit
#: min-contact`` more than its question). Every other table is validated in full.
SHIPPED_CONTENT_HASHES = frozenset(content for content, _ in SHIPPED_TABLES.values())

#: Digests of the shipped tables' files (:func:`file_digest`: the .json header and the .npz's directory).
#: Files with one of these digests are a shipped content, checked in full when it was shipped
#: (tests/test_startup.py checks every shipped table again, the long way), so loading them checks the
#: digest instead of hashing every decompressed array, and
#: reads an array only when a question asks for it, hashing that array's bytes then against its shipped
#: digest (:func:`shipped_member_digests`). Files that differ (a rebuilt table, an edited one, a
#: header rewritten with other line endings) take the long way: hash, schema, consistency.
SHIPPED_FILE_DIGESTS = frozenset(files for _, files in SHIPPED_TABLES.values())


def file_digest(header_bytes: bytes, members: Mapping[str, zipfile.ZipInfo]) -> str:
    """XXH3-128 of a table's header file and its .npz's directory, as listed in :data:`SHIPPED_FILE_DIGESTS`
    (XXH3 as :func:`member_digest`, and why).

    The directory records each array's CRC-32, sizes, compression and place in the file, but it does
    not vouch for the bytes (an array edited in place keeps it): each array of a shipped table is
    hashed when first read, mapped or decompressed, and compared with :func:`shipped_member_digests`.

    >>> file_digest(b"{}", {})[:17]
    'xxh3_128:070d65bc'
    """
    h = xxhash.xxh3_128(b"designkit-table-files\0")
    h.update(len(header_bytes).to_bytes(8, "little"))
    h.update(header_bytes)
    for name in sorted(members):
        i = members[name]
        h.update(f"{name}\0{i.CRC}\0{i.compress_size}\0{i.file_size}\0{i.compress_type}\0{i.header_offset}\n"
                 .encode())
    return "xxh3_128:" + h.hexdigest()


def _read_header(path: Path, *, schema: bool = True) -> dict:
    from .._schemas import load_json

    jpath = path.with_suffix(".json")
    header = load_json(jpath, "table header")
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise InputError(f"{jpath} is not a designkit table header")
    version = header.get("schema_version")
    if version == 1:
        raise InputError(f"table {path.stem} has schema version 1, whose hash covers the arrays only (its header "
                         f"could be edited unnoticed): check its header, then re-hash it with 'python "
                         f"benchmarks/rehash_tables.py {jpath}', or rebuild it with designkit sweep")
    if version != SCHEMA_VERSION:
        raise InputError(f"table {path.stem} has schema version {version!r}; this designkit reads "
                         f"version {SCHEMA_VERSION} (rebuild it with designkit sweep)")
    if schema:
        _check_schema(header, path)
    return header


def _check_schema(header: dict, path: Path) -> None:
    from .._schemas import schemas, validate

    validate(schemas()["table"], header, f"table header {path.with_suffix('.json')}")


def load_table(name_or_path: str | Path, *, verify: bool = True, thorough: bool = False,
               checked_hash: str | None = None) -> Table:
    """Load and verify a table (shipped name or path): its content hash (header and arrays) and its
    header's schema and consistency with the arrays.

    Files of a shipped table as shipped (:data:`SHIPPED_FILE_DIGESTS`) are checked by their digest
    instead, and each array is read when a question first asks for it; ``thorough=True`` takes the
    long way for them too (``designkit tables show`` does). ``checked_hash``: the content hash of a table
    this designkit checked in full before (a registered sensor table's, recorded when it was registered):
    content with that hash skips the schema check as a shipped table's does (the content hash itself is
    still verified, so any other content gets the schema's verdict)."""
    path = resolve_table(name_or_path)
    header = _read_header(path, schema=False)
    from .._schemas import check_regular_file

    check_regular_file(path, "table")
    specs = header.get("arrays") if isinstance(header.get("arrays"), dict) else {}
    if verify:
        try:
            with zipfile.ZipFile(path) as z:
                members = _zip_members(z)
            digest = file_digest(path.with_suffix(".json").read_bytes(), members)
        except (zipfile.BadZipFile, OSError, ValueError, EOFError):
            digest = None  # the long way says what is wrong
        shipped_members = _shipped_members(digest)
        if (not thorough and shipped_members is not None
                and header.get("content_hash") in SHIPPED_CONTENT_HASHES):
            return Table(name=header["name"], path=path, header=header,
                         arrays=_NpzArrays(path, members, specs, shipped_members), checked=True)
    # a shipped table's content is checked by its hash instead of the schema (see SHIPPED_CONTENT_HASHES)
    known = verify and isinstance(header.get("content_hash"), str) and (
        header["content_hash"] in SHIPPED_CONTENT_HASHES or header["content_hash"] == checked_hash)
    if not known:
        _check_schema(header, path)
        specs = header["arrays"]
    arrays = _read_all(path, specs)
    if verify:
        try:
            got = content_hash(arrays, header)
        except Exception:  # a header the schema would refuse: let it say why
            got = None
        if known and got != header.get("content_hash"):
            known = False
            _check_schema(header, path)  # not the shipped content: the schema's verdict first, as for any table
        if got is None:
            got = content_hash(arrays, header)
        if got != header.get("content_hash"):
            raise InputError(f"table {path.name} failed its content check (hash of header and arrays mismatch): "
                             f"corrupted or edited; rebuild it with designkit sweep")
    check_table(header, arrays, path.name, schema=not known)
    return Table(name=header["name"], path=path, header=header, arrays=arrays, checked=known)


@functools.cache
def shipped_member_digests() -> dict[str, dict[str, str | tuple[str, ...]]]:
    """Digests of every array of each shipped table, as shipped (:func:`member_digests`), by table name.

    A shipped table's files are recognised by :func:`file_digest` of their header and zip directory, so that a
    question reads only the arrays (and, for a table stored uncompressed, only the rows) it needs. The
    directory does not vouch for the bytes: each array (each row of one listed row by row) is hashed when it
    is first read and compared with its digest here. Read once per process from the package's data file
    ``designkit/data/shipped_members.json`` (by its path, as ``materials.yaml`` is: importing
    importlib.resources cost a fresh question about 8 ms, the read 0.2 ms); after rebuilding a shipped table,
    regenerate it with ``python benchmarks/rehash_tables.py --members`` (tests/test_startup.py names a table
    missing from it).
    """
    path = Path(__file__).resolve().parent.parent / "data" / "shipped_members.json"
    listed = json.loads(path.read_text(encoding="utf-8"))
    return {table: {name: tuple(d) if isinstance(d, list) else d for name, d in members.items()}
            for table, members in listed.items()}


def _shipped_members(files_digest: str | None) -> dict[str, str | tuple[str, ...]] | None:
    """The member digests of the shipped table whose files have ``files_digest``, or None (not shipped)."""
    if files_digest is None or files_digest not in SHIPPED_FILE_DIGESTS:
        return None
    listed = shipped_member_digests()
    for name, (_, files) in SHIPPED_TABLES.items():
        if files == files_digest and name in listed:
            return listed[name]
    return None


def _read_all(path: Path, specs: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Every array of the .npz at ``path`` (the long way), each npy header checked against ``specs``."""
    name = "?"
    try:
        with zipfile.ZipFile(path) as z:
            members = _zip_members(z)
            extra = [i.filename for i in z.infolist() if not i.filename.endswith(".npy")]
        if extra:
            raise ValueError(f"members that are not arrays: {', '.join(extra[:3])}")
        arrays = {}
        for name, info in members.items():
            arrays[name] = _read_member(path, info, specs.get(name) if isinstance(specs, Mapping) else None)
        return arrays
    except _READ_ERRORS as exc:
        if isinstance(exc, _EditedArray):
            raise _read_error(path, name, exc) from None
        raise InputError(f"table {path.name} is corrupted or truncated ({type(exc).__name__}); "
                         f"rebuild it with designkit sweep") from None


def check_table(header: Mapping[str, Any], arrays: Mapping[str, np.ndarray], what: str, *,
                schema: bool = True) -> None:
    """The header's consistency with itself and the arrays: one-line InputError naming ``what`` otherwise.

    Axis names, order, units and values; the effusivity grid and its reference centres; every
    array listed with its shape and dtype (and none unlisted); the arrays a fidelity needs; the
    classifier protocol; the sensor (through its schema unless ``schema=False``: a shipped table) and the
    forward model.
    """
    def bad(msg: str) -> InputError:
        return InputError(f"table {what}: {msg}")

    axes = header["axes"]
    names = [a["name"] for a in axes]
    if names[-2:] != ["contact_s", "e_ref"] or names[:-2] not in (["noise_ratio"], ["noise_c", "delta_t_c"]):
        raise bad(f"axes must be noise_ratio (or noise_c, delta_t_c), contact_s, e_ref; got {', '.join(names)}")
    for a in axes:
        units, scale, _ = _AXIS_DOCS[a["name"]]
        if a["units"] != units:
            raise bad(f"axis {a['name']}: expected units {units!r}, got {a['units']!r}")
        v = np.asarray(a["values"], dtype=np.float64)
        if not np.all(np.isfinite(v)) or np.any(np.diff(v) <= 0):
            raise bad(f"axis {a['name']}: values must be finite and increasing")
        if a["name"] in ("noise_ratio", "noise_c") and np.any(v < 0) or a["name"] == "contact_s" and np.any(v <= 0):
            raise bad(f"axis {a['name']}: values out of range ({v.min():g} .. {v.max():g})")
    fixed = names[0] == "noise_ratio"
    if header.get("fixed_initial_conditions", True) != fixed:
        raise bad(f"fixed_initial_conditions is {header.get('fixed_initial_conditions')} but the axes are {names[0]}")
    eff = header["effusivity"]
    lo, hi, n, width = eff["min"], eff["max"], eff["intervals"], eff["width"]
    if not (0 <= lo < hi < math.inf) or n < 2:
        raise bad(f"effusivity grid must satisfy 0 <= min < max < inf with >= 2 intervals, got ({lo:g}, {hi:g}], {n}")
    if not math.isclose(width, (hi - lo) / n, rel_tol=1e-9):
        raise bad(f"effusivity width {width:g} is not (max - min) / intervals = {(hi - lo) / n:g}")
    e_ref = np.asarray(axes[-1]["values"], dtype=np.float64)
    centres = lo + width * (np.arange(n) + 0.5)
    if e_ref.shape != centres.shape or not np.allclose(e_ref, centres, rtol=1e-9, atol=1e-9 * hi):
        raise bad(f"axis e_ref ({e_ref.size} values) is not the centres of the {n} effusivity intervals")
    shape = [len(a["values"]) for a in axes]
    listed = header["arrays"]
    if set(listed) != set(arrays):
        extra = sorted(set(arrays) - set(listed))
        missing = sorted(set(listed) - set(arrays))
        raise bad(f"arrays in the file and in the header differ (missing {missing or 'none'}, unlisted {extra or 'none'})")
    need = {"delta_up", "delta_down"}
    if not need <= set(arrays):
        raise bad(f"a {header['fidelity']} table needs arrays {', '.join(sorted(need - set(arrays)))}")
    if header["fidelity"] == "ideal" and {"delta_up_lo", "delta_up_hi"} & set(arrays):
        raise bad("an ideal table is exact: it has no Monte Carlo interval arrays (is it an svm table?)")
    for name, a in arrays.items():
        spec = listed[name]
        if list(a.shape) != list(spec["shape"]) or str(a.dtype) != spec["dtype"]:
            raise bad(f"array {name} is {a.dtype}{list(a.shape)}, the header says {spec['dtype']}{spec['shape']}")
        if a.dtype.kind not in "fiub":
            raise bad(f"array {name} has dtype {a.dtype}; tables hold numbers only")
        expect = {"fits": shape[:-1], "chunk_wall_s": shape[:-1], "f1_matrix": shape + [n]}.get(name, shape)
        if list(a.shape) != expect:
            raise bad(f"array {name} has shape {list(a.shape)}; the axes give {expect}")
    threshold, trials, folds = header["threshold"], header["trials"], header["folds"]
    if not 2 / 3 < threshold < 1 or folds < 2 or trials < folds:
        raise bad(f"classifier protocol out of range (threshold {threshold:g}, {trials} trials, {folds} folds)")
    cfg = header["config"]
    for key, value in (("e_min", lo), ("e_max", hi), ("intervals", n), ("threshold", threshold),
                       ("trials", trials), ("folds", folds), ("seed", header["seed"]),
                       ("fidelity", header["fidelity"])):
        if key in cfg and cfg[key] != value:
            raise bad(f"config.{key} = {cfg[key]!r} disagrees with the header's {value!r}")
    from ..models import get_model
    from ..sensor import Sensor

    Sensor.from_dict(header["sensor"], source=f"table {what}: sensor", schema=schema)
    try:
        get_model(header.get("model"))
    except InputError as exc:
        raise bad(f"model: {exc}") from None
