"""Sweep engine: delta(e), the smallest distinguishable effusivity difference, over a grid.

The paper's protocol (section IV): cut ``(e_min, e_max]`` into equal intervals
("material categories"), simulate ``trials`` touches per interval with ``e``
uniform inside it, score every pair of intervals by the SVM's cross-validated
F1, and call a pair distinguishable when ``F1 >= Phi``. ``delta(e)`` for a
reference interval is the smallest distance (in effusivity, between interval
centres) to a distinguishable interval, towards higher (``delta_up``) or lower
(``delta_down``) effusivity. Touches come from any forward model of
:mod:`designkit.models` (``SweepConfig.model``; the paper's semi-infinite one
by default), and the table header records which.

It computes only what the answer needs: one sigma/dT axis, a staircase search per reference interval
from the ideal observer's floor, trials drawn once per contact, and Monte Carlo intervals from pairs
re-scored near ``Phi``. Each shortcut, and why it is exact or tested: docs/engine.md, "How a sweep
computes only what the answer needs".

Modules
-------
``config``  :class:`SweepConfig`, what determines a sweep (and its identity)
``scorer``  SVM F1 of interval pairs, with repeats near the threshold
``search``  the staircase searches, the ideal floor, delta assembly
``chunk``   one (scene point, block, contact) unit of work
``run``     a whole sweep: parallel chunks, working folder, resume, the table
"""

from __future__ import annotations

from .chunk import ChunkResult, run_chunk, run_scene
from .config import FIDELITIES, SOLVERS, SweepConfig
from .scorer import ENGINE_VERSION
from .run import SweepInterrupted, iter_sweep, prepare_workdir, run_sweep
from .search import (assemble, closed_form_model, delta_from_staircase, ideal_staircase, staircase_search,
                     staircase_searches)

__all__ = [
    "ENGINE_VERSION",
    "FIDELITIES",
    "SOLVERS",
    "ChunkResult",
    "SweepConfig",
    "SweepInterrupted",
    "assemble",
    "closed_form_model",
    "delta_from_staircase",
    "ideal_staircase",
    "iter_sweep",
    "prepare_workdir",
    "run_chunk",
    "run_scene",
    "run_sweep",
    "staircase_search",
    "staircase_searches",
]
