"""C99 export of a live sequential test: a fixed-memory, allocation-free per-sample update function.

:func:`write_sequential_c` fills the template
``designkit/export/templates/designkit_sequential.h.in`` from a
:class:`~designkit.recognition.sequential.SequentialTest`: the response shape
``g_k`` tabulated at the sensor's sampling rate up to the longest contact,
the candidates' prior pieces, the thresholds and the scene, as ``static
const`` data; ``PREFIX_init`` and ``PREFIX_update`` do what
:meth:`SequentialTest.update` does, sample for sample (the state is two running
sums and a sample index). Numbers enter as shortest round-trip doubles
(:func:`~designkit.export._common.c_double`), names as escaped C string literals
(:func:`~designkit.export._common.c_string`) and comments
(:func:`~designkit.export._common.c_comment`); the prefix is validated
(:func:`~designkit.export._common.check_prefix`). The table export (format ``c``)
is separate and unchanged.
"""

from __future__ import annotations

import math

import numpy as np

from .._validation import InputError
from ..recognition import sequential as seq
from ._common import c_comment, c_double, c_string, check_prefix, fill_template, read_template

__all__ = ["TEMPLATE", "write_sequential_c"]

#: The header template, a file in the package.
TEMPLATE = "designkit_sequential.h.in"


def _doubles(vals, per_line: int = 6) -> str:
    words = [c_double(v) for v in vals]
    return ",\n".join("    " + ", ".join(words[i:i + per_line]) for i in range(0, len(words), per_line))


def write_sequential_c(test: "seq.SequentialTest", prefix: str = "designkit_seq") -> bytes:
    """The C99 header text of ``test``; every function, macro and constant starts with ``prefix``.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> t = seq.SequentialTest([("wood", (331, 506.46)), ("metal", (12767, 25972))], SENSORS["paper"],
    ...                        noise_c=0.05, sensor_temp_c=35, ambient_temp_c=25, max_contact_s=2)
    >>> text = write_sequential_c(t, "robot").decode()
    >>> "int  robot_update(robot_state *st, double t_s, double temp_c)" in text, "#define ROBOT_N_CANDIDATES 2" in text
    (True, True)
    """
    if not isinstance(test, seq.SequentialTest):
        raise InputError(f"a C sequential export needs a SequentialTest, got {type(test).__name__}")
    prefix = check_prefix(prefix)
    P = prefix.upper()
    plan = test.plan
    cands = plan.candidates
    k = len(cands)
    first, count, w0, w1, lm = [], [], [], [], []
    for c in cands:
        first.append(len(lm))
        count.append(len(c.log_mass))
        w0.extend(c.w_edges[:-1])
        w1.extend(c.w_edges[1:])
        lm.extend(c.log_mass)
    g = np.asarray(test.shape_table, dtype=np.float64)
    lines = [" *   " + c_comment(f"{i}: {c.name}, e [{c.e_range[0]:g}, {c.e_range[1]:g}), error rate {c.error_rate:g}, "
                                  f"{len(c.log_mass)} piece(s)") for i, c in enumerate(cands)]
    s = test.sensor
    nbytes = 8 * (g.size + 4 * len(lm) + k * k + 2) + 8 * k
    thr = [[float(x) for x in row] for row in plan.thresholds]
    text = fill_template(read_template(TEMPLATE), {
        "P": P, "p": prefix,
        "VERSION": c_comment(_version()), "S_VERSION": c_string(_version()),
        "SENSOR": c_comment(s.name),
        "SENSOR_LINE": c_comment(f"e_s {s.effusivity!r} J s^-1/2 K^-1 m^-2, tau {s.tau_s!r} s, "
                                 f"{s.sample_rate_hz!r} Hz"),
        "MODEL": c_comment(test.model.describe()),
        "TS0_TEXT": c_comment(repr(test.sensor_temp_c)), "TA_TEXT": c_comment(repr(test.ambient_temp_c)),
        "SIGMA_TEXT": c_comment(repr(test.noise_c)), "TMAX_TEXT": c_comment(repr(test.max_contact_s)),
        "FS_TEXT": c_comment(repr(s.sample_rate_hz)),
        "CANDIDATE_LINES": "\n".join(lines), "PLAN": c_comment(plan.reason),
        "K": str(k), "NP": str(len(lm)), "MAXP": str(max(count)), "N_G": str(g.size),
        "SEPARABLE": "1" if plan.separable else "0", "BYTES": str(nbytes),
        "FS": c_double(s.sample_rate_hz), "TS0": c_double(test.sensor_temp_c), "TA": c_double(test.ambient_temp_c),
        "SIGMA": c_double(test.noise_c), "LOG_SQRT_2PI": c_double(seq.LOG_SQRT_2PI), "FAR": c_double(seq.FAR_PIECES),
        "CENTRAL": c_double(seq.CENTRAL),
        "NAMES": ", ".join(c_string(c.name) for c in cands),
        "THRESHOLDS": ", ".join("{" + ", ".join(c_double(x) for x in row) + "}" for row in thr),
        "FIRST": ", ".join(map(str, first)), "COUNT": ", ".join(map(str, count)),
        "W0": ", ".join(c_double(x) for x in w0), "W1": ", ".join(c_double(x) for x in w1),
        "LM": ", ".join(c_double(x) for x in lm),
        "LW": ", ".join(c_double(math.log(b - a) if b > a else 0.0) for a, b in zip(w0, w1)),
        # the Python object's expression, so that the constants are its values to the bit
        "DENS": ", ".join(c_double(math.exp(m - math.log(b - a)) if b > a else 0.0) for a, b, m in zip(w0, w1, lm)),
        "G": _doubles(g),
    })
    if not all(math.isfinite(x) for row in thr for x in row):
        raise InputError("the test's thresholds are not finite: nothing to export")
    return text.encode("ascii")


def _version() -> str:
    from .. import __version__

    return str(__version__)
