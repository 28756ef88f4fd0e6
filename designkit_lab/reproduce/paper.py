"""The reference paper's published numbers, as the report compares against them.

Bai et al., "Analyzing Material Recognition Performance of Thermal Tactile
Sensing using a Large Materials Database and a Real Robot" (the LaTeX source
in ``shared/reference``; docs/physics.md section 3 collects the same numbers).
Table I's noise row printed "0.5" is a typo for 0.05 (the text and figures
use sigma = 0.05).
"""

from __future__ import annotations

import types
from dataclasses import dataclass

from designkit.query import guideline as _guideline

__all__ = [
    "GUIDELINE",
    "PAPER_EXTREMES",
    "REAL_ROBOT",
    "TABLE1",
    "Table1Row",
    "TABLE1_F1_TOLERANCE",
    "TABLE1_PERCENT_TOLERANCE",
]

#: Differences from the paper larger than these are explained in the report (issue 5).
TABLE1_PERCENT_TOLERANCE = 3.0
TABLE1_F1_TOLERANCE = 0.03


@dataclass(frozen=True)
class Table1Row:
    """One (sigma, dT) setting of the paper's Table I (contact 2 s, Ta 25 degC).

    Attributes
    ----------
    noise_c, delta_t_c : float
        Noise sigma [degC] and Ts0 - Ta [degC] (5: Ts0 30 degC, 10: Ts0 35 degC).
    intervals_percent, intervals_f1 : float
        % indistinguishable effusivity-interval pairs (of 124,750) and their mean F1.
    materials_percent, materials_f1 : float
        % indistinguishable material pairs (of 2346) and their mean F1.
    """

    noise_c: float
    delta_t_c: float
    intervals_percent: float
    intervals_f1: float
    materials_percent: float
    materials_f1: float

    @property
    def noise_ratio(self) -> float:
        """sigma / dT: recognition depends on the two only through it (fixed conditions)."""
        return self.noise_c / self.delta_t_c


#: Table I, in the paper's row order (noise 0.1, 0.05, 0.01; dT 5 then 10).
TABLE1: tuple[Table1Row, ...] = (
    Table1Row(0.1, 5.0, 20.25, 0.815, 47.76, 0.931),
    Table1Row(0.1, 10.0, 16.54, 0.882, 31.56, 0.943),
    Table1Row(0.05, 5.0, 16.41, 0.885, 30.87, 0.945),
    Table1Row(0.05, 10.0, 14.96, 0.934, 18.28, 0.952),
    Table1Row(0.01, 5.0, 13.51, 0.900, 20.19, 0.958),
    Table1Row(0.01, 10.0, 13.04, 0.945, 11.28, 0.960),
)

#: The design guideline (section VIII-B) lives with the questions (:mod:`designkit.query.guideline`): the
#: main job prints it beside its answer, and importing this package would cost a fresh shell ~10-30 ms.
GUIDELINE = _guideline.GUIDELINE


#: Real robot (Table II, contact 4 s, 12 materials, 66 pairs) and sim-to-real (section VII).
REAL_ROBOT = types.MappingProxyType({
    "real_fixed_f1": 0.994,
    "real_varied_f1": 0.966,
    "sim_to_real_f1": 0.815,
    "sim_to_real_indistinguishable_percent": 48.48,
    "sim_to_real_noise_c": 0.075,
    "sim_to_real_noise_grid_c": (0.01, 0.025, 0.05, 0.075, 0.1),
    "contact_s": 4.0,
    "materials": 12,
    "pairs": 66,
})

#: Effusivity extremes of the CES EduPack Level-1 database (section IV-A).
PAPER_EXTREMES = types.MappingProxyType({
    "min_name": "Rigid polymer foam (LD)", "min": 30.5,
    "max_name": "Copper alloys", "max": 36800.0,
    "materials": 69, "pairs": 2346,
})
