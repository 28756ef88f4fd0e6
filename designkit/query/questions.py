"""The design questions: one registry, one entry per question, two routes each.

=================  ==================================================  ==========
question           value                                               unit
=================  ==================================================  ==========
``min-contact``    shortest contact time that separates two objects    s
``max-noise``      largest noise sigma at which a contact still does   degC
``min-delta-t``    smallest sensor-object temperature difference       degC
``delta-e``        smallest distinguishable effusivity difference      J s^-1/2 K^-1 m^-2
``distinguishable`` whether a scene separates two objects              (bool)
=================  ==================================================  ==========

Each is answered by the **table** route (:mod:`designkit.query.table`,
milliseconds, for the model, sensor and threshold a table was built with) or
the **exact** route (:mod:`designkit.query.exact`, seconds, any forward model),
and both answer with the same :class:`~designkit.query.answer.Answer`. Adding
a question is one entry in :data:`QUESTIONS` plus its two route functions.

Examples
--------
>>> sorted(QUESTIONS)
['delta-e', 'distinguishable', 'max-noise', 'min-contact', 'min-delta-t']
>>> ask("min-contact", e1=35000, e2=20000, table="ideal-paper").route
'table'
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from .._validation import InputError
from . import exact as _exact_route
from . import table as _table_route
from .answer import QUANTITIES, Answer

__all__ = ["QUESTIONS", "ROUTES", "Question", "ask", "delta_e", "distinguishable", "max_noise", "min_contact",
           "min_delta_t"]

ROUTES = ("table", "exact")


@dataclass(frozen=True)
class Question:
    """One design question: its name, what it answers, and its two routes.

    Attributes
    ----------
    name : str
        CLI command and ``Answer.question``.
    summary : str
        One line for people.
    scene : tuple of str
        The scene quantities the question takes (the others are what it asks for).
    table, exact : callable
        The route functions (same objects and scene arguments; route options differ).
    """

    name: str
    summary: str
    scene: tuple[str, ...]
    table: Callable[..., Answer]
    exact: Callable[..., Answer]

    @property
    def quantity(self) -> str:
        return QUANTITIES[self.name][0]

    @property
    def unit(self) -> str:
        return QUANTITIES[self.name][1]

    def route(self, name: str) -> Callable[..., Answer]:
        """The function answering this question by route ``name``."""
        if name not in ROUTES:
            raise InputError(f"unknown route {name!r}; known: {', '.join(ROUTES)}")
        return self.table if name == "table" else self.exact


#: The registry: question name -> :class:`Question`.
QUESTIONS: dict[str, Question] = {q.name: q for q in (
    Question("min-contact", "shortest contact time that separates two objects", ("noise_c", "delta_t_c"),
             _table_route.min_contact, _exact_route.exact_min_contact),
    Question("max-noise", "largest noise sigma at which a contact time still separates two objects",
             ("contact_s", "delta_t_c"), _table_route.max_noise, _exact_route.exact_max_noise),
    Question("min-delta-t", "smallest sensor-object temperature difference that separates two objects",
             ("contact_s", "noise_c"), _table_route.min_delta_t, _exact_route.exact_min_delta_t),
    Question("delta-e", "smallest distinguishable effusivity difference from a reference, both directions",
             ("contact_s", "noise_c", "delta_t_c"), _table_route.delta_e, _exact_route.exact_delta_e),
    Question("distinguishable", "whether a scene separates two objects, with the SVM's and ideal F1",
             ("contact_s", "noise_c", "delta_t_c"), _table_route.distinguishable,
             _exact_route.exact_distinguishable),
)}


def ask(question: str, *, route: str = "table", **arguments: Any) -> Answer:
    """Answer ``question`` by ``route`` (``"table"`` or ``"exact"``).

    ``arguments`` are the route function's (objects, scene, and the route's
    options: ``table=`` ... for the table route, ``trials=`` ... for the exact one).
    """
    if question not in QUESTIONS:
        raise InputError(f"unknown question {question!r}; known: {', '.join(QUESTIONS)}")
    return QUESTIONS[question].route(route)(**arguments)


def _route(exact: bool, route: str | None) -> str:
    if route is not None and exact and route != "exact":
        raise InputError(f"exact=True contradicts route={route!r}")
    return route or ("exact" if exact else "table")


def min_contact(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any) -> Answer:
    """Shortest contact time [s] that separates two objects (table route unless ``exact``).

    See :func:`designkit.query.table.min_contact` and
    :func:`designkit.query.exact.exact_min_contact` for the arguments.
    """
    return ask("min-contact", route=_route(exact, route), e1=e1, e2=e2, **kw)


def max_noise(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any) -> Answer:
    """Largest noise sigma [degC] at which ``contact_s`` still separates two objects."""
    return ask("max-noise", route=_route(exact, route), e1=e1, e2=e2, **kw)


def min_delta_t(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any) -> Answer:
    """Smallest sensor-object temperature difference [degC] that separates two objects."""
    return ask("min-delta-t", route=_route(exact, route), e1=e1, e2=e2, **kw)


def delta_e(e=None, *, exact: bool = False, route: str | None = None, **kw: Any) -> Answer:
    """delta(e) [J s^-1/2 K^-1 m^-2] towards lower and higher effusivity."""
    return ask("delta-e", route=_route(exact, route), e=e, **kw)


def distinguishable(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any) -> Answer:
    """Whether a scene separates two objects, with the SVM's and the ideal observer's F1."""
    return ask("distinguishable", route=_route(exact, route), e1=e1, e2=e2, **kw)
