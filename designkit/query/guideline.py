"""The paper's design guideline (section VIII-B), and its figure beside an answer asked in its scene.

Bai et al. conclude that separating e = 35,000 from 20,000 J s^-1/2 K^-1 m^-2 with
sigma 0.05 degC and the sensor 10 degC above the object takes contact "for at least
2 s" on their grid of 1, 2, 3, 4 s (F1 >= 0.9). The main job (``designkit min-contact
--e1 35000 --e2 20000``) is that question; :func:`guideline_remark` words the paper's
answer beside designkit's. :mod:`designkit_lab.reproduce.paper` re-exports :data:`GUIDELINE`
with the paper's other numbers.
"""

from __future__ import annotations

import math
import types
from typing import Any, Mapping

__all__ = ["GUIDELINE", "guideline_remark"]

#: The design guideline (section VIII-B): 35k vs 20k, sigma 0.05, dT 10, contact grid 1-4 s, F1 >= 0.9.
GUIDELINE = types.MappingProxyType({
    "e1": 35000.0, "e2": 20000.0, "noise_c": 0.05, "delta_t_c": 10.0,
    "contact_grid_s": (1.0, 2.0, 3.0, 4.0), "min_contact_s": 2.0, "threshold": 0.9,
})


def guideline_remark(answer: Mapping[str, Any]) -> str | None:
    """The paper's own figure beside a ``min-contact`` answer (its dict) asked in the guideline's scene.

    The scene is the paper's (:data:`GUIDELINE`: the two effusivities as numbers, sigma, dT and
    Phi, its sensor, the semi-infinite model, fixed initial conditions); otherwise None.
    The answer's contact is placed on the paper's 1-s grid (the first grid time at or above it).

    >>> d = {"question": "min-contact", "value": 1.5, "threshold": 0.9, "sensor": {"name": "paper"},
    ...      "model": {"name": "semi-infinite"}, "scene": {"noise_c": 0.05, "delta_t_c": 10.0},
    ...      "objects": [{"material": None, "e_range": [35000.0, 35080.0]},
    ...                  {"material": None, "e_range": [20000.0, 20080.0]}], "computation": {}}
    >>> print(guideline_remark(d))
    the paper (section VIII-B): at least 2 s on its 1-s grid (1, 2, 3, 4 s); 1.5 s rounds up to 2 s there
    >>> guideline_remark({**d, "scene": {"noise_c": 0.1, "delta_t_c": 10.0}}) is None
    True
    """
    g = GUIDELINE
    try:
        same = (answer["question"] == "min-contact" and answer["sensor"]["name"] == "paper"
                and answer["model"]["name"] == "semi-infinite"
                and not (answer.get("computation") or {}).get("sensor_temp_spread_c")
                and all(o.get("material") is None for o in answer["objects"])
                and sorted(o["e_range"][0] for o in answer["objects"]) == sorted((g["e1"], g["e2"]))
                and math.isclose(answer["scene"]["noise_c"], g["noise_c"])
                and math.isclose(answer["scene"]["delta_t_c"], g["delta_t_c"])
                and math.isclose(answer["threshold"], g["threshold"]))
    except (KeyError, TypeError, IndexError):
        return None
    if not same:
        return None
    grid = g["contact_grid_s"]
    words = (f"the paper (section VIII-B): at least {g['min_contact_s']:g} s on its 1-s grid "
             f"({', '.join(f'{c:g}' for c in grid)} s)")
    value = answer.get("value")
    if value is None:
        return words
    on_grid = next((c for c in grid if c >= value - 1e-9), None)
    where = f"rounds up to {on_grid:g} s there" if on_grid is not None else f"lies beyond that grid's {grid[-1]:g} s"
    return f"{words}; {value:.3g} s {where}"
