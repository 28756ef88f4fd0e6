"""designkit's lab: what measures and reports designkit, outside the installed core.

:mod:`designkit_lab.accuracy` (``designkit bench``: every answering route against a reference),
:mod:`designkit_lab.reproduce` (``designkit reproduce``: the paper's figures and tables),
:mod:`designkit_lab.emulator` (``designkit emulate``: a simulated rig on a pseudo-terminal, for trying
``designkit calibrate`` and ``classify`` without hardware, and the tests' serial peer),
:mod:`designkit_lab.explicit_euler` (why the slab model's finite volumes step implicitly),
:mod:`designkit_lab.roundtrip` (synthetic calibration round trips, ``benchmarks/bench_roundtrip.py``) and
:mod:`designkit_lab.sequential_bound` (the optimal sequential test: the bound on the core's live decisions).
The lab imports the core (:mod:`designkit`); the core never imports the lab. The three commands above are
the lab's (:mod:`designkit_lab.cli`), added to ``designkit`` through the ``designkit.commands`` entry points.
Installed by the same distribution; its figures need ``pip install 'designkit[lab]'`` (matplotlib, networkx).
"""

__all__ = ["accuracy", "cli", "emulator", "explicit_euler", "reproduce", "roundtrip", "sequential_bound"]
