"""Design questions, answered from lookup tables or computed exactly, under any forward model.

=====================  ===========================================================
module                 what it holds
=====================  ===========================================================
``questions``          the registry of questions (:data:`QUESTIONS`), :func:`ask`, :func:`ask_each`
``answer``             the typed :class:`Answer`; its ``to_dict()`` is the ``--json`` schema
``inputs``             objects, the materials rule, scene inputs (shared by both routes)
``table``              the table route (milliseconds, no scikit-learn)
``exact``              the exact route (simulation + SVM, any forward model)
``ideal_bound``        the ideal observer's closed-form answers, vectorized, cached per process
``vectorized``         every question over numpy arrays (:class:`ArrayAnswer`)
=====================  ===========================================================

Examples
--------
>>> from designkit.query import min_contact
>>> a = min_contact(35000, 20000, table="ideal-paper")
>>> a.question, a.unit
('min-contact', 's')
"""

import importlib

#: Where each public name lives. PEP 562: a name is imported on first use, so ``import designkit.query`` loads
#: nothing and a table question does not load the exact route (simulation, SVM; ``python -X importtime``).
_LAZY = {
    **dict.fromkeys(("ANSWER_KEYS", "Answer", "IdealBound"), ".answer"),
    **dict.fromkeys(("exact_delta_e", "exact_distinguishable", "exact_max_noise", "exact_min_contact",
                     "exact_min_delta_t"), ".exact"),
    **dict.fromkeys(("MATERIALS_RULE", "NeedsInput", "PairQuestion", "TableMismatch", "pair_question",
                     "reference_class"), ".inputs"),
    "ArrayAnswer": ".vectorized",
    **dict.fromkeys(("QUESTIONS", "Question", "ask", "ask_each", "delta_e", "distinguishable", "max_noise", "min_contact",
                     "min_delta_t"), ".questions"),
}


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name], __name__), name)
        globals()[name] = value  # once: later lookups are plain attribute reads
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = sorted(_LAZY)
