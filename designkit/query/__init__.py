"""Design questions, answered from lookup tables or computed exactly, under any forward model.

=====================  ===========================================================
module                 what it holds
=====================  ===========================================================
``questions``          the registry of questions (:data:`QUESTIONS`) and :func:`ask`
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

from .answer import ANSWER_KEYS, Answer, IdealBound
from .exact import exact_delta_e, exact_distinguishable, exact_max_noise, exact_min_contact, exact_min_delta_t
from .inputs import MATERIALS_RULE, NeedsInput, PairQuestion, TableMismatch, pair_question, reference_class
from .vectorized import ArrayAnswer
from .questions import QUESTIONS, Question, ask, delta_e, distinguishable, max_noise, min_contact, min_delta_t

__all__ = [
    "ANSWER_KEYS",
    "MATERIALS_RULE",
    "QUESTIONS",
    "Answer",
    "ArrayAnswer",
    "IdealBound",
    "NeedsInput",
    "PairQuestion",
    "Question",
    "TableMismatch",
    "ask",
    "delta_e",
    "distinguishable",
    "exact_delta_e",
    "exact_distinguishable",
    "exact_max_noise",
    "exact_min_contact",
    "exact_min_delta_t",
    "max_noise",
    "min_contact",
    "min_delta_t",
    "pair_question",
    "reference_class",
]
