"""The sweep engine's former single module, kept so that imports written before the split work.

Import from :mod:`designkit.sweep` instead (the engine now lives in
``config``, ``scorer``, ``search``, ``chunk`` and ``run``); this module only
re-exports the public names.
"""

from __future__ import annotations

from .chunk import ChunkResult, run_chunk, run_scene
from .config import FIDELITIES, SweepConfig
from .run import SweepInterrupted, iter_sweep, prepare_workdir, run_sweep
from .scorer import FEATURE_CACHE_MB
from .search import IDEAL_UNKNOWN, assemble, closed_form_model, delta_from_staircase, ideal_staircase, staircase_search

__all__ = [
    "FEATURE_CACHE_MB",
    "FIDELITIES",
    "IDEAL_UNKNOWN",
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
]
