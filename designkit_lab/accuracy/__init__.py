"""The accuracy report: every way designkit answers a question, against a reference, in one run.

Each section is one module and returns :class:`Row` objects (the cost
section :class:`CostCurve` objects); :func:`run_bench` runs a selection of
them into a :class:`BenchReport`, and :func:`write_report` /
:func:`render_markdown` turn that into ``docs/accuracy.md``
(``designkit bench --out docs``).

==============  ==========================================================
module          what it holds
==============  ==========================================================
``physics``     eq. 2 against mpmath; thin-sample solvers against a tight
                image series
``recognition`` SVM F1 against a long run; ideal closed form against its
                Monte Carlo
``delta``       staircase search against the full F1 matrix; coarse
                effusivity grids against a fine one
``queries``     table answers (the question layer users call) against
                exact answers
``cost``        the sweep engine's wall time, fits and memory as work grows
``coverage``    do stated intervals cover a 4x-more-seeds reference? (the
                coverage benchmark, benchmarks/bench_coverage.py)
``instruments`` timing, peak memory, a child process's cost, power-law fits
``results``     :class:`Row`, :class:`CostCurve` and the shared summaries
``render``      the page, its figures and the JSON record
``run``         :func:`run_bench` and :class:`BenchReport`
==============  ==========================================================
"""

from __future__ import annotations

from .cost import cost_curve, cost_curve_specs, cost_curves
from .coverage import (COVERAGE_QUESTIONS, answer_reading, calibration_z, case_arguments, coverage_case,
                       diluted_coverage, draw_case, run_cases, summarize, synthetic_coverage, table_reading,
                       worst_regions)
from .delta import delta_rows, grid_rows, staircase_vs_full
from .instruments import ProcessCost, fit_exponent, measure, process_cost, reset_peak_memory, resident_mb, timed
from .physics import physics_rows, slab_rows
from .queries import GAP_BINS, QUESTIONS, density_rows, query_rows, subsample_table, svm_query_rows
from .recognition import RECOGNITION_PAIRS, ideal_mc_rows, recognition_rows
from .render import (COVERAGE_FILES, FIGURES_HINT, VARIED_COVERAGE_FIGURE, VARIED_COVERAGE_FILE, coverage_markdown,
                     curves_markdown,
                     format_time, format_value, insert_coverage, insert_varied_coverage, markdown_cell, pareto_figure,
                     plot_costs, plot_pareto, print_report, render_markdown, require_figures, rows_markdown,
                     varied_coverage_cases, varied_coverage_figure, varied_coverage_markdown, write_coverage,
                     write_report, write_varied_coverage)
from .results import PAPER_RATIO, CostCurve, Row, p95, paper_sensor, worst
from .run import SECTIONS, BenchReport, check_sections, environment, run_bench

__all__ = [
    "COVERAGE_FILES", "COVERAGE_QUESTIONS", "FIGURES_HINT", "GAP_BINS", "PAPER_RATIO", "QUESTIONS",
    "RECOGNITION_PAIRS", "SECTIONS", "VARIED_COVERAGE_FIGURE", "VARIED_COVERAGE_FILE",
    "insert_varied_coverage", "varied_coverage_cases", "varied_coverage_figure", "varied_coverage_markdown",
    "write_varied_coverage",
    "BenchReport", "CostCurve", "ProcessCost", "Row",
    "answer_reading", "calibration_z", "case_arguments", "check_sections", "coverage_case", "coverage_markdown", "diluted_coverage",
    "draw_case", "insert_coverage", "run_cases", "summarize", "synthetic_coverage", "table_reading", "worst_regions", "write_coverage",
    "cost_curve", "cost_curve_specs", "cost_curves", "curves_markdown", "delta_rows",
    "density_rows", "environment", "fit_exponent", "format_time", "format_value", "grid_rows", "ideal_mc_rows",
    "markdown_cell", "measure", "p95", "paper_sensor", "pareto_figure", "physics_rows", "plot_costs",
    "plot_pareto", "print_report", "process_cost", "query_rows", "recognition_rows", "render_markdown", "require_figures",
    "reset_peak_memory", "resident_mb", "rows_markdown", "run_bench", "slab_rows", "staircase_vs_full",
    "subsample_table", "svm_query_rows", "timed", "worst", "write_report",
]
