"""Where shipped files are: inside the installed package, or in the source tree.

A non-editable install puts ``tables/`` at ``designkit/shipped_tables`` and
``calibration/profiles/`` at ``designkit/profiles`` (see pyproject.toml); in a
source checkout (tests, editable installs) they are read where they live.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["DATA_DIR_VARIABLE", "data_dir", "profiles_dir", "shipped_tables_dir"]

#: Environment variable naming designkit's data folder instead of the user's (tests, shared machines).
DATA_DIR_VARIABLE = "DESIGNKIT_DATA_DIR"

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


def data_dir() -> Path:
    """designkit's data folder (what it records for later runs: the sensor-table registry, the sensor files it
    checked): ``$DESIGNKIT_DATA_DIR`` or the user's data folder (``platformdirs.user_data_dir("designkit")``)."""
    import os

    base = os.environ.get(DATA_DIR_VARIABLE)
    if not base:
        import platformdirs

        base = platformdirs.user_data_dir("designkit", appauthor=False)
    return Path(base)
