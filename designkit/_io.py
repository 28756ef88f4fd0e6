"""Small file helpers: atomic writes, so that an interrupted run never leaves a
half-written file where a complete one is expected."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

__all__ = ["WriteError", "atomic_write_bytes", "atomic_write_text", "fsync_folder", "jsonable"]


class WriteError(OSError):
    """A file could not be written; its message is one line naming the file the caller asked for.

    An :class:`OSError` (``errno`` kept) whose text has no ``[Errno N]`` and no temporary file name.
    """

    def __str__(self) -> str:
        return str(self.strerror)


class _IsAFolder(WriteError, IsADirectoryError):
    """A folder where a file was to be written: one line, without ``[Errno 21]`` or the path repeated."""


def _cannot_write(path: Path, exc: OSError) -> WriteError:
    return WriteError(exc.errno, f"cannot write {path}: {exc.strerror or exc}")


def atomic_write_bytes(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file and an atomic rename.

    A crash or kill at any moment leaves either the old file or the new one,
    never a truncated mix. The data are flushed to disk before the rename, and the folder after it.

    A destination that exists and is not a regular file (``/dev/null``, a
    terminal, a FIFO) is written to as it is: renaming over it would replace
    the device with a file (as root, ``--out /dev/null`` did exactly that).
    A folder is refused. Errors are :class:`WriteError` naming ``path``, never the temporary file:

    >>> import tempfile
    >>> with tempfile.NamedTemporaryFile() as f:  # doctest: +ELLIPSIS
    ...     atomic_write_bytes(Path(f.name) / "x.h", b"")  # a file where a folder should be
    Traceback (most recent call last):
    ...
    designkit._io.WriteError: cannot write /.../x.h: Not a directory
    """
    import stat

    path = Path(path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as exc:
        raise _cannot_write(path, exc) from None
    if mode is not None and stat.S_ISDIR(mode):
        raise _IsAFolder(21, f"cannot write {path}: it is a folder; give a file name")
    if mode is not None and not stat.S_ISREG(mode):
        with open(path, "wb") as fh:
            fh.write(data)
        return path
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        import tempfile  # here: the commands that only print (through jsonable) never need it

        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:  # name the file the user asked for, not the temporary one beside it
        raise _cannot_write(path, exc) from None
    try:
        os.fchmod(fd, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual permissions
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError):
            raise _cannot_write(path, exc) from None
        raise
    fsync_folder(path.parent)  # the rename itself reaches the disk: a power cut keeps the new file's name
    return path


def fsync_folder(folder: Path) -> None:
    """Flush a folder's entries (a rename, a new file) to disk; where a folder cannot be opened or synced
    (some file systems, other platforms) nothing more can be done, and nothing is said."""
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path: Path, text: str) -> Path:
    """Text version of :func:`atomic_write_bytes` (UTF-8)."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def jsonable(obj: Any) -> Any:
    """``obj`` as plain JSON types: mappings as dicts with text keys, tuples as lists, numpy arrays and
    scalars as lists and numbers, NaN and inf as None, paths as text."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "tolist"):  # numpy arrays and scalars
        return jsonable(obj.tolist())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, Path):
        return str(obj)
    return obj
