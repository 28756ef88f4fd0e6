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

Computing only what the answer needs
------------------------------------
The naive route scores all ``n (n - 1) / 2`` pairs (124,750 for 500 intervals).
This engine scores a few per reference, and each shortcut is exact or tested:

* **sigma/dT invariance.** With fixed initial conditions and standardized
  features the F1 depends on noise and temperature difference only through
  ``sigma / dT`` (docs/physics.md, "Invariance"; tests/test_recognition.py) for every forward
  model here (all are linear in the temperatures), so one axis replaces two
  and every sweep is run at ``dT = 1``.
* **Staircase search** (:mod:`~designkit.sweep.search`). Distinguishability is
  monotone in the pair's distance, so ``J(i)``, the first distinguishable
  partner above ``i``, alone determines both directions of ``delta``. Each
  ``J(i)`` is found by galloping up from the row's own floor and bisecting; a
  row's probes depend on nothing but its own decisions, so a table is a
  function of its config alone (the same arrays whatever ``blocks``, jobs,
  backend or the other contact times swept), and the rows of a chunk advance
  in lockstep, every step's probes scored as one batch.
* **Ideal-observer certificate.** A pair whose ideal-observer F1 is below
  ``Phi`` cannot be distinguishable by any classifier, so the search starts at
  the ideal staircase (closed form, milliseconds) and never fits an SVM below
  it. The closed form exists for shared-shape models (and models that cannot
  be told from one at the scene's noise); for others the search runs without
  the floor (correct, slower) and the table has no ideal arrays.
* **No warm starts.** A row starts from its own floor, never from the previous
  row's or contact time's answer, which would change answers on noisy (not
  exactly monotone) F1.
* **Trials generated once.** Noise is drawn time-major
  (:mod:`designkit.simulation`), so the trials of a shorter contact are exact
  prefixes of a longer one: drawing the shorter trials directly *is* truncating
  the long ones, bit for bit.

Monte Carlo error
-----------------
Pairs within ``z`` standard errors of ``Phi`` are re-scored with fresh seeds
(:mod:`~designkit.sweep.scorer`); three staircases are walked on the same
cached scores (:mod:`~designkit.sweep.chunk`): ``mean >= Phi`` gives delta,
``mean + z se >= Phi`` its lower end and ``mean - z se >= Phi`` its upper end.

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
