"""Where shipped files are: inside the installed package, or in the source tree.

A non-editable install puts ``tables/`` at ``designkit/shipped_tables`` and
``calibration/profiles/`` at ``designkit/profiles`` (see pyproject.toml); in a
source checkout (tests, editable installs) they are read where they live.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["profiles_dir", "shipped_tables_dir"]

_PKG = Path(__file__).resolve().parent
_REPO = _PKG.parent


def _first_dir(*candidates: Path) -> Path:
    for c in candidates:
        if c.is_dir():
            return c
    return candidates[0]


def shipped_tables_dir() -> Path:
    """Folder of the shipped lookup tables."""
    return _first_dir(_PKG / "shipped_tables", _REPO / "tables")


def profiles_dir() -> Path:
    """Folder of the shipped device profiles."""
    return _first_dir(_PKG / "profiles", _REPO / "calibration" / "profiles")
