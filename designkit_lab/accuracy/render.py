"""The accuracy report as a page: ``accuracy.md``, its figures and ``accuracy.json``.

:func:`render_markdown` turns a :class:`~designkit_lab.accuracy.run.BenchReport`
into ``docs/accuracy.md``; :func:`write_report` writes it with its figures
(matplotlib, from the ``figures`` extra) and the JSON record
(``designkit bench --out docs``). Nothing here measures anything.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from designkit._io import jsonable
from designkit._validation import InputError
from .results import CostCurve, Row

if TYPE_CHECKING:  # pragma: no cover
    from .run import BenchReport

__all__ = ["COVERAGE_FILES", "FIGURES_HINT", "VARIED_COVERAGE_FIGURE", "VARIED_COVERAGE_FILE", "coverage_markdown", "curves_markdown", "format_time", "format_value",
           "insert_coverage", "insert_varied_coverage", "markdown_cell", "pareto_figure", "plot_costs", "print_report", "plot_pareto", "render_markdown",
           "require_figures", "rows_markdown", "varied_coverage_cases", "varied_coverage_figure",
           "varied_coverage_markdown", "write_coverage", "write_report", "write_varied_coverage"]

#: The coverage benchmark's record and figure beside ``accuracy.md`` (benchmarks/bench_coverage.py --docs).
COVERAGE_FILES = ("accuracy_coverage.json", "accuracy_coverage.png")
_COV_START, _COV_END = "<!-- COVERAGE START -->", "<!-- COVERAGE END -->"

#: The coverage record under varied initial conditions beside ``accuracy.md``
#: (benchmarks/bench_coverage_varied.py --docs).
VARIED_COVERAGE_FILE = "accuracy_coverage_varied.json"
#: Its figure (:func:`varied_coverage_figure`), beside it.
VARIED_COVERAGE_FIGURE = "accuracy_coverage_varied.png"
_VAR_START, _VAR_END = "<!-- VARIED COVERAGE START -->", "<!-- VARIED COVERAGE END -->"

#: What to install for the report's figures.
FIGURES_HINT = "pip install 'designkit[figures]'"


# ============================================================ formatting
def _pct(x: float | None) -> str:
    """A fraction as a whole percentage for a table cell (``—`` when missing).

    >>> _pct(0.8823), _pct(None)
    ('88 %', '—')
    """
    return "—" if x is None else f"{100 * x:.0f} %"


def format_value(x: float | None, digits: int = 2) -> str:
    """A number for a table cell: ``—`` when missing, scientific when very large or small.

    Examples
    --------
    >>> format_value(0.12345, 3), format_value(123456.0), format_value(None), format_value(0.0)
    ('0.123', '1.2e+05', '—', '0')
    """
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def format_time(s: float | None) -> str:
    """A duration [s] in µs, ms or s, three significant digits (``—`` when missing).

    Examples
    --------
    >>> format_time(2.5e-5), format_time(0.0123), format_time(42.0), format_time(float("nan"))
    ('25 µs', '12.3 ms', '42 s', '—')
    """
    if s is None or not math.isfinite(s):
        return "—"
    if s < 1e-3:
        return f"{s * 1e6:.3g} µs"
    if s < 1:
        return f"{s * 1e3:.3g} ms"
    return f"{s:.3g} s"


def markdown_cell(text: Any) -> str:
    """A markdown table cell: pipes escaped (metrics like |t - t_exact| contain them).

    Examples
    --------
    >>> markdown_cell("|t - t_exact| [s]")
    '\\\\|t - t_exact\\\\| [s]'
    """
    return str(text).replace("|", "\\|")


def _optional(x: float | None) -> str:
    return format_value(x, 3) if x is not None else "—"


def rows_markdown(rows: Sequence[Row]) -> str:
    """Markdown table of rows (one question's rows: the question is the section heading)."""
    head = "| method | setting | metric | p95 / value | worst | time per answer | reference | " \
           "reference time | speed-up | n | note |"
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        cells = [r.method, r.setting, r.metric, format_value(r.error, 3), format_value(r.worst, 3),
                 format_time(r.wall_s), r.reference, format_time(r.reference_wall_s), format_value(r.speedup, 3),
                 r.n, r.note]
        lines.append("| " + " | ".join(markdown_cell(c) for c in cells) + " |")
    return "\n".join(lines)


def curves_markdown(curves: Sequence[CostCurve]) -> str:
    """Markdown table of cost curves with their exponents."""
    lines = ["| curve | setting | x | wall time [s] | SVM fits | peak memory above baseline [MB] | "
             "time exponent | fits exponent | memory exponent | note |", "|" + "---|" * 10]
    for c in curves:
        lines.append(
            f"| {markdown_cell(c.name)} | {markdown_cell(c.setting)} | {', '.join(f'{x:g}' for x in c.x)} | "
            f"{', '.join(f'{w:.3g}' for w in c.wall_s)} | {', '.join(str(f) for f in c.fits)} | "
            f"{', '.join(f'{m:.1f}' for m in c.peak_mb)} (process at {c.base_mb:.0f}) | "
            f"{format_value(c.time_exponent, 3)} | {_optional(c.fits_exponent)} | {_optional(c.memory_exponent)} | "
            f"{c.note} |")
    return "\n".join(lines)


def _by_question(rows: Sequence[Row]) -> dict[str, list[Row]]:
    groups: dict[str, list[Row]] = {}
    for r in rows:
        groups.setdefault(r.question, []).append(r)
    return groups


# ============================================================ the page
def _md_head(report: BenchReport) -> list[str]:
    env = report.environment
    mode = "--quick" if report.quick else "(full run)"
    out = [
        "# Accuracy against run time",
        "",
        f"<!-- GENERATED by `designkit bench {'--quick ' if report.quick else ''}--out docs`: do not edit by hand; "
        "re-run the command to refresh. -->",
        "",
        f"Generated by `designkit bench {mode} --out docs` (seed {report.seed}) in {report.wall_s / 60:.1f} min on "
        f"{env.get('cpus')} CPUs (load average at start {env.get('load_average_at_start')}), designkit "
        f"{env.get('designkit')}, numpy {env.get('numpy')}, scipy {env.get('scipy')}, scikit-learn "
        f"{env.get('scikit-learn')}. Every error below is measured against a high-fidelity reference computed in "
        "the same run; every speed-up is a ratio of two times measured in that run. Timings on a shared machine "
        "vary by tens of percent; errors are reproducible with the same seed.",
        "",
    ]
    if report.skipped:
        out += ["Skipped in this run: " + "; ".join(report.skipped), ""]
    return out


def _md_ideal_errors(name: str, mc: Mapping[str, Any]) -> list[str]:
    """The error table of the ideal table's queries."""
    out = [
        f"Measured over {mc.get('n')} random pairs and scenes spread across the grid of `{name}` (effusivity "
        "uniform, sigma/dT log-uniform over the table's range, the partner placed so that the exact answer lies "
        "inside the grid), against the exact ideal-observer answer for the same classes (closed form, bisection, "
        "what `--exact` computes for the ideal bound):",
        "",
        "| query | error metric | median | 95th percentile | worst |",
        "|---|---|---|---|---|",
    ]
    for q in ("min-contact", "max-noise", "min-delta-t", "delta-e"):
        if q in mc:
            d = mc[q]
            out.append(f"| `{q}` | {markdown_cell(d['metric'])} | {format_value(d['median'], 3)} | "
                       f"{format_value(d['p95'], 3)} | {format_value(d['worst'], 3)} |")
    for q in ("min-contact", "delta-e"):
        if q in mc and "relative_p95" in mc[q]:
            d = mc[q]
            out.append(f"| `{q}` | relative error | — | {100 * d['relative_p95']:.1f} % | "
                       f"{100 * d['relative_worst']:.1f} % |")
    if "distinguishable" in mc:
        d = mc["distinguishable"]
        out.append(f"| `distinguishable` | wrong verdicts, pairs within -20..+25 % of the boundary | "
                   f"{100 * d['wrong_fraction']:.1f} % | — | wrong ones at most "
                   f"{100 * d['farthest_wrong_relative']:.0f} % from the boundary |")
    out += ["",
            f"A table query takes {format_time(mc.get('time_per_table_query_s', math.nan))} in-process with the "
            "table loaded (see `benchmarks/bench_query.py` for the fresh-shell time).", ""]
    return out


def _md_gap_table(mc: Mapping[str, Any]) -> list[str]:
    """Where the ideal table's error comes from: by the pair's distance, and its conservativeness."""
    out = ["**Where the error comes from.** A table's delta(e) is a whole number of effusivity intervals "
           "(80 wide for the shipped tables): the first interval that is distinguishable. For pairs only a "
           "few intervals apart this rounding dominates, and because delta falls slowly with contact at "
           "long contacts, a fraction of an interval becomes seconds of contact time. The error by the "
           "pair's distance:", "",
           "| distance [intervals] | pairs | with a table answer | `min-contact` median [s] | p95 [s] | "
           "worst [s] | `max-noise` median | p95 |",
           "|---|---|---|---|---|---|---|---|"]
    mn = {tuple(b["gap_intervals"]): b for b in mc.get("max-noise", {}).get("by_gap", [])}
    for b in mc["min-contact"]["by_gap"]:
        a_, z_ = b["gap_intervals"]
        m = mn.get((a_, z_), {})
        out.append(f"| {a_:g} – {'∞' if not math.isfinite(z_) else f'{z_:g}'} | {b['pairs']} | "
                   f"{b['answered']} | {format_value(b['median'], 3)} | {format_value(b['p95'], 3)} | "
                   f"{format_value(b['worst'], 3)} | {format_value(m.get('median', math.nan), 3)} | "
                   f"{format_value(m.get('p95', math.nan), 3)} |")
    cons = mc["min-contact"].get("conservative_fraction")
    unres = mc.get("unresolved_fraction")
    noise_cons = (f" and its `max-noise` at or below for {100 * mc['max-noise']['conservative_fraction']:.0f} %"
                  if "conservative_fraction" in mc.get("max-noise", {}) else "")
    redrawn = (f"{100 * unres:.0f} % of the random boundary pairs drawn were (they were drawn again; "
               "use `--exact` for such pairs). " if unres is not None and math.isfinite(unres) else "")
    out += ["",
            f"The table errs on the safe side: its `min-contact` was at or above the exact answer for "
            f"{100 * cons:.0f} % of the pairs" + noise_cons +
            ". Pairs closer than one interval cannot be resolved by a table at all: " + redrawn
            + "A second, smaller source is linear interpolation in contact time of a need that is convex in "
            "it, and a neighbouring grid point with no answer (beyond the grid), which makes the query fall "
            "back to the next grid point.", ""]
    return out


def _md_svm(name: str | None, s: Mapping[str, Any] | None) -> list[str]:
    """The SVM table against ``--exact``, or why it is not on the page."""
    if not name:
        return ["`svm-paper` (the paper's SVM) was not available when this page was generated; its interpolation "
                "error on its own grid is estimated by the density rows below (the ideal table cut to sparser "
                "axes), and its Monte Carlo error by the recognition rows. Regenerate this page once the table is "
                "built: `designkit bench --out docs`.", ""]
    mcs = s.get("min-contact-summary", {})
    dd = s.get("distinguishable", {})
    return [
        f"`{name}` (the paper's SVM) against `--exact` ({s['trials']} trials per class, {s['repeats']} seeds per "
        f"evaluation) over {mcs.get('n')} random pairs"
        + (f" ({mcs['drawn'] - mcs['n']} more drawn without both answers)" if mcs.get("drawn", 0) > mcs.get("n", 0)
           else "") + ": `min-contact` error 95th percentile "
        f"{format_value(mcs.get('p95'), 3)} s, worst {format_value(mcs.get('worst'), 3)} s; the exact answer lay "
        f"inside the table's Monte Carlo interval for {mcs.get('exact_in_table_interval')} of {mcs.get('n')} pairs. "
        f"`distinguishable`: {dd.get('wrong')} wrong verdicts of {dd.get('n')} near-boundary cases "
        f"({dd.get('wrong_uncertain')} of them within 2 standard errors of the threshold, i.e. undecidable at "
        f"that Monte Carlo effort). One `--exact min-contact` took {format_time(mcs.get('exact_wall_s_mean'))} "
        "here.",
        "",
        "The SVM table's error has two parts: interpolation (how far apart its grid points are; the "
        "density rows below measure it on the ideal table cut to the SVM table's axes) and Monte Carlo "
        "(100 trials per class; the recognition rows measure it).", ""]


_BUYING = [
    "## How to buy more accuracy with time",
    "",
    "- **`--exact`** computes the one pair and scene you ask about instead of interpolating: no grid error "
    "at all, at the price of seconds instead of milliseconds (rows `min-contact` and `distinguishable` "
    "below give both times).",
    "- **`--exact --repeats R`** averages R seeds per evaluation; the Monte Carlo error of an F1 falls as "
    "1/sqrt(R) at R times the cost (rows `SVM F1`: trials x seeds). **`--trials T`** trains on more "
    "touches: it removes the bias of a small training set (the reference is the large-sample SVM), with a "
    "cost per fit growing about as T^p (cost curve `SVM: trials per interval`).",
    "- **Denser tables** (`designkit sweep` with more `noise_ratio` / `contact_s` points) cut the "
    "interpolation error roughly with the square of the spacing; rows `table interpolation (density)` show "
    "it on the same sweep with points left out. The build time grows linearly with the number of points "
    "(cost curve `ideal: contact times per table`).",
    "- **`max_repeats`** in a sweep config re-scores pairs near the threshold with more seeds, narrowing "
    "delta's Monte Carlo interval; the cost grows only for the few pairs near the threshold.",
    "- **More intervals** (`--intervals`) narrow each effusivity class: rows `delta(e)` give the error of a "
    "125/250/500-interval grid against a fine one; the cost grows about linearly (cost curves).",
    "",
]

_RELATED = [
    "## Related benchmarks", "",
    "Scripts in `benchmarks/` measure the performance targets against baselines in the same run:",
    "`bench_query.py` (a table query from a fresh shell against `python -c pass` and `import numpy`, "
    "what it imports, in-process time, memory), `bench_exact.py` (`--exact` min-contact for one pair "
    "against the table), `bench_delta_e.py` (staircase search against the full F1 matrix as the grid "
    "grows), `bench_memory.py` (peak memory of sweeps and queries), `bench_slab.py` (thin-sample "
    "solvers, see thin_samples.md) and `bench_export.py` (exported tables).", ""]


def _md_measurements(report: BenchReport, figures: Mapping[str, str]) -> list[str]:
    """Every row, by question, and the cost curves."""
    out = ["## All measurements", ""]
    if "pareto" in figures:
        out += [f"![error against run time]({figures['pareto']})", ""]
    for q, rows in _by_question(report.rows).items():
        out += [f"### {q}", "", rows_markdown(rows), ""]
    if report.curves:
        out += ["## The sweep's cost curve", "",
                "One scene point; a table costs this times its number of scene points. Exponents are "
                "least-squares slopes of log cost against log size. Memory: each point's peak resident set (Linux's "
                "resettable high-water mark) above the resident set of a fresh process after its imports; each "
                "curve runs in its own process, points in increasing order.", ""]
        if "cost" in figures:
            out += [f"![cost curves]({figures['cost']})", ""]
        out += [curves_markdown(report.curves), ""]
    return out


def _queries_facts(facts: Mapping[str, Any]) -> tuple[str | None, str | None]:
    """Names of the ideal table and the SVM table whose query facts the report holds."""
    ideal = next((k.split(":", 1)[1] for k in facts if k.startswith("queries:") and
                  facts[k].get("table", "").startswith("ideal")), None)
    svm = next((k.split(":", 1)[1] for k in facts if k.startswith("queries:") and "repeats" in facts[k]), None)
    return ideal, svm


def render_markdown(report: BenchReport, figures: Mapping[str, str] | None = None) -> str:
    """``docs/accuracy.md``: what error to expect from each query, and how to buy more with time.

    Parameters
    ----------
    report : BenchReport
        What a run measured.
    figures : mapping, optional
        File names of the figures beside the page (``pareto``, ``cost``).

    Returns
    -------
    str
        The page, markdown.
    """
    figures = figures or {}
    f = report.facts
    ideal, svm = _queries_facts(f)
    out = _md_head(report) + ["## What error to expect from the shipped tables", ""]
    if ideal:
        mc = f[f"queries:{ideal}"]
        out += _md_ideal_errors(ideal, mc)
        if "min-contact" in mc and "by_gap" in mc["min-contact"]:
            out += _md_gap_table(mc)
    out += _md_svm(svm, f.get(f"queries:{svm}"))
    out += _BUYING + _md_measurements(report, figures) + _RELATED
    out += ["## Section wall times", "",
            ", ".join(f"{k} {v:.0f} s" for k, v in report.section_wall_s.items()) +
            f"; total {report.wall_s:.0f} s.", ""]
    return short_paragraphs("\n".join(out))


#: The longest paragraph (or list item) of the page [characters]; tests/test_docs_site.py holds docs/ to it.
MAX_PARAGRAPH = 800
_SENTENCE_END = re.compile(r"(?<=[\w%)][.;])\s+(?=[A-Za-z(])")
_NOT_AN_END = re.compile(r"(?:\b(?:e\.g|i\.e|vs|cf|eq|Fig|et al)|\d)\.$")


def short_paragraphs(markdown: str, limit: int = MAX_PARAGRAPH) -> str:
    """``markdown`` with every prose line longer than ``limit`` characters cut at sentence ends into
    paragraphs (a list item's continue under it, indented). Idempotent; code fences and tables are kept.

    >>> text = "- " + "A sentence here. " * 60
    >>> max(len(p) for p in short_paragraphs(text).split(chr(10) * 2)) <= 800
    True
    """
    out, fence = [], False
    for line in markdown.split("\n"):
        if line.lstrip().startswith("```"):
            fence = not fence
        if fence or len(line) <= limit or line.lstrip().startswith(("|", "#", "<!--")):
            out.append(line)
            continue
        item = re.match(r"(\s*)((?:[-*]|\d+\.)\s+)?", line)
        indent = item.group(1) + " " * len(item.group(2) or "")
        rest = line
        while len(rest) > limit:
            cuts = [m.start() for m in _SENTENCE_END.finditer(rest)
                    if m.start() <= limit and not _NOT_AN_END.search(rest[:m.start()])]
            if not cuts:
                break
            out += [rest[:cuts[-1]].rstrip(), ""]
            rest = indent + rest[cuts[-1]:].strip()
        out.append(rest)
    return "\n".join(out)


# ============================================================ figures
def require_figures() -> None:
    """Refuse, in one line naming the extra, when matplotlib (the ``figures`` extra) is not installed.

    Raises
    ------
    InputError
        ``figures need matplotlib: pip install 'designkit[figures]'``.
    """
    import importlib.util

    if importlib.util.find_spec("matplotlib") is None:
        raise InputError(f"figures need matplotlib: {FIGURES_HINT}")


def _log_axes(ax) -> None:
    from matplotlib.ticker import NullFormatter

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())


def _save(fig, path, plt) -> Path:
    """Save by the suffix of ``path`` (png at 200 dpi, or vector svg / pdf) and close."""
    from designkit.figures import save_figure

    return save_figure(fig, path)


def _declutter(ax, labels) -> None:
    """Move point labels apart so that none overlaps another, and keep each inside its axes.

    Call it on a figure already laid out and frozen (no layout engine), so that extents stay put.

    A label that would run past the right edge is put on the left of its point; one that overlaps a
    label already placed moves up or down by its own height (alternately, further each time) and is
    tied to its point by a thin leader line.
    """
    from matplotlib.text import Text

    def extent(ann):  # the text alone (not its leader line), where it is now
        ann.update_positions(renderer)
        return Text.get_window_extent(ann, renderer)

    fig = ax.figure
    renderer = fig.canvas.get_renderer()
    box = ax.get_window_extent(renderer)
    to_pt = 72.0 / fig.dpi
    placed = []
    for ann in sorted(labels, key=lambda a: (a.xy[0], a.xy[1])):
        dx, dy = ann.xyann
        bb = extent(ann)
        if bb.x1 > box.x1:
            ann.set_horizontalalignment("right")
            dx = -abs(dx)
            ann.xyann = (dx, dy)
            bb = extent(ann)
        if bb.x0 < box.x0:  # too long for either side: start it at the left edge
            ann.set_horizontalalignment("left")
            dx = abs(dx)
            ann.xyann = (dx, dy)
            bb = extent(ann)
        if bb.y1 > box.y1:
            dy -= (bb.y1 - box.y1) * to_pt + 1.0
            ann.xyann = (dx, dy)
            bb = extent(ann)
        step = (bb.height + 1.0) * to_pt
        base = dy
        for k in range(1, 25):
            if not any(bb.overlaps(p) for p in placed) and box.y0 <= bb.y0 and bb.y1 <= box.y1 + 0.5:
                break
            shift = ((k + 1) // 2) * step * (1 if k % 2 else -1)
            ann.xyann = (dx, base + shift)
            bb = extent(ann)
        if ann.xyann[1] != base and ann.arrow_patch is not None:
            ann.arrow_patch.set_visible(True)
        placed.append(bb)


def _label(ax, text: str, xy, **kw):
    """A point label with a leader line that shows only once :func:`_declutter` moves the label."""
    ann = ax.annotate(text, xy, xytext=kw.pop("xytext", (3, 2)), textcoords="offset points", fontsize=5.5,
                      arrowprops={"arrowstyle": "-", "lw": 0.4, "color": "0.55", "shrinkA": 0, "shrinkB": 2}, **kw)
    ann.arrow_patch.set_visible(False)
    ann.set_in_layout(False)  # placed inside its axes by _declutter; the layout ignores it
    return ann


def plot_pareto(report: BenchReport, path) -> Path | None:
    """Error against time per answer, one panel per question (log-log), saved as PNG (None without rows)."""
    from designkit.figures import pyplot

    fig = pareto_figure(report)
    return None if fig is None else _save(fig, path, pyplot())


def _pareto_panel(ax, question: str, rows: Sequence[Row]) -> list:
    """One question's methods (error against time) and its references (★ at the panel's floor);
    returns the point labels (for :func:`_declutter`)."""
    floor = min([r.error for r in rows if r.error > 0] + [1.0]) / 10
    labels = []
    for m_i, m in enumerate(sorted({r.method for r in rows})):
        sel = [r for r in rows if r.method == m]
        xs = [r.wall_s for r in sel]
        ys = [r.error if r.error > 0 else floor for r in sel]
        ax.scatter(xs, ys, s=22, color=f"C{m_i}", label=m, zorder=3,
                   marker="o" if all(r.error > 0 for r in sel) else "v")
        for r, x, y in zip(sel, xs, ys):
            labels.append(_label(ax, r.setting, (x, y)))
    refs: dict[str, float] = {}
    for r in rows:
        if math.isfinite(r.reference_wall_s):
            refs.setdefault(r.reference, r.reference_wall_s)
    for ref_i, (name, t) in enumerate(refs.items()):
        ax.scatter([t], [floor], marker="*", s=70, color="k", zorder=4, label="reference" if ref_i == 0 else None)
        labels.append(_label(ax, name, (t, floor), xytext=(3, 4), color="0.3"))
    _log_axes(ax)
    xs_all = [r.wall_s for r in rows] + list(refs.values())
    lo_x, hi_x = min(xs_all), max(xs_all)
    ax.set_xlim(lo_x / 2.5, hi_x * 2.5)  # room for the labels of the outermost points
    ax.set_title(question, fontsize=9)
    ax.set_xlabel("time per answer [s]", fontsize=7)
    ax.set_ylabel(rows[0].metric[:48], fontsize=7)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3, which="both")
    # the legend below the panel, where it hides no point and no label
    ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False, ncol=1)
    return labels


def pareto_figure(report: BenchReport) -> Any:
    """The matplotlib figure of :func:`plot_pareto` (None without rows)."""
    from designkit.figures import pyplot

    plt = pyplot()
    groups = _by_question(report.rows)
    if not groups:
        return None
    ncol = 3
    nrow = math.ceil(len(groups) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.4 * ncol, 4.8 * nrow), constrained_layout=True, squeeze=False)
    panels = []
    for ax, (question, rows) in zip(axes.ravel(), groups.items()):
        panels.append((ax, _pareto_panel(ax, question, rows)))
    for ax in axes.ravel()[len(groups):]:
        ax.set_visible(False)
    fig.suptitle("designkit: error against run time per answer (★ reference, drawn at the panel's floor; "
                 "▼ error 0)", fontsize=10)
    fig.canvas.draw()  # lay the figure out once, then freeze it: labels are placed in that layout
    fig.set_layout_engine("none")
    for ax, labels in panels:
        _declutter(ax, labels)
    return fig


def plot_costs(report: BenchReport, path) -> Path | None:
    """The sweep's cost curves (time and memory against size), log-log, saved as PNG (None without curves)."""
    from designkit.figures import pyplot

    if not report.curves:
        return None
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for i, c in enumerate(report.curves):
        x = np.asarray(c.x) / c.x[0]
        a1.plot(x, c.wall_s, "o-", color=f"C{i}", ms=3, label=f"{c.name} (p = {c.time_exponent:.2f})")
        mem = np.asarray(c.peak_mb)
        ok = np.isfinite(mem) & (mem > 0.5)  # below about 1 MB the high-water mark is noise
        if np.any(ok):
            exp = "" if c.memory_exponent is None else f" (p = {c.memory_exponent:.2f})"
            a2.plot(x[ok], mem[ok], "o-", color=f"C{i}", ms=3, label=c.name + exp)
    from designkit.figures import log_ticks

    sizes = [v for c in report.curves for v in np.asarray(c.x) / c.x[0]]
    walls = [v for c in report.curves for v in c.wall_s]
    mems = [v for c in report.curves for v in c.peak_mb if np.isfinite(v) and v > 0.5]
    for ax, lab, ys in ((a1, "wall time [s]", walls), (a2, "peak memory above baseline [MB]", mems)):
        _log_axes(ax)
        log_ticks(ax.xaxis, sizes)  # the values measured: a range inside one decade showed a single tick
        log_ticks(ax.yaxis, ys)
        ax.set_xlabel("size relative to the curve's first point")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    fig.suptitle("Sweep engine cost curves (one scene point)", fontsize=10)
    return _save(fig, path, plt)


# ============================================================ files
def print_report(report: BenchReport, written: Mapping[str, Path], con: Any) -> None:
    """``designkit bench``'s text: one table per question (error against run time), the sweep's cost curves,
    what was skipped, the sections' wall times and the files written, on the rich console ``con``."""
    from rich.table import Table

    con.print(f"[bold]designkit bench{' --quick' if report.quick else ''}: error against run time[/] "
              f"(seed {report.seed}; time per answer; speed-up = reference time / method time)")
    groups: dict = {}
    for r in report.rows:
        groups.setdefault(r.question, []).append(r)
    for question, rows in groups.items():
        refs: dict = {}
        for r in rows:
            refs.setdefault(r.reference, r.reference_wall_s)
        ref_text = "; ".join(f"{name} ({format_time(t)})" for name, t in refs.items())
        t = Table(title=f"{question} — reference: {ref_text}", title_justify="left", title_style="bold")
        for col, kw in (("method", {}), ("setting", {"max_width": 44}), ("metric", {"max_width": 30}),
                        ("p95/value", {"justify": "right"}), ("worst", {"justify": "right"}),
                        ("time/answer", {"justify": "right"}), ("speed-up", {"justify": "right"}),
                        ("n", {"justify": "right"})):
            t.add_column(col, **kw)
        for r in rows:
            t.add_row(r.method, r.setting, r.metric, format_value(r.error, 3), format_value(r.worst, 3),
                      format_time(r.wall_s), format_value(r.speedup, 3), str(r.n))
        con.print(t)
    if report.curves:
        c = Table(title="Sweep cost curves (one scene point; exponent p of cost ~ size^p)", title_justify="left",
                  title_style="bold")
        for col in ("curve", "x", "wall time [s]", "SVM fits", "peak MB above start", "p time", "p fits", "p memory"):
            c.add_column(col)
        for cur in report.curves:
            c.add_row(cur.name, ", ".join(f"{x:g}" for x in cur.x), ", ".join(f"{w:.3g}" for w in cur.wall_s),
                      ", ".join(str(f) for f in cur.fits), ", ".join(f"{m:.1f}" for m in cur.peak_mb),
                      format_value(cur.time_exponent, 3),
                      "—" if cur.fits_exponent is None else format_value(cur.fits_exponent, 3),
                      "—" if cur.memory_exponent is None else format_value(cur.memory_exponent, 3))
        con.print(c)
    for s in report.skipped:
        con.print(f"[yellow]skipped:[/] {s}")
    con.print(f"total {report.wall_s:.0f} s (" + ", ".join(f"{k} {v:.0f} s" for k, v in report.section_wall_s.items())
              + ")")
    for v in written.values():
        con.print(f"[bold green]wrote[/] {v}")


def write_report(report: BenchReport, out_dir) -> dict[str, Path]:
    """Write ``accuracy.md``, its figures and ``accuracy.json`` into ``out_dir``; returns the paths.

    Raises
    ------
    InputError
        Before writing anything, when matplotlib (the ``figures`` extra) is
        not installed (:func:`require_figures`).
    """
    import json

    from designkit._io import atomic_write_text

    require_figures()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    figs = {}
    for key, plot in (("pareto", plot_pareto), ("cost", plot_costs)):
        p = plot(report, out_dir / f"accuracy_{key}.png")
        if p is not None:
            figs[key] = p.name
    page = render_markdown(report, figs)
    cov_json = out_dir / COVERAGE_FILES[0]
    if cov_json.exists():  # the coverage benchmark's section survives a regeneration of the page
        cov_png = out_dir / COVERAGE_FILES[1]
        page = insert_coverage(page, coverage_markdown(json.loads(cov_json.read_text()),
                                                       cov_png.name if cov_png.exists() else None))
    varied_json = out_dir / VARIED_COVERAGE_FILE
    if varied_json.exists():  # and so does the varied-conditions one
        var_png = out_dir / VARIED_COVERAGE_FIGURE
        page = insert_varied_coverage(page, varied_coverage_markdown(json.loads(varied_json.read_text()),
                                                                     var_png.name if var_png.exists() else None))
    md = atomic_write_text(out_dir / "accuracy.md", page)
    js = atomic_write_text(out_dir / "accuracy.json",
                           json.dumps(jsonable(report.to_dict()), indent=1, allow_nan=False) + "\n")
    return {"markdown": md, "json": js, **{k: out_dir / v for k, v in figs.items()}}


# ============================================================ the coverage benchmark's section
def coverage_markdown(doc: Mapping[str, Any], figure: str | None = None) -> list[str]:
    """The coverage section of ``accuracy.md`` from a coverage record (``benchmarks/bench_coverage.py``).

    Examples
    --------
    >>> doc = {"meta": {"pairs": 2, "repeats": 4, "ref_repeats": 16, "wall_s": 60.0, "load_start": 1.0,
    ...        "cpus": 2, "exact_solver": "batched"}, "diluted_nominal": 0.859,
    ...        "synthetic": {"n": 10, "coverage": 0.9, "median_rel": 0.01, "p95_rel": 0.03},
    ...        "rows": [{"question": "min-contact", "route": "exact", "n": 2, "n_compared": 2, "n_stated": 2,
    ...                  "coverage": 1.0, "n_unstated": 0, "n_no_answer": 0, "median_abs": 0.01, "p95_abs": 0.02,
    ...                  "median_rel": 0.01, "p95_rel": 0.02, "violations": 0, "worst": []}]}
    >>> lines = coverage_markdown(doc)
    >>> lines[0], any("| `min-contact` | exact | 2 |" in x for x in lines)
    ('## Do the stated intervals cover the truth? (coverage benchmark)', True)
    """
    m = doc["meta"]
    out = ["## Do the stated intervals cover the truth? (coverage benchmark)", "",
           f"Generated by `benchmarks/bench_coverage.py` (up to {m['pairs']} random cases per question, the "
           "counts below, "
           f"{m.get('wall_s', 0) / 60:.0f} min on {m.get('cpus')} CPUs, load average {m.get('load_start', 0):.1f} "
           f"at start). Each answer (table `{m.get('table') or 'svm-paper'}`, and `--exact` with the default 4 "
           "seeds x 100 touches, solver "
           f"{m.get('exact_solver', 'sklearn')}) is compared with a reference: the same exact estimate with "
           f"{m['ref_repeats']} seeds ({m['ref_repeats'] // m['repeats']}x the answer's, disjoint), batched solver. "
           "Pairs: effusivities uniform in 100-39,000, three in four at least 5 table intervals (400) apart; "
           "noise 0.01 / 0.05 / 0.1 degC at dT 10 degC; contact log-uniform 0.5-10 s.", "",
           f"Known truth first: on synthetic F1 curves (logistic in log x, the SVM's binomial noise) the exact "
           f"estimator's 90 % intervals covered {_pct(doc['synthetic']['coverage'])} of {doc['synthetic']['n']} "
           f"crossings (median relative error {doc['synthetic']['median_rel']:.3g}, p95 "
           f"{doc['synthetic']['p95_rel']:.3g}). Against a reference with its own Monte Carlo error an exactly "
           f"calibrated 90 % interval covers about {_pct(doc['diluted_nominal'])} (the target band is 85-97 %).", "",
           *(["Variants of the same check: " + "; ".join(
               f"{v['label']}: {_pct(v['coverage'])} covered, stated widths {1 / v['z_sd']:.2f}x the real spread"
               for v in doc["synthetic"]["variants"]) + ".", ""] if doc["synthetic"].get("variants") else []),
           "| question | route | cases | compared | stated | coverage of 90 % | no stated coverage | no answer "
           "| median abs err | p95 abs err | median rel err | p95 rel err | ideal-bound violations |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in doc["rows"]:
        out.append(f"| `{r['question']}` | {r['route']} | {r['n']} | {r['n_compared']} | {r['n_stated']} | "
                   f"{_pct(r['coverage'])} | {r['n_unstated']} | {r['n_no_answer']} | "
                   f"{format_value(r['median_abs'], 3)} | "
                   f"{format_value(r['p95_abs'], 3)} | {_pct(r['median_rel'])} | {_pct(r['p95_rel'])} | "
                   f"{r['violations']}{_at_bound(r)} |")
    out += ["", "Units of the absolute errors: s (min-contact), degC (max-noise, min-delta-t), "
            "J s^-1/2 K^-1 m^-2 (delta-e), F1 (distinguishable; its relative error is of the F1).", ""]
    zs = [r for r in doc["rows"] if r.get("n_z")]
    if zs:
        out += ["Calibration free of the reference's own error: the spread of (answer - reference) / "
                "sqrt(sd_answer^2 + sd_reference^2), the sd each stated interval implies (log scale for the "
                "crossings), is 1 for calibrated intervals, above 1 for too narrow ones (robust spread, "
                "1.4826 x median |z|; cases): "
                + "; ".join(f"`{r['question']}` {r['route']} {r['z_robust_sd']:.2f} (n {r['n_z']})" for r in zs)
                + ".", ""]
    far = next((r for r in doc["rows"] if "far" in r), None)
    if far is not None:
        f, n = far["far"], far["near"]
        out += [f"Table `min-contact`, pairs at least 5 intervals apart: p95 relative error {_pct(f['p95_rel'])} "
                f"(median {_pct(f['median_rel'])}, {f['n_compared']} pairs; target 5 %); closer pairs: p95 "
                f"{_pct(n['p95_rel'])} ({n['n_compared']} pairs).", ""]
    halves = [r for r in doc["rows"] if r.get("halves") and r["route"] == "table" and r.get("n_stated")]
    if halves:
        out += ["Table rows by half of the cases (0-49 / 50-99; an earlier table route was designed after looking "
                "at cases 0-49 and covered 87 % / 59 % of min-contact's): " + "; ".join(
                    f"`{r['question']}` {_pct(r['halves'][0]['coverage'])} / {_pct(r['halves'][1]['coverage'])} "
                    f"covered, median error {_pct(r['halves'][0]['median_rel'])} / {_pct(r['halves'][1]['median_rel'])}"
                    for r in halves) + ".", ""]
    brackets = [r for r in doc["rows"] if r.get("n_reference_bracket")]
    if brackets:
        out += ["References that are only a search bracket (too few informative evaluations for a fit; their "
                "value is the bracket's middle, not a measurement) are left out of coverage and error: " + "; ".join(
                    f"`{r['question']}` {r['route']}: {r['n_reference_bracket']}, the answer inside the bracket "
                    f"for {r['reference_bracket_contains']}" for r in brackets) + ".", ""]
    for r in doc["rows"]:
        if r.get("n_edge_bound"):
            out += [f"`{r['question']}` {r['route']}: {r['n_edge_bound']} answers at the edge of the table's axis "
                    f"(\"at least\" / \"at most\" the axis' end) are one-sided bounds, not counted as errors; "
                    f"{r['edge_bound_holds']} of them hold for the reference.", ""]
    for r in doc["rows"]:
        if r.get("verdicts"):
            v = r["verdicts"]
            out += [f"`distinguishable` {r['route']} verdicts agreeing with the reference's (mean F1 >= 0.9): "
                    f"{v['agree']} of {v['n']}.", ""]
    out += ["Worst regions (median relative error by noise and the pair's lower effusivity):", ""]
    for r in doc["rows"]:
        if r.get("worst"):
            w = "; ".join(f"noise {d['noise_c']:g} degC, e {d['e_band'][0]}-{d['e_band'][1]}: "
                          f"{100 * d['median_rel']:.1f} % (n {d['n']})" for d in r["worst"])
            out.append(f"- `{r['question']}` {r['route']}: {w}")
    if m.get("notes"):
        out += ["", *[f"- {n}" for n in m["notes"]]]
    if figure:
        out += ["", f"![answer error against the reference by effusivity and noise]({figure})"]
    return out + [""]


def _at_bound(r: Mapping[str, Any]) -> str:
    n = r.get("reference_at_bound")
    return f" ({n} references reach Phi at the bound itself)" if n else ""


def _insert_section(page: str, start: str, end: str, section: Sequence[str], after: str | None = None) -> str:
    """``page`` with the section between markers ``start`` and ``end`` replaced, or else inserted right after
    marker ``after`` where the page has it, or before the first ``## ``."""
    block = "\n".join([start, *section, end])
    if start in page and end in page:
        a, rest = page.split(start, 1)
        return a + block + rest.split(end, 1)[1]
    if after is not None and after in page:
        a, rest = page.split(after, 1)
        return a + after + "\n" + block + rest
    head, sep, tail = page.partition("\n## ")
    return head + "\n" + block + "\n" + sep.lstrip("\n") + tail if sep else page + "\n" + block + "\n"


def insert_coverage(page: str, section: Sequence[str]) -> str:
    """``page`` with its coverage section replaced (between markers), or inserted before the first ``## ``."""
    return short_paragraphs(_insert_section(page, _COV_START, _COV_END, section))


def write_coverage(doc: Mapping[str, Any], figure, out_dir) -> Path:
    """Write the coverage record and figure beside ``accuracy.md`` and put its section in the page."""
    import json
    import shutil

    from designkit._io import atomic_write_text

    out_dir = Path(out_dir)
    js, png = (out_dir / n for n in COVERAGE_FILES)
    atomic_write_text(js, json.dumps(doc, indent=1) + "\n")
    if figure is not None and Path(figure).resolve() != png.resolve():
        shutil.copyfile(figure, png)
    page = out_dir / "accuracy.md"
    text = page.read_text() if page.exists() else "# Accuracy against run time\n"
    return atomic_write_text(page, insert_coverage(text, coverage_markdown(doc, png.name if png.exists() else None)))


# ============================================================ the varied-conditions coverage section
def varied_coverage_markdown(doc: Mapping[str, Any], figure: str | None = None) -> list[str]:
    """The section of ``accuracy.md`` on varied initial conditions, from its record
    (``benchmarks/bench_coverage_varied.py --docs``): one row per run and route, and each run's worst
    regions for the table.

    Examples
    --------
    >>> s = {"n": 100, "n_compared": 59, "n_stated": 51, "coverage": 0.882, "n_unstated": 8,
    ...      "unstated_contains": 0.25, "n_no_answer": 39, "median_rel": 0.04, "p95_rel": 0.547, "violations": 0}
    >>> run = {"question": "min-contact", "seed": 1, "wall_s": 533.0, "cpus": 2, "spread_c": 2.5, "delta_t_c": 7.5,
    ...        "routes": {"table": s, "exact": s}, "sharp": {"n": 46, "median_rel": 0.032, "p95_rel": 0.084},
    ...        "regions": []}
    >>> lines = varied_coverage_markdown({"runs": [run]})
    >>> row = [ln for ln in lines if ln.startswith("| `min-contact`")][0].split(" | ")
    >>> lines[0], row[2], row[6], row[11]
    ('## Varied initial conditions (coverage benchmark)', 'table', '88 %', '8 % (46)')
    """
    runs = sorted(doc["runs"], key=lambda r: (r["question"], r["seed"]))
    spreads = sorted({(r["spread_c"], r["delta_t_c"]) for r in runs})
    out = ["## Varied initial conditions (coverage benchmark)", "",
           "Generated by `benchmarks/bench_coverage_varied.py --docs docs` (100 random cases a run, on "
           f"{runs[0]['cpus'] if runs else 2} CPUs). The sensor temperature is drawn per touch within "
           + ", ".join(f"+-{a:g} degC at dT {b:g} degC" for a, b in spreads)
           + " (the paper's robot setting: Ts0 uniform in 30-35 degC, object at 25 degC); noise log-uniform over "
           "the varied table's axis, 0.01-0.1 degC. Each case is asked from the shipped table `svm-paper-varied` "
           "and by `--exact` (4 seeds), against a reference of 16 other seeds. A run's seed draws its cases; "
           "the table's min-contact rule was designed on seed 1's cases, so seed 2's are held out. "
           "\"Sharp\" references are those whose own 90 % interval spans less than a factor 1.5 (an F1 that is "
           "not monotone in contact time under varied conditions gives references spanning 1-10 s).", "",
           "| question | seed | route | cases | compared | stated | coverage of 90 % | no stated coverage "
           "(holding the reference) | no answer | median rel err | p95 rel err | p95 rel err, sharp references "
           "| ideal-bound violations | wall |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        for route, s in r["routes"].items():
            sharp = r.get("sharp") if route == "table" else None
            out.append(
                f"| `{r['question']}` | {r['seed']} | {route} | {s['n']} | {s['n_compared']} | {s['n_stated']} | "
                f"{_pct(s['coverage'])} | {s['n_unstated']} ({_pct(s['unstated_contains'])}) | {s['n_no_answer']} | "
                f"{_pct(s['median_rel'])} | {_pct(s['p95_rel'])} | "
                + (f"{_pct(sharp['p95_rel'])} ({sharp['n']})" if sharp else "—")
                + f" | {s['violations']} | {format_time(r['wall_s']) if route == 'table' else ''} |")
    out += ["", "Worst regions of the table's answers (median relative error by noise band and the pair's lower "
            "effusivity [J s^-1/2 K^-1 m^-2]; coverage of the stated intervals there):", ""]
    for r in runs:
        worst = [g for g in r.get("regions", []) if g["n"] >= 3][:3]
        if not worst:
            continue
        parts = [f"noise {g['noise_band'][0]:.2g}-{g['noise_band'][1]:.2g} degC, e {g['e_band'][0]:g}-{g['e_band'][1]:g}: "
                 f"{_pct(g['median_rel'])} ({g['n']} cases, coverage {_pct(g['coverage'])})" for g in worst]
        out.append(f"- `{r['question']}` seed {r['seed']}: " + "; ".join(parts) + ".")
    if figure:
        out += ["", "Each case's answer over its reference, with its stated interval (blue: the interval holds the "
                "reference, red: it misses, grey: no coverage stated; open markers: references wider than a "
                "factor 1.5; circles seed 1, triangles held out):", "",
                f"![varied conditions: answers against the reference, with their intervals]({figure})"]
    return out


def varied_coverage_cases(results: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The per-case readings a run's figure needs (``benchmarks/bench_coverage_varied.py`` results), compact:
    the case's noise, and for each route and the reference its value, interval and stated coverage."""
    keep = ("value", "low", "high", "coverage", "method")
    return [{"noise_c": r.get("noise_c"), **{k: {f: r[k].get(f) for f in keep}
                                             for k in ("table", "exact", "reference")}} for r in results]


def varied_coverage_figure(doc: Mapping[str, Any], path) -> Path | None:
    """Each case's answer over its reference, with the stated interval, per question and route
    (``accuracy_coverage_varied.png``); None where no run of the record kept its cases.

    Blue: a stated 90 % interval that holds the reference; red: one that misses it; grey: an answer whose
    interval states no coverage (grid cells and grid-rule readings). Open markers: references whose own
    90 % interval spans more than a factor 1.5 (F1 not monotone in contact time). Circles: seed 1 (the
    cases the varied min-contact rule was designed on); triangles: later seeds (held out).
    """
    runs = [r for r in doc.get("runs", []) if r.get("cases")]
    if not runs:
        return None
    from designkit.figures import pyplot

    plt = pyplot()
    questions = sorted({r["question"] for r in runs}, key=lambda q: (q != "min-contact", q))
    fig, axes = plt.subplots(len(questions), 2, figsize=(10, 3.6 * len(questions)), squeeze=False,
                             constrained_layout=True)
    units = {"min-contact": "reference contact time [s]", "delta-e": "reference delta(e) [J s^-1/2 K^-1 m^-2]"}
    for i, q in enumerate(questions):
        for j, route in enumerate(("table", "exact")):
            ax = axes[i][j]
            n = {"held": 0, "missed": 0, "unstated": 0}
            for run in (r for r in runs if r["question"] == q):
                marker = "o" if run["seed"] == 1 else "^"
                for c in run["cases"]:
                    ref, ans = c["reference"], c[route]
                    if not (ref.get("value") and ref.get("coverage") and ans.get("value")):
                        continue
                    x, y = ref["value"], ans["value"] / ref["value"]
                    sharp = bool(ref.get("low") and ref.get("high") and ref["high"] < 1.5 * ref["low"])
                    lo, hi = ans.get("low"), ans.get("high")
                    if ans.get("coverage"):
                        held = (lo is None or lo <= x) and (hi is None or x <= hi)
                        color = "tab:blue" if held else "tab:red"
                        n["held" if held else "missed"] += 1
                    else:
                        color = "0.55"
                        n["unstated"] += 1
                    if lo is not None or hi is not None:
                        ylo = (lo if lo is not None else ans["value"]) / x
                        yhi = (hi if hi is not None else ans["value"]) / x
                        ax.plot([x, x], [max(ylo, 1 / 3), min(yhi, 3.0)], color=color, lw=0.8, alpha=0.5)
                    ax.plot([x], [min(max(y, 1 / 3), 3.0)], marker, ms=4.5, color=color,
                            mfc=color if sharp else "none", alpha=0.9)
            ax.axhline(1.0, color="k", lw=0.7)
            _log_axes(ax)
            ax.set_ylim(1 / 3, 3.0)
            ticks = [0.4, 0.5, 0.67, 0.8, 1.0, 1.25, 1.5, 2.0, 2.5]
            ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
            if q == "min-contact":
                xt = [0.5, 1.0, 2.0, 5.0]
                ax.set_xticks(xt, [f"{t:g}" for t in xt])
            ax.set_xlabel(units.get(q, "reference"))
            ax.set_ylabel("answer / reference")
            ax.grid(alpha=0.3, which="both")
            stated = n["held"] + n["missed"]
            ax.set_title(f"{q}, {'table' if route == 'table' else '--exact'}: stated 90 % intervals held "
                         f"{n['held']} of {stated}" + (f"\n{n['unstated']} answer{'s' if n['unstated'] != 1 else ''} without a stated coverage (grey)"
                                                       if n["unstated"] else ""), fontsize=9)
    spreads = sorted({(r["spread_c"], r["delta_t_c"]) for r in runs})
    fig.suptitle("Varied initial conditions (" + ", ".join(f"+-{a:g} degC at dT {b:g} degC" for a, b in spreads)
                 + "): each answer over its 16-seed reference, bars its stated interval (clipped at 1/3 and 3)\n"
                 "blue held, red missed, grey no coverage stated; circles seed 1, triangles held-out seeds; "
                 "open markers: references wider than a factor 1.5", fontsize=9)
    return _save(fig, path, plt)


def insert_varied_coverage(page: str, section: Sequence[str]) -> str:
    """``page`` with its varied-conditions section replaced (between markers), or inserted after the coverage
    section (before the first ``## `` where there is none)."""
    return short_paragraphs(_insert_section(page, _VAR_START, _VAR_END, section, after=_COV_END))


def write_varied_coverage(run: Mapping[str, Any], out_dir) -> Path:
    """Put one run (``benchmarks/bench_coverage_varied.py``) into the record beside ``accuracy.md``, replacing
    an earlier run of the same question and seed, and its section into the page."""
    import json

    from designkit._io import atomic_write_text

    out_dir = Path(out_dir)
    js = out_dir / VARIED_COVERAGE_FILE
    doc = json.loads(js.read_text()) if js.exists() else {"runs": []}
    doc["runs"] = [r for r in doc["runs"] if (r["question"], r["seed"]) != (run["question"], run["seed"])]
    doc["runs"].append(dict(run))
    atomic_write_text(js, json.dumps(jsonable(doc), indent=1, allow_nan=False) + "\n")
    png = varied_coverage_figure(doc, out_dir / VARIED_COVERAGE_FIGURE)
    page = out_dir / "accuracy.md"
    text = page.read_text() if page.exists() else "# Accuracy against run time\n"
    section = varied_coverage_markdown(doc, png.name if png is not None else None)
    return atomic_write_text(page, insert_varied_coverage(text, section))
