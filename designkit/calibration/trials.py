"""Recorded touches on disk: one CSV per trial, a JSON sidecar, an index.

The CSV has the columns of the shared robot recordings,
``time_s,passive_temp_c,active_temp_c,unused_channel,force_n``: time relative
to the detected contact onset [s], the object (passive) thermistor [degC],
the heated sensor [degC], an always-empty channel kept for compatibility
(``nan``), and force [N]. A channel the rig does not have is written as
``nan``. Rows of lines that could not be read are left out (``time_s`` stays
right: it comes from the device clock or the sample count).

The sidecar ``<trial>.json`` records the profile, material, time, the sensor
and object temperatures before contact, and how the trial was cut. The folder's
``index.csv`` (columns ``file,material,trial_index``) is rebuilt from the
sidecars after every trial and can be given to ``designkit calibrate fit`` as
it is. A folder whose index lists files without a designkit sidecar (another
index, like the shared recordings') is refused rather than having those rows
dropped (:func:`check_trial_folder`).

A trial is recorded when, and only when, the index lists it. Writing one is
three atomic file replacements: the CSV, the sidecar, then the index, whose
replacement is the commit point. Ctrl-C (SIGINT) during those steps is held
until the index is written, so an interrupt never leaves a trial on disk that
no index lists; a write that fails (disk full) removes the files it wrote. Only
a hard kill between the steps can leave a complete CSV and sidecar unlisted;
the next trial written to the folder lists them (the index is rebuilt from the
sidecars).

One writer per folder. Trial numbers are the next free ones on disk, so two
programs recording into one folder at once would pick the same names and
overwrite each other's trials. A recorder holds :class:`FolderLock` (an
exclusive ``flock`` on the folder itself, released by the kernel however the
process ends) for its whole session, and :func:`write_trial` takes it for
each write when its caller does not hold it: a second recorder is refused
with one line before it records anything. Each trial's sidecar names the
recording session (``session``), so a run reports the trials it wrote, not
others the rebuilt index also lists.

A material label is checked before anything is recorded
(:func:`check_material_label`); the file name made from it is bounded
(:data:`MAX_STEM_CHARS`), the label itself is kept whole in the sidecar and
the index.
"""

from __future__ import annotations

import contextlib
import csv
import errno
import hashlib
import io
import json
import math
import os
import re
import signal
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from .._io import atomic_write_text, jsonable
from .._validation import InputError

__all__ = ["COLUMNS", "FolderBusy", "FolderLock", "MAX_LABEL_CHARS", "MAX_STEM_CHARS", "Trial",
           "check_material_label", "check_trial_folder", "load_index", "read_trial_csv", "rebuild_index",
           "recorded_trials", "session_trials", "trial_stem", "write_trial"]

COLUMNS = ("time_s", "passive_temp_c", "active_temp_c", "unused_channel", "force_n")
TRIAL_FILE_VERSION = 1


@dataclass(frozen=True)
class Trial:
    """One touch.

    Attributes
    ----------
    time_s : ndarray, shape (m,)
        Time relative to the detected contact onset [s], increasing.
    sensor_c : ndarray, shape (m,)
        Heated sensor temperature [degC].
    object_c : ndarray, shape (m,)
        Object (passive thermistor) temperature [degC]; all NaN without one.
    force_n : ndarray, shape (m,)
        Contact force [N]; all NaN without a force sensor.
    material : str
        Material label.
    source : str
        Where it came from (file path).
    meta : mapping
        Sidecar content, when there is one.
    """

    time_s: np.ndarray
    sensor_c: np.ndarray
    object_c: np.ndarray
    force_n: np.ndarray
    material: str
    source: str = ""
    meta: Mapping[str, Any] = field(default_factory=dict, compare=False)

    @property
    def has_object(self) -> bool:
        return bool(np.isfinite(self.object_c).any())

    @property
    def n_samples(self) -> int:
        return int(self.time_s.size)

    def before_contact(self) -> tuple[float, float]:
        """Mean sensor and object temperatures before contact (``time_s < 0``) [degC]; the object's NaN
        without a finite passive reading there (the caller checks that there are samples before contact)."""
        pre = self.time_s < 0
        obj = self.object_c[pre]
        ok = np.isfinite(obj)
        return float(np.mean(self.sensor_c[pre])), float(np.mean(obj[ok])) if ok.any() else math.nan


#: Longest material label [characters]: it is written into every trial's sidecar, the index and messages.
MAX_LABEL_CHARS = 100
#: Longest file-name stem made from a label (the trial number and suffix come on top; file systems allow 255 bytes).
MAX_STEM_CHARS = 48
#: Characters a spreadsheet opening index.csv reads as the start of a formula.
_FORMULA_START = "=+-@"


def check_material_label(label: object, what: str = "the material label") -> str:
    """``label`` if it can name trials, else InputError (one line) saying why.

    A label must be non-empty text of at most :data:`MAX_LABEL_CHARS` printable
    characters (no newline, tab or other control character), without spaces at
    either end, and must not start with ``=``, ``+``, ``-`` or ``@`` (a
    spreadsheet opening ``index.csv`` would run it as a formula).

    >>> check_material_label("Aluminium alloys")
    'Aluminium alloys'
    >>> check_material_label("=400")
    Traceback (most recent call last):
    ...
    designkit._validation.InputError: the material label '=400' starts with '=': a spreadsheet opening index.csv would read it as a formula; start it with a letter or digit
    """
    if not isinstance(label, str) or not label.strip():
        raise InputError(f"{what} must not be empty (it names the trials in the index)")
    if len(label) > MAX_LABEL_CHARS:
        raise InputError(f"{what} is {len(label)} characters long; at most {MAX_LABEL_CHARS} are allowed (it is "
                         f"written into every trial's file and the index): {label[:40]!r}...")
    bad = next((c for c in label if not c.isprintable()), None)
    if bad is not None:
        raise InputError(f"{what} {label!r} contains {bad!r}: use printable characters only (no newline, tab or "
                         "control character)")
    if label != label.strip():
        raise InputError(f"{what} {label!r} has spaces at its start or end ('wood ' and 'wood' would be two "
                         "materials): remove them")
    if label[0] in _FORMULA_START:
        raise InputError(f"{what} {label!r} starts with {label[0]!r}: a spreadsheet opening index.csv would read it "
                         "as a formula; start it with a letter or digit")
    return label


def trial_stem(label: str) -> str:
    """The file-name stem of a label's trials: letters and digits, lower case, at most :data:`MAX_STEM_CHARS`.

    A longer stem is cut and given 8 hex digits of the label's SHA-256, so that
    two long labels sharing their start stay apart.

    >>> trial_stem("Aluminium alloys")
    'aluminium_alloys'
    >>> len(trial_stem("w" * 300)) <= MAX_STEM_CHARS
    True
    """
    slug = re.sub(r"[^A-Za-z0-9]+", "_", label).strip("_").lower() or "material"
    if len(slug) > MAX_STEM_CHARS:
        digest = hashlib.sha256(label.encode("utf-8")).hexdigest()[:8]
        slug = slug[:MAX_STEM_CHARS - 9].rstrip("_") + "_" + digest
    return slug


class FolderBusy(InputError):
    """Another program holds the recording folder's lock."""


class FolderLock:
    """The exclusive right to write trials into a folder (a ``flock`` on the folder itself).

    No lock file is left behind: the lock is on the folder's own descriptor,
    and the kernel releases it when the holder closes it or ends in any way
    (Ctrl-C, SIGTERM, kill -9). Creates the folder.

    Parameters
    ----------
    folder : Path
    wait_s : float
        How long :meth:`acquire` waits for another holder to let go [s]
        (0: refuse at once).
    """

    def __init__(self, folder: Path | str, wait_s: float = 0.0) -> None:
        self.folder = Path(folder)
        self.wait_s = float(wait_s)
        self._fd: int | None = None

    @property
    def held(self) -> bool:
        return self._fd is not None

    def acquire(self) -> "FolderLock":
        """Take the lock; FolderBusy (one line) if another program holds it past ``wait_s``."""
        if self._fd is not None:
            return self
        try:
            import fcntl
        except ImportError:   # pragma: no cover - Windows: no flock; one recorder per folder is then on the user
            self.folder.mkdir(parents=True, exist_ok=True)
            self._fd = -1
            return self
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        except OSError as exc:
            raise InputError(f"cannot create the trial folder {self.folder}: {exc.strerror or exc}") from None
        deadline = time.monotonic() + self.wait_s
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError as exc:
                if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES) or time.monotonic() >= deadline:
                    os.close(fd)
                    if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                        raise InputError(f"cannot lock the trial folder {self.folder}: {exc.strerror or exc}") from None
                    raise FolderBusy(
                        f"another recorder is writing trials into {self.folder} (a second 'calibrate record' or "
                        "'calibrate' with the same --out?): two at once would number their trials alike and "
                        "overwrite each other's; let it finish, or record into another folder") from None
                time.sleep(0.02)
        self._fd = fd
        return self

    def release(self) -> None:
        if self._fd is not None:
            if self._fd >= 0:
                os.close(self._fd)   # closing the descriptor releases the flock
            self._fd = None

    def __enter__(self) -> "FolderLock":
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()


def trial_csv_text(time_s, sensor_c, object_c, force_n) -> str:
    """CSV text of one trial in the shared recordings' columns."""
    n = len(time_s)
    table = np.column_stack([time_s, object_c, sensor_c, np.full(n, np.nan), force_n])
    buf = io.StringIO()
    np.savetxt(buf, table, delimiter=",", header=",".join(COLUMNS), comments="",
               fmt=["%.6f", "%.6f", "%.6f", "%.6f", "%.6f"])
    return buf.getvalue()


def write_trial(folder: Path, material: str, time_s, sensor_c, object_c, force_n,
                meta: Mapping[str, Any], *, lock: FolderLock | None = None, stem: str | None = None) -> Path:
    """Record one trial: write its CSV and sidecar, then the index that lists it (each atomically).

    The trial number is the next free one for ``material`` in ``folder``
    (file names from :func:`trial_stem`, or ``stem`` when given). Ctrl-C
    arriving meanwhile is held until the index is written (see the module
    docstring), so on return, or on KeyboardInterrupt raised from here, the
    trial is recorded; on any other error nothing of it is left. ``lock``: the
    caller's held :class:`FolderLock` of ``folder``; without one the folder is
    locked for this write (waiting up to 2 s for another writer, then
    FolderBusy). Returns the CSV path.
    """
    folder = Path(folder)
    check_trial_folder(folder)  # before writing anything
    if lock is None or not lock.held:
        with FolderLock(folder, wait_s=2.0) as own:
            return write_trial(folder, material, time_s, sensor_c, object_c, force_n, meta, lock=own, stem=stem)
    slug = trial_stem(material) if stem is None else stem
    taken = {int(m.group(1)) for p in folder.glob(f"{slug}_*.json")
             if (m := re.fullmatch(rf"{re.escape(slug)}_(\d+)\.json", p.name))}
    taken |= {int(m.group(1)) for p in folder.glob(f"{slug}_*.csv")
              if (m := re.fullmatch(rf"{re.escape(slug)}_(\d+)\.csv", p.name))}
    k = max(taken, default=0) + 1
    csv_path = folder / f"{slug}_{k:03d}.csv"
    csv_text = trial_csv_text(time_s, sensor_c, object_c, force_n)
    side = {"designkit_trial": TRIAL_FILE_VERSION, "file": csv_path.name, "material": material,
            "trial_index": k, **dict(meta)}
    side_text = json.dumps(jsonable(side), indent=2) + "\n"
    written: list[Path] = []
    with _sigint_held():
        try:
            written.append(atomic_write_text(csv_path, csv_text))
            written.append(atomic_write_text(csv_path.with_suffix(".json"), side_text))
            _write_index(folder)  # the commit point: from here on the trial is recorded
        except BaseException:
            for path in reversed(written):
                with contextlib.suppress(OSError):
                    path.unlink()
            raise
    return csv_path


@contextlib.contextmanager
def _sigint_held():
    """Hold Ctrl-C (SIGINT) while the block runs, then deliver it.

    The handler in place when the block starts (Python's, which raises
    KeyboardInterrupt, or the program's own) is called once the block is done
    if SIGINT arrived meanwhile. A no-op outside the main thread (signals are
    only handled there) and where SIGINT is ignored or has no Python handler.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGINT)
    if not callable(previous):
        yield
        return
    pending: list[tuple[int, Any]] = []
    signal.signal(signal.SIGINT, lambda signum, frame: pending.append((signum, frame)))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        if pending:
            previous(*pending[0])


def rebuild_index(folder: Path) -> Path:
    """Write ``folder/index.csv`` (file, material, trial_index) from the sidecars.

    Refuses (see :func:`check_trial_folder`) to replace an index that lists
    files which are not designkit recordings.
    """
    folder = Path(folder)
    check_trial_folder(folder)
    return _write_index(folder)


def _write_index(folder: Path) -> Path:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["file", "material", "trial_index"])
    writer.writerows(_sidecar_rows(folder))
    return atomic_write_text(folder / "index.csv", buf.getvalue())


def check_trial_folder(folder: Path | str) -> None:
    """Refuse to record into a folder whose ``index.csv`` this module would not rewrite faithfully.

    The index is rebuilt from the sidecars after every trial, so an index
    listing files that have no designkit sidecar (the shared recordings', a
    hand-made one) would lose those rows, and one that cannot be read would be
    replaced. Raises InputError naming the index and a file it lists (or
    ``folder``, when it is a file).
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder} is not a folder (the trials and their index.csv go in one)")
    index_csv = folder / "index.csv"
    if not index_csv.exists():
        return
    try:
        rows = read_index_rows(index_csv)
    except InputError as exc:
        raise InputError(f"{exc}; recording into {folder} would replace it: use another folder") from None
    ours = {name for name, _, _ in _sidecar_rows(folder)}
    foreign = [r["file"] for r in rows if r.get("file") and r["file"] not in ours and (folder / r["file"]).exists()]
    if foreign:
        raise InputError(f"index {index_csv} lists {len(foreign)} file(s) that are not designkit recordings (e.g. "
                         f"{foreign[0]}); recording into {folder} would drop them from it: use another folder")


def _sidecar_rows(folder: Path) -> list[tuple[str, str, Any]]:
    """(file, material, trial_index) of every trial in ``folder`` with a sidecar and its CSV, sorted."""
    rows = []
    from .._schemas import load_json, schemas, validate

    for side in sorted(folder.glob("*.json")):
        try:
            meta = load_json(side, "trial sidecar")
        except ValueError:
            continue
        if not isinstance(meta, dict) or "designkit_trial" not in meta:
            continue
        try:  # a sidecar whose fields have the wrong types, or that names a file elsewhere, lists nothing
            validate(schemas()["sidecar"], meta, f"trial sidecar {side}")
        except ValueError:
            continue
        csv_path = folder / str(meta.get("file", side.with_suffix(".csv").name))
        if csv_path.is_file():
            rows.append((csv_path.name, str(meta.get("material", "")), meta.get("trial_index", "")))
    rows.sort(key=lambda r: (r[1], r[2] if isinstance(r[2], int) else 0, r[0]))
    return rows


def _first_bad_row(text: str, columns: int) -> str:
    """Why numpy could not read a trial's rows, in the file's terms (line number, what is wrong)."""
    for n, row in enumerate(csv.reader(io.StringIO(text, newline="")), start=1):
        if n == 1 or not row:
            continue
        if len(row) != columns:
            return (f"line {n} has {len(row)} of the header's {columns} columns (a truncated or damaged file; "
                    "record the trial again or delete that line)")
        for k, v in enumerate(row):
            try:
                float(v)
            except ValueError:
                return f"line {n}, column {k + 1}: {v.strip()!r} is not a number"
    return "a row is not numbers separated by commas"


def read_trial_csv(path: Path, material: str = "") -> Trial:
    """Read a trial CSV (the shared recordings' columns; passive and force optional)."""
    from .._schemas import load_json, read_text, schemas, validate

    path = Path(path)
    text = read_text(path, "trial")  # also refuses a FIFO, a device or a folder before reading
    header = next(csv.reader(io.StringIO(text, newline="")), None)
    if not header:
        raise InputError(f"trial {path} is empty")
    header = [h.strip() for h in header]
    missing = [c for c in ("time_s", "active_temp_c") if c not in header]
    if missing:
        raise InputError(f"trial {path} lacks column(s) {', '.join(missing)} "
                         f"(expected {','.join(COLUMNS)})")
    try:
        data = np.loadtxt(io.StringIO(text, newline=None), delimiter=",", skiprows=1, ndmin=2, dtype=np.float64)
    except ValueError:
        raise InputError(f"trial {path}: {_first_bad_row(text, len(header))}") from None
    if data.shape[0] < 3 or data.shape[1] != len(header):
        raise InputError(f"trial {path}: need at least 3 rows of {len(header)} columns, got {data.shape}")

    def col(name):
        return data[:, header.index(name)] if name in header else np.full(data.shape[0], np.nan)

    t = col("time_s")
    keep = np.isfinite(t) & np.isfinite(col("active_temp_c"))
    t = t[keep]
    if t.size < 3 or np.any(np.diff(t) <= 0):
        raise InputError(f"trial {path}: time_s must increase from row to row")
    meta: dict[str, Any] = {}
    side = path.with_suffix(".json")
    if side.is_file():
        meta = load_json(side, "trial sidecar")
        if not isinstance(meta, dict):
            raise InputError(f"trial sidecar {side}: expected a mapping of keys, got {type(meta).__name__}")
        validate(schemas()["sidecar"], {"designkit_trial": 1, **meta}, f"trial sidecar {side}")
    return Trial(time_s=t, sensor_c=col("active_temp_c")[keep], object_c=col("passive_temp_c")[keep],
                 force_n=col("force_n")[keep], material=material or str(meta.get("material", "")),
                 source=str(path), meta=meta)


def read_index_rows(index_csv: Path | str) -> list[dict[str, str]]:
    """The rows of a trial index (a UTF-8 CSV with at least the columns ``file`` and ``material``).

    Raises InputError, with the path, when it cannot be read, is not UTF-8 or lacks those columns.
    """
    from .._schemas import read_text

    index_csv = Path(index_csv)
    reader = csv.DictReader(io.StringIO(read_text(index_csv, "index"), newline=""))
    rows = list(reader)
    if not {"file", "material"} <= set(reader.fieldnames or ()):
        raise InputError(f"index {index_csv} needs columns file and material")
    return rows


def session_trials(folder: Path | str, session: str) -> list[Path]:
    """The trials of ``folder``'s index whose sidecar names recording session ``session``, in index order."""
    from .._schemas import load_json

    out = []
    for path in recorded_trials(folder):
        try:
            meta = load_json(path.with_suffix(".json"), "trial sidecar")
        except (ValueError, OSError):
            continue
        if isinstance(meta, dict) and meta.get("session") == session:
            out.append(path)
    return out


def recorded_trials(folder: Path | str) -> list[Path]:
    """The trials recorded in ``folder``: the CSVs its ``index.csv`` lists, in its order.

    Empty when there is no index yet. This, not what a recorder remembers
    writing, is what is on disk (a trial is recorded when the index lists it).
    """
    index_csv = Path(folder) / "index.csv"
    if not index_csv.exists():
        return []
    return [index_csv.parent / r["file"] for r in read_index_rows(index_csv) if r.get("file")]


def load_index(index_csv: Path, only: Sequence[str] | None = None) -> list[Trial]:
    """Read every trial an index lists (columns ``file`` and ``material``; others ignored).

    Paths are relative to the index's folder. ``only`` keeps those materials
    (an unknown name in it is an error).
    """
    index_csv = Path(index_csv)
    rows = read_index_rows(index_csv)
    materials = sorted({r["material"] or "" for r in rows})
    numbered = list(enumerate(rows, start=2))  # CSV line numbers, header = line 1
    if only:
        unknown = [m for m in only if m not in materials]
        if unknown:
            raise InputError(f"--only names material(s) not in {index_csv.name}: {', '.join(unknown)} "
                             f"(it has {', '.join(materials)})")
        numbered = [(n, r) for n, r in numbered if r["material"] in set(only)]
    trials = []
    seen: dict[Path, int] = {}
    for line_no, r in numbered:
        if not r.get("file") or not r.get("material"):
            raise InputError(f"index {index_csv} line {line_no}: empty file or material")
        path = (index_csv.parent / r["file"]).resolve()
        if path in seen:  # fitted twice, it counted as two touches: a confidence the data does not have
            raise InputError(f"index {index_csv} lists {r['file']} twice (lines {seen[path]} and {line_no}); "
                             "remove one of them")
        seen[path] = line_no
        trials.append(read_trial_csv(index_csv.parent / r["file"], r["material"]))
    return trials
