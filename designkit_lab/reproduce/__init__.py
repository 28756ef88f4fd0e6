"""The paper's analyses, reproduced: ``designkit reproduce --out DIR``.

Writes ``DIR/report.md`` (with PNG figures in ``DIR/figures`` and every
figure's numbers as CSV in ``DIR/data``) and ``DIR/report.json`` (every number
of the report, machine-readable), each of our numbers beside the paper's.

Sections (``only=`` / ``--only`` picks some):

``f1-matrices``   Fig. 3, F1 matrices at contact 4 s and 1 s
``delta-curves``  Figs. 4 and 5, delta(e) curves with Monte Carlo bands and the ideal bound
``effusivity``    Fig. 7, effusivity ranges of the materials database
``node-graphs``   Fig. 6, indistinguishable material pairs as node graphs
``table1``        Table I, % indistinguishable pairs and mean F1, with measured explanations
``guideline``     the 35k vs 20k contact-time guideline, from a table and computed
``real-robot``    train real / test real on the shared robot recordings
``sim-to-real``   train on simulated touches (calibrated sensor), test on the real ones
``multiclass``    k materials at once (simulated database, the paper's 12 materials)

Heavy parts come from shipped lookup tables built by the sweep engine
(``tables/*.yaml``); what is computed at run time is small (about 5 minutes
on 2 cores for the whole report). The library does the work; the command
line (:mod:`designkit_lab.cli.reproduce`) adds a progress bar.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

from designkit._validation import InputError
from ._report import Context, ReproduceSettings, SectionResult, default_robot_data_dir, fmt, md_table

__all__ = [
    "SECTIONS",
    "ReproduceResult",
    "ReproduceSettings",
    "SectionResult",
    "default_robot_data_dir",
    "parse_only",
    "reproduce",
]


def _registry() -> dict[str, tuple[Callable[[Context], SectionResult], float]]:
    """Section name -> (function, rough share of the run time, for progress bars)."""
    from .curves import section_delta_curves, section_effusivity, section_guideline
    from .matrices import section_f1_matrices, section_node_graphs
    from .table1 import section_table1
    from .multiclass import section_multiclass
    from .prediction import section_real_prediction
    from .robot import section_real_robot, section_sim_to_real

    return {
        "f1-matrices": (section_f1_matrices, 2.0),
        "delta-curves": (section_delta_curves, 2.0),
        "effusivity": (section_effusivity, 1.0),
        "node-graphs": (section_node_graphs, 3.0),
        "table1": (section_table1, 20.0),
        "guideline": (section_guideline, 15.0),
        "real-robot": (section_real_robot, 10.0),
        "sim-to-real": (section_sim_to_real, 12.0),
        "real-prediction": (section_real_prediction, 12.0),
        "multiclass": (section_multiclass, 30.0),
    }


#: Section names in report order.
SECTIONS: tuple[str, ...] = ("f1-matrices", "delta-curves", "effusivity", "node-graphs", "table1", "guideline",
                             "real-robot", "sim-to-real", "real-prediction", "multiclass")


def parse_only(only: "str | Sequence[str] | None") -> tuple[str, ...]:
    """Section names from ``--only`` values (repeated and/or comma-separated); all when empty."""
    if only is None:
        return SECTIONS
    items = [only] if isinstance(only, str) else list(only)
    names = [p.strip() for item in items for p in str(item).split(",") if p.strip()]
    if not names:
        return SECTIONS
    unknown = [n for n in names if n not in SECTIONS]
    if unknown:
        raise InputError(f"unknown section(s) {', '.join(unknown)}; choose from: {', '.join(SECTIONS)}")
    return tuple(n for n in SECTIONS if n in names)


@dataclass(frozen=True)
class ReproduceResult:
    """What :func:`reproduce` wrote."""

    out_dir: Path
    report: Path
    report_json: Path
    sections: tuple[SectionResult, ...]
    wall_s: float

    @property
    def figures(self) -> tuple[Path, ...]:
        return tuple(self.out_dir / f for s in self.sections for f in s.figures)

    def section(self, name: str) -> SectionResult:
        for s in self.sections:
            if s.name == name:
                return s
        raise KeyError(name)

    def to_dict(self) -> dict:
        return {"out_dir": str(self.out_dir), "report": str(self.report), "report_json": str(self.report_json),
                "wall_s": self.wall_s, "figures": [str(f) for f in self.figures],
                "sections": {s.name: s.to_dict() for s in self.sections}}


def reproduce(out_dir: "str | Path", only: "str | Sequence[str] | None" = None,
              settings: ReproduceSettings = ReproduceSettings(),
              on_progress: Callable[[str, float, float], None] | None = None) -> ReproduceResult:
    """Run the sections and write ``out_dir/report.md`` and ``out_dir/report.json``.

    Parameters
    ----------
    out_dir : path
        Report folder (created; files in it are replaced atomically).
    only : str or sequence of str, optional
        Section names (see :data:`SECTIONS`); all by default.
    settings : ReproduceSettings
    on_progress : callable(section, completed, total), optional
        Progress in arbitrary units (the sections' weights), for a progress bar.

    Returns
    -------
    ReproduceResult
    """
    from designkit._io import atomic_write_text, jsonable

    names = parse_only(only)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out} exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    registry = _registry()
    total = sum(registry[n][1] for n in names)
    done = 0.0
    t0 = time.perf_counter()
    ctx = Context(settings, out)  # one per run: loaded tables and caches shared by the sections
    results: list[SectionResult] = []
    for name in names:
        fn, weight = registry[name]
        if on_progress is not None:
            on_progress(name, done, total)
            ctx.set_step(lambda frac, _n=name, _b=done, _w=weight: on_progress(_n, _b + frac * _w, total))
        results.append(fn(ctx))
        done += weight
        if on_progress is not None:
            on_progress(name, done, total)
    wall = time.perf_counter() - t0
    report = out / "report.md"
    atomic_write_text(report, _markdown(results, settings, ctx, wall, names))
    result = ReproduceResult(out, report, out / "report.json", tuple(results), wall)
    payload = {"designkit_reproduce": 1, **result.to_dict(), "settings": _settings_dict(settings),
               "tables": ctx.tables_used()}
    atomic_write_text(result.report_json, json.dumps(jsonable(payload), indent=1, allow_nan=False) + "\n")
    return result


def _settings_dict(s: ReproduceSettings) -> dict:
    return {"tables_dir": None if s.tables_dir is None else str(s.tables_dir), "robot_data": str(s.robot_data_dir),
            "quick": s.quick, "seed": s.seed, "jobs": s.jobs}


def _markdown(results: Sequence[SectionResult], settings: ReproduceSettings, ctx: Context, wall: float,
              names: Sequence[str]) -> str:
    from designkit import __version__

    lines = [
        "# The paper's analyses, reproduced with designkit",
        "",
        "Reference: Bai et al., *Analyzing Material Recognition Performance of Thermal Tactile Sensing using a "
        "Large Materials Database and a Real Robot* (semi-infinite contact model, SVM on raw samples + local "
        "slope, 3-fold F1, Φ = 0.9). Every number below stands beside the paper's; figures are in `figures/`, "
        "their numbers in `data/` and all numbers in `report.json`.",
        "",
        f"Generated by designkit {__version__} with `designkit reproduce` in {wall:.0f} s"
        + (" (**quick mode**: fewer Monte Carlo repeats and trials at run time; not the reference report)"
           if settings.quick else "") + (f"; sections: {', '.join(names)}" if tuple(names) != SECTIONS else "")
        + ".",
        "",
    ]
    used = ctx.tables_used()
    if used:
        lines += ["Tables used: " + "; ".join(f"`{t['name']}` ({t['content_hash'][:19]}…)" for t in used) + ".", ""]
    lines += ["## Contents", ""] + [f"- [{r.title}](#{_anchor(r.title)})" + (" — *partly skipped*" if r.skipped else "")
                                    for r in results] + [""]
    comps = [c for r in results for c in r.comparisons]
    if comps:
        lines += ["## Our numbers beside the paper's", "",
                  md_table(["quantity", "ours", "paper", "difference", "beyond tolerance"],
                           [[c.quantity, fmt(c.ours, 4), fmt(c.paper, 4), fmt(c.difference, 3),
                             "**yes**" if c.beyond_tolerance else "no"] for c in comps], align="lrrrl"),
                  ""]
        beyond = [c for c in comps if c.beyond_tolerance]
        if beyond:
            lines += ["Differences beyond tolerance (3 points of %, 0.03 F1), explained with the evidence measured "
                      "in the sections below:", ""]
            lines += [f"- **{c.quantity}**: ours {fmt(c.ours, 4)}, paper {fmt(c.paper, 4)}: {c.explanation or '—'}."
                      for c in beyond] + [""]
    for r in results:
        lines += [f"## {r.title}", "", r.markdown.rstrip(), "", f"*Section computed in {r.wall_s:.1f} s.*", ""]
    return "\n".join(lines)


def _anchor(title: str) -> str:
    import re

    return re.sub(r"[^a-z0-9 -]", "", title.lower()).strip().replace(" ", "-")
