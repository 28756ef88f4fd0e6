"""Report plumbing: settings, the per-run context, section results, markdown helpers."""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from designkit._validation import InputError

__all__ = [
    "Comparison",
    "Context",
    "ReproduceSettings",
    "SectionResult",
    "default_robot_data_dir",
    "fmt",
    "md_table",
]


def default_robot_data_dir(cwd: Path | str | None = None) -> Path:
    """Where the shared robot recordings are looked for.

    ``$DESIGNKIT_ROBOT_DATA`` if set; else the first ``shared/data/robot-thermal-recordings`` (with its
    ``index.csv``) in the working directory ``cwd`` or one of its parents, so that running from a
    repository (or any folder in it) beside ``shared/`` finds them; else the same folder beside the
    source checkout designkit is imported from (never inside an installed package's site-packages).
    When none has the recordings: ``../shared/data/robot-thermal-recordings`` from ``cwd``, which the
    report names as where it looked.

    >>> import os, tempfile
    >>> from pathlib import Path
    >>> old = os.environ.pop("DESIGNKIT_ROBOT_DATA", None)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     data = Path(tmp, "shared", "data", "robot-thermal-recordings")
    ...     data.mkdir(parents=True); _ = (data / "index.csv").write_text("")
    ...     Path(tmp, "repo", "examples").mkdir(parents=True)
    ...     default_robot_data_dir(Path(tmp, "repo", "examples")) == data.resolve()
    True
    >>> if old is not None: os.environ["DESIGNKIT_ROBOT_DATA"] = old
    """
    env = os.environ.get("DESIGNKIT_ROBOT_DATA")
    if env:
        return Path(env)
    sub = Path("shared") / "data" / "robot-thermal-recordings"
    here = (Path.cwd() if cwd is None else Path(cwd)).resolve()
    candidates = [base / sub for base in (here, *here.parents)]
    checkout = Path(__file__).resolve().parents[2]
    if (checkout / "pyproject.toml").is_file() and (checkout / "designkit").is_dir():  # a source checkout
        candidates.append(checkout.parent / sub)
    for cand in candidates:
        if (cand / "index.csv").is_file():
            return cand
    return here.parent / sub


@dataclass(frozen=True)
class ReproduceSettings:
    """How a reproduction runs.

    Parameters
    ----------
    tables_dir : path, optional
        Folder searched for lookup tables before the shipped ones (tests put
        small tables with the shipped names there).
    robot_data : path, optional
        Folder of the real robot recordings (``index.csv`` + trial CSVs);
        default :func:`default_robot_data_dir`.
    quick : bool
        Fewer Monte Carlo repeats, trials and subsets in the parts computed at
        run time (for tests and a first look); the report says so.
    seed : int
        Seed of every random draw made at run time.
    jobs : int
        Worker processes for the exact queries (1: in-process).
    figure_format : {"png", "svg", "pdf"}
        Format of the report's figures: png (200 dpi) or vector (svg, pdf).
    """

    tables_dir: Path | None = None
    robot_data: Path | None = None
    quick: bool = False
    seed: int = 0
    jobs: int = 1
    figure_format: str = "png"

    def __post_init__(self) -> None:
        if int(self.seed) != self.seed or self.seed < 0:
            raise InputError(f"seed must be a non-negative integer, got {self.seed}")
        from designkit._workers import worker_count

        worker_count(self.jobs)  # not a count, none or absurdly many: refused here, before any section runs
        fmt = str(self.figure_format).strip().lower()
        if fmt not in ("png", "svg", "pdf"):
            raise InputError(f"figure format must be png, svg or pdf, got {self.figure_format!r}")
        object.__setattr__(self, "figure_format", fmt)
        if self.tables_dir is not None:
            object.__setattr__(self, "tables_dir", Path(self.tables_dir))
        if self.robot_data is not None:
            object.__setattr__(self, "robot_data", Path(self.robot_data))

    @property
    def robot_data_dir(self) -> Path:
        return self.robot_data if self.robot_data is not None else default_robot_data_dir()


@dataclass(frozen=True)
class Comparison:
    """One of our numbers beside the paper's.

    ``explanation`` is filled when the difference exceeds ``tolerance``.
    """

    quantity: str
    ours: float | None
    paper: float
    tolerance: float
    explanation: str = ""

    @property
    def difference(self) -> float | None:
        return None if self.ours is None else self.ours - self.paper

    @property
    def beyond_tolerance(self) -> bool:
        d = self.difference
        return d is not None and abs(d) > self.tolerance

    def to_dict(self) -> dict[str, Any]:
        return {"quantity": self.quantity, "ours": self.ours, "paper": self.paper,
                "difference": self.difference, "tolerance": self.tolerance,
                "beyond_tolerance": self.beyond_tolerance, "explanation": self.explanation}


@dataclass(frozen=True)
class SectionResult:
    """What one section of the report produced.

    Attributes
    ----------
    name, title : str
        Section key (``--only``) and heading.
    markdown : str
        Body of the section (without its heading).
    numbers : dict
        Every number of the section, JSON-able (``report.json``).
    figures : tuple of str
        Figure paths relative to the report folder.
    comparisons : tuple of Comparison
        Our numbers beside the paper's.
    skipped : str or None
        Why the section (or its main part) could not run.
    wall_s : float
        Compute time [s].
    """

    name: str
    title: str
    markdown: str
    numbers: dict = field(default_factory=dict)
    figures: tuple[str, ...] = ()
    comparisons: tuple[Comparison, ...] = ()
    skipped: str | None = None
    wall_s: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "title": self.title, "numbers": self.numbers, "figures": list(self.figures),
                "comparisons": [c.to_dict() for c in self.comparisons], "skipped": self.skipped,
                "wall_s": self.wall_s}


class Context:
    """Per-run state shared by the sections: settings, output folder, loaded tables, caches.

    ``step(done, total)`` reports progress inside the running section.
    """

    def __init__(self, settings: ReproduceSettings, out_dir: Path,
                 on_step: Callable[[float], None] | None = None):
        self.settings = settings
        self.out_dir = Path(out_dir)
        self.fig_dir = self.out_dir / "figures"
        self.data_dir = self.out_dir / "data"
        self._tables: dict[str, Any] = {}
        self._problems: dict[str, str | None] = {}
        self.cache: dict[Any, Any] = {}
        self._on_step = on_step
        self.started = time.perf_counter()

    # ---------------------------------------------------------------- progress
    def set_step(self, on_step: Callable[[float], None] | None) -> None:
        """Where :meth:`step` reports (the running section's share of a progress bar)."""
        self._on_step = on_step

    def step(self, done: float, total: float) -> None:
        if self._on_step is not None and total > 0:
            self._on_step(min(max(done / total, 0.0), 1.0))

    # ------------------------------------------------------------------ tables
    def table(self, name: str):
        """The lookup table ``name`` (settings.tables_dir first, then shipped), or None when absent.

        Why a table is missing or unusable is kept for the report (:meth:`table_problem`).
        """
        if name not in self._tables:
            from designkit.tables.store import load_table

            found, problem = None, None
            cands: list[Any] = []
            if self.settings.tables_dir is not None:
                local = self.settings.tables_dir / f"{name}.npz"
                if local.is_file():
                    cands.append(local)
            cands.append(name)
            for cand in cands:
                try:
                    found = load_table(cand)
                    break
                except InputError as exc:
                    problem = str(exc)
            self._tables[name] = found
            self._problems[name] = None if found is not None else problem
        return self._tables[name]

    def table_problem(self, name: str) -> str:
        """One line saying why table ``name`` is not available, with how to build it."""
        self.table(name)
        why = self._problems.get(name) or "not found"
        return (f"table `{name}` is not available ({why}); build it with "
                f"`designkit sweep --config tables/{name}.yaml --out tables/`")

    def tables_used(self) -> list[dict[str, Any]]:
        return [{"name": n, "path": str(t.path), "content_hash": t.header.get("content_hash"),
                 "created": t.header.get("created")} for n, t in sorted(self._tables.items()) if t is not None]

    # ----------------------------------------------------------------- outputs
    def save_figure(self, fig, name: str) -> str:
        """Save a matplotlib figure as ``figures/NAME.png``, ``.svg`` and ``.pdf``; returns the report-relative
        path of the one in the settings' figure format (the one the report shows)."""
        from designkit.figures import FIGURE_FORMATS, save_figure

        fmt = self.settings.figure_format
        self.fig_dir.mkdir(parents=True, exist_ok=True)
        tmp = self.fig_dir / f".{name}.tmp.{fmt}"
        save_figure(fig, tmp)
        for f in FIGURE_FORMATS:
            os.replace(tmp.with_suffix(f".{f}"), self.fig_dir / f"{name}.{f}")
        return f"figures/{name}.{fmt}"

    def save_csv(self, name: str, header: Sequence[str], rows) -> str:
        """Write ``data/NAME.csv`` atomically; returns the report-relative path."""
        import csv
        import io

        from designkit._io import atomic_write_text

        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(list(header))
        for r in rows:
            w.writerow([_csv_cell(x) for x in r])
        atomic_write_text(self.data_dir / f"{name}.csv", buf.getvalue())
        return f"data/{name}.csv"

    def save_matrix_csv(self, name: str, matrix: np.ndarray, axis_values: np.ndarray, axis_label: str) -> str:
        """A square matrix as CSV: first row and column are the axis values."""
        rows = [[f"{v:g}"] + [_csv_cell(x) for x in row] for v, row in zip(axis_values, matrix)]
        return self.save_csv(name, [axis_label] + [f"{v:g}" for v in axis_values], rows)


def _csv_cell(x: Any) -> Any:
    if isinstance(x, (float, np.floating)):
        return "" if not math.isfinite(float(x)) else f"{float(x):.6g}"
    return x


# ------------------------------------------------------------------ markdown
def fmt(x: Any, digits: int = 3, unit: str = "") -> str:
    """A number for a markdown cell: ``—`` for None/NaN, ``digits`` significant digits."""
    if x is None:
        return "—"
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return f"{int(x)}{unit}"
    v = float(x)
    if not math.isfinite(v):
        return "—"
    return f"{v:.{digits}g}{unit}"


def md_table(headers: Sequence[str], rows: Sequence[Sequence[Any]], align: str | None = None) -> str:
    """A GitHub markdown table; cells already formatted as strings (others through :func:`fmt`)."""
    def cell(x):
        return str(x) if isinstance(x, str) else fmt(x)

    align = align or ("l" + "r" * (len(headers) - 1))
    sep = ["---:" if a == "r" else ":---:" if a == "c" else ":---" for a in align]
    lines = ["| " + " | ".join(headers) + " |", "| " + " | ".join(sep) + " |"]
    lines += ["| " + " | ".join(cell(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)
