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

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence, overload

from numpy.typing import ArrayLike

from .._validation import InputError
from ..rig import for_rig, rig_arguments
from . import table as table_route
from .answer import Answer, QuestionQuantity
from .policy import MC_BOUND, choose_route, sensor_table_answer
from .vectorized import ArrayAnswer, answer_arrays, is_array_call

__all__ = ["QUESTIONS", "Question", "ask", "ask_each", "delta_e", "distinguishable", "max_noise", "min_contact",
           "min_delta_t"]



@dataclass(frozen=True)
class Question(QuestionQuantity):
    """One design question: its name, what it answers, and its two routes.

    Attributes
    ----------
    name : str
        CLI command and ``Answer.question``.
    summary : str
        One line for people.
    scene : tuple of str
        The scene quantities the question takes (the others are what it asks for).
    table : callable
        The table route's function.
    exact_name : str
        The name of the exact route's function in :mod:`designkit.query.exact` (same objects and scene
        arguments; route options differ); :attr:`exact` is the function, imported on first use so that a
        table question does not load the exact route.
    """

    name: str
    summary: str
    scene: tuple[str, ...]
    table: Callable[..., Answer]
    exact_name: str

    @property
    def exact(self) -> Callable[..., Answer]:
        """The exact route's function."""
        from . import exact

        return getattr(exact, self.exact_name)

    @property
    def question(self) -> str:
        """Its name (what :class:`~designkit.query.answer.QuestionQuantity` reads ``quantity`` and ``unit`` by)."""
        return self.name

    def route(self, name: str) -> Callable[..., Answer]:
        """The function answering this question by route ``name`` (``"table"`` or ``"exact"``)."""
        if name not in ("table", "exact"):
            raise InputError(f"unknown route {name!r}; known: table, exact")
        return self.table if name == "table" else self.exact


#: The registry: question name -> :class:`Question`.
QUESTIONS: dict[str, Question] = {q.name: q for q in (
    Question("min-contact", "shortest contact time that separates two objects", ("noise_c", "delta_t_c"),
             table_route.min_contact, "exact_min_contact"),
    Question("max-noise", "largest noise sigma at which a contact time still separates two objects",
             ("contact_s", "delta_t_c"), table_route.max_noise, "exact_max_noise"),
    Question("min-delta-t", "smallest sensor-object temperature difference that separates two objects",
             ("contact_s", "noise_c"), table_route.min_delta_t, "exact_min_delta_t"),
    Question("delta-e", "smallest distinguishable effusivity difference from a reference, both directions",
             ("contact_s", "noise_c", "delta_t_c"), table_route.delta_e, "exact_delta_e"),
    Question("distinguishable", "whether a scene separates two objects, with the SVM's and ideal F1",
             ("contact_s", "noise_c", "delta_t_c"), table_route.distinguishable,
             "exact_distinguishable"),
)}


def ask(question: str, *, route: str = "auto", ideal_bound: bool = True,
        **arguments: Any) -> "Answer | ArrayAnswer":
    """Answer ``question`` by ``route``: ``"auto"`` (default), ``"table"`` or ``"exact"``.

    ``arguments`` are the route function's (objects, scene, and the route's
    options: ``table=`` ... for the table route, ``trials=`` ... for the exact one).
    ``"auto"`` reads a table where one is built for the sensor, model and scene
    asked (or one is named), and computes the answer otherwise; the options of the
    route not taken are left out (:func:`designkit.query.policy.choose_route`). The
    answer's ``route_reason`` says why its route answered.
    Numeric inputs given as arrays (or lists), and material names given as lists,
    broadcast like numpy and give an
    :class:`~designkit.query.vectorized.ArrayAnswer` (:mod:`designkit.query.vectorized`);
    ``ideal_bound=False`` there skips the closed-form ideal bound (the slow part of a first call).
    Scene values not given (or None) are the sensor's: a sensor file's recorded rig conditions, with contact
    counted from the rig's detected onset, else the paper's defaults; the answer's ``scene["conditions"]``
    (an array answer's ``conditions``) says each value and where it came from (:func:`designkit.rig.rig_arguments`).
    """
    if question in QUESTIONS and not is_array_call(question, arguments):
        if not ideal_bound:
            raise InputError("ideal_bound=False is for array inputs (a single answer always carries its bound)")
        objects = {k: arguments.pop(k) for k in _OBJECTS[question] if k in arguments}
        return ask_each(question, [objects], route=route, **arguments)[0]
    asked, route, arguments, why, rig = _resolve(question, route, arguments)
    fn, own = QUESTIONS[question].route(route), _own(question, route, why)
    ans = answer_arrays(question, functools.partial(fn, ideal_bound=False) if own else fn, route, arguments,
                        ideal_bound=ideal_bound and not own)
    return _finished(question, ans, route, why, arguments, rig, asked)


#: The arguments naming a question's objects (one element of :func:`ask_each`'s ``objects``).
_OBJECTS = {q: (("e", "m") if q == "delta-e" else table_route.PAIR_KEYS) for q in QUESTIONS}


def ask_each(question: str, objects: Sequence[Mapping[str, Any]], *, route: str = "auto",
             **arguments: Any) -> list[Answer]:
    """What :func:`ask` answers for each element of ``objects`` (each a mapping of the question's object
    arguments: ``e1``, ``e2``, ``m1``, ``m2``, ``objects``; delta-e's ``e``, ``m``) with the same scene and options
    ``arguments`` (numbers, not arrays): one list of :class:`~designkit.query.answer.Answer`, in order. The table
    route answers every pair from one array call (:data:`designkit.query.table.EACH`: a 12-material matrix's 66
    pairs cost about what a few single questions do); a single :func:`ask` is element 0 of it.
    """
    asked, route, arguments, why, rig = _resolve(question, route, arguments)
    fn = QUESTIONS[question].route(route)
    extra = {"ideal_bound": False} if _own(question, route, why) else {}
    if route == "table" and question in table_route.EACH:
        answers = table_route.EACH[question](objects, **arguments, **extra)
    else:
        answers = [fn(**o, **arguments, **extra) for o in objects]
    return [_finished(question, a, route, why, arguments, rig, asked) for a in answers]


def _resolve(question: str, route: str, arguments: dict[str, Any]):
    """The asked contact, then the route, its arguments and why (:func:`~designkit.query.policy.choose_route`),
    with the scene resolved for the sensor (:func:`~designkit.rig.rig_arguments`); an unknown question refused."""
    if question not in QUESTIONS:
        raise InputError(f"unknown question {question!r}; known: {', '.join(QUESTIONS)}")
    asked = arguments.get("contact_s")
    arguments, rig = rig_arguments(QUESTIONS[question].scene, arguments)
    route, arguments, why = choose_route(question, route, arguments)
    return asked, route, arguments, why, rig


def _own(question: str, route: str, why) -> bool:
    """A sensor's own table: no Monte Carlo bound from it."""
    return route == "table" and why.sensor_table and question in MC_BOUND


def _finished(question: str, ans, route: str, why, arguments, rig, asked):
    """An answer (or array answer) as :func:`ask` gives it: a sensor table's, the route's reason, counted as the
    rig counts."""
    if route == "table" and why.sensor_table:
        ans = sensor_table_answer(question, ans, why, arguments.get("sensor"))
    notes = (*ans.notes, why.reason) if why.noted and isinstance(ans, Answer) else None
    changes = {"route_reason": why.reason, **({"notes": notes} if notes else {})}
    ans = ans.replaced(**changes) if type(ans) is Answer else dataclasses.replace(ans, **changes)
    return ans if rig is None else for_rig(ans, rig, asked)


def _route(exact: bool, route: str | None) -> str:
    if route is not None and exact and route != "exact":
        raise InputError(f"exact=True contradicts route={route!r}")
    return route or ("exact" if exact else "auto")


# Each question answers one Answer for numbers and one ArrayAnswer when a numeric input is an array
# (the overloads tell editors and type checkers which).
@overload
def min_contact(e1: float | None = None, e2: float | None = None, *, noise_c: float = 0.05,
                delta_t_c: float = 10.0, exact: bool = False, route: str | None = None, **kw: Any) -> Answer: ...
@overload
def min_contact(e1: ArrayLike | None = None, e2: ArrayLike | None = None, *, noise_c: ArrayLike = 0.05,
                delta_t_c: ArrayLike = 10.0, exact: bool = False, route: str | None = None,
                ideal_bound: bool = True, **kw: Any) -> ArrayAnswer: ...
def min_contact(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any):
    """Shortest contact time [s] that separates two objects (table route unless ``exact``).

    See :func:`designkit.query.table.min_contact` and
    :func:`designkit.query.exact.exact_min_contact` for the arguments; arrays:
    :mod:`designkit.query.vectorized`.
    """
    return ask("min-contact", route=_route(exact, route), e1=e1, e2=e2, **kw)


@overload
def max_noise(e1: float | None = None, e2: float | None = None, *, contact_s: float, delta_t_c: float = 10.0,
              exact: bool = False, route: str | None = None, **kw: Any) -> Answer: ...
@overload
def max_noise(e1: ArrayLike | None = None, e2: ArrayLike | None = None, *, contact_s: ArrayLike,
              delta_t_c: ArrayLike = 10.0, exact: bool = False, route: str | None = None,
              ideal_bound: bool = True, **kw: Any) -> ArrayAnswer: ...
def max_noise(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any):
    """Largest noise sigma [degC] at which ``contact_s`` still separates two objects (arrays: as min_contact)."""
    return ask("max-noise", route=_route(exact, route), e1=e1, e2=e2, **kw)


@overload
def min_delta_t(e1: float | None = None, e2: float | None = None, *, contact_s: float, noise_c: float = 0.05,
                exact: bool = False, route: str | None = None, **kw: Any) -> Answer: ...
@overload
def min_delta_t(e1: ArrayLike | None = None, e2: ArrayLike | None = None, *, contact_s: ArrayLike,
                noise_c: ArrayLike = 0.05, exact: bool = False, route: str | None = None,
                ideal_bound: bool = True, **kw: Any) -> ArrayAnswer: ...
def min_delta_t(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any):
    """Smallest sensor-object temperature difference [degC] that separates two objects (arrays: as min_contact)."""
    return ask("min-delta-t", route=_route(exact, route), e1=e1, e2=e2, **kw)


@overload
def delta_e(e: float | None = None, *, contact_s: float, noise_c: float = 0.05, delta_t_c: float = 10.0,
            exact: bool = False, route: str | None = None, **kw: Any) -> Answer: ...
@overload
def delta_e(e: ArrayLike | None = None, *, contact_s: ArrayLike, noise_c: ArrayLike = 0.05,
            delta_t_c: ArrayLike = 10.0, exact: bool = False, route: str | None = None,
            ideal_bound: bool = True, **kw: Any) -> ArrayAnswer: ...
def delta_e(e=None, *, exact: bool = False, route: str | None = None, **kw: Any):
    """delta(e) [J s^-1/2 K^-1 m^-2] towards lower and higher effusivity (arrays: as min_contact)."""
    return ask("delta-e", route=_route(exact, route), e=e, **kw)


@overload
def distinguishable(e1: float | None = None, e2: float | None = None, *, contact_s: float, noise_c: float = 0.05,
                    delta_t_c: float = 10.0, exact: bool = False, route: str | None = None, **kw: Any) -> Answer: ...
@overload
def distinguishable(e1: ArrayLike | None = None, e2: ArrayLike | None = None, *, contact_s: ArrayLike,
                    noise_c: ArrayLike = 0.05, delta_t_c: ArrayLike = 10.0, exact: bool = False,
                    route: str | None = None, ideal_bound: bool = True, **kw: Any) -> ArrayAnswer: ...
def distinguishable(e1=None, e2=None, *, exact: bool = False, route: str | None = None, **kw: Any):
    """Whether a scene separates two objects, with the SVM's and the ideal observer's F1 (arrays: 1.0 / 0.0 / NaN)."""
    return ask("distinguishable", route=_route(exact, route), e1=e1, e2=e2, **kw)
