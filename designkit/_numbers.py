"""The one rounding rule for numbers people read: text answers, table cells and figure labels.

Three significant digits, never an exponent for the magnitudes designkit prints (contact times,
noise, temperature differences, effusivities), trailing zeros dropped. JSON and CSV keep full
precision; only what is read by eye goes through :func:`sig`.
"""

from __future__ import annotations

import math

#: Significant digits of every number printed for people (CLI text, table cells, figure labels).
DIGITS = 3


def sig(x: float | None, unit: str = "", digits: int = DIGITS) -> str:
    """``x`` rounded to ``digits`` significant digits, as text (``"—"`` for None or not finite).

    Parameters
    ----------
    x : float or None
        The value.
    unit : str
        Appended after a space when given (``"s"``, ``"°C"``).
    digits : int
        Significant digits (default :data:`DIGITS`).

    Examples
    --------
    >>> sig(1.3251, "s"), sig(35000), sig(3088), sig(0.000123), sig(None)
    ('1.33 s', '35000', '3090', '0.000123', '—')
    """
    if x is None or not math.isfinite(float(x)):
        return "—"
    import numpy as np

    text = np.format_float_positional(float(x), precision=digits, unique=False, fractional=False, trim="-")
    return f"{text} {unit}" if unit else text
