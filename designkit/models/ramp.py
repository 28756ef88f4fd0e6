"""A contact area that grows while the finger presses in: any model's reading, summed over the area's shares.

A real touch does not put the whole contact area down at once: the force
rises over 0.5-1 s, and each share of the final area starts its own heat flow
when it comes into contact. With the shares as parallel columns (lateral
conduction neglected) and every model here linear in the temperatures, the
reading is the area-weighted sum of step responses (Duhamel's principle),

.. math::

    u(t) = \\sum_j \\Delta A_j \\, u_{\\mathrm{step}}(t - t_j),

with ``A(t)`` the share of the final area in contact (0 before contact, 1 from
the end of the ramp on) and ``u_step`` the full-contact reading of the
``base`` model. Calibration (:mod:`designkit.calibration.identify`, option
``force_area``) fits the area from each touch's measured force,
``A = clip((F / F_p - c) / (1 - c), 0, 1)`` (:func:`area_share`); a sensor file
records the threshold ``c`` and the calibration touches' median force ramp, and
:func:`designkit.models.sensor_model` plays that nominal ramp for touches that
have no force trace (questions, sweeps, simulations).

Time ``t = 0`` is the first instant any share of the area is in contact (the
heat flow's start, as for every other model), so a contact time counts from
there.

Examples
--------
>>> from designkit import SENSORS
>>> from designkit.models.semi_infinite import SemiInfinite
>>> instant = ForceRamp(SemiInfinite(), ramp_time_s=(0.0,), ramp_area=(1.0,))
>>> t = [0.5, 2.0]
>>> bool(np.allclose(instant.response(t, [400.0], SENSORS["paper"]), SemiInfinite().response(t, [400.0],
...      SENSORS["paper"])))
True
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from .._validation import InputError
from .base import ForwardModel

__all__ = ["ForceRamp", "area_share"]


def area_share(force_rel, fraction: float = 0.0) -> np.ndarray:
    """Share of the final contact area in contact: ``clip((F / F_p - c) / (1 - c), 0, 1)``.

    Parameters
    ----------
    force_rel : array_like
        Force divided by its plateau ``F / F_p``.
    fraction : float
        ``c``, the force share at which the area starts to grow, in [0, 1).

    Examples
    --------
    >>> area_share([0.1, 0.3, 0.65, 1.0, 1.2], 0.3).round(3).tolist()
    [0.0, 0.0, 0.5, 1.0, 1.0]
    """
    c = float(fraction)
    if not 0.0 <= c < 1.0:
        raise InputError(f"contact force fraction c must be in [0, 1), got {c:g}")
    return np.clip((np.asarray(force_rel, dtype=np.float64) - c) / (1.0 - c), 0.0, 1.0)


@dataclass(frozen=True)
class ForceRamp(ForwardModel):
    """The ``base`` model's reading with a contact area that grows along a given ramp.

    Parameters
    ----------
    base : ForwardModel or mapping or None
        The full-contact model (a mapping as :meth:`ForwardModel.to_dict` writes
        it; None: the semi-infinite model).
    ramp_time_s : tuple of float
        Times [s] after the first contact, increasing, the first 0.
    ramp_area : tuple of float
        Share of the final contact area in contact at those times: in (0, 1],
        non-decreasing, the last 1 (held at 1 afterwards).
    force_fraction : float
        The threshold ``c`` the ramp was made with (recorded, for people; the
        ramp already contains it).
    source : str
        Where the ramp came from (for people).
    touch_ramps : tuple of (float, tuple, tuple)
        The calibration touches' own ramps, ``(delay_s, ramp_time_s, ramp_area)`` each, the delay of
        its first contact after the nominal ramp's (negative: before it). A simulated touch presses as
        one of them, drawn at random (:func:`designkit.simulation.simulate_class`): real presses vary in
        pace and in where the recorder's onset fires. Empty: every touch follows the nominal ramp.

    Examples
    --------
    >>> from designkit import SENSORS
    >>> from designkit.models.contact import Contact
    >>> base = Contact(conductance_w_m2k=2500.0)
    >>> slow = ForceRamp(base, ramp_time_s=(0.0, 0.25, 0.5), ramp_area=(0.2, 0.6, 1.0))
    >>> u, full = slow.response([0.1, 0.4, 3.0], [400.0], SENSORS["paper"]), base.response([0.1, 0.4, 3.0], [400.0],
    ...                                                                             SENSORS["paper"])
    >>> bool(np.all(u < full)), bool(np.isclose(u[0, 0], 0.2 * full[0, 0]))
    (True, True)
    """

    base: Any = None
    ramp_time_s: tuple[float, ...] = (0.0,)
    ramp_area: tuple[float, ...] = (1.0,)
    force_fraction: float = 0.0
    source: str = ""
    touch_ramps: tuple = ()

    name = "force-ramp"
    shared_shape = False
    shared_response = True
    units = {"ramp_time_s": "s", "ramp_area": "share of the final contact area", "force_fraction": "of F_p",
             "touch_ramps": "delay s, times s, area shares"}

    def __post_init__(self) -> None:
        base = self.base
        if base is None:   # the defaults: the paper's model, the whole area at once
            from .semi_infinite import SemiInfinite

            base = SemiInfinite()
        if isinstance(base, Mapping):
            from . import get_model

            base = get_model(dict(base))
        if not isinstance(base, ForwardModel) or isinstance(base, ForceRamp):
            raise InputError("a force ramp needs a base model (a full-contact forward model, not another ramp)")
        object.__setattr__(self, "base", base)
        t = np.asarray(self.ramp_time_s, dtype=np.float64).ravel()
        a = np.asarray(self.ramp_area, dtype=np.float64).ravel()
        if t.size == 0 or t.size != a.size:
            raise InputError(f"a force ramp needs as many area shares as times, got {a.size} and {t.size}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(a))):
            raise InputError("a force ramp's times and area shares must be finite numbers")
        if t[0] != 0.0 or np.any(np.diff(t) <= 0):
            raise InputError("a force ramp's times must start at 0 (the first contact) and increase")
        if a[0] <= 0.0 or np.any(np.diff(a) < 0) or abs(a[-1] - 1.0) > 1e-9:
            raise InputError("a force ramp's area shares must be above 0, non-decreasing, and end at 1")
        object.__setattr__(self, "ramp_time_s", tuple(float(v) for v in t))
        object.__setattr__(self, "ramp_area", tuple(float(v) for v in a))
        object.__setattr__(self, "force_fraction", float(self.force_fraction))
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "object_properties", base.object_properties)
        touches = []
        for item in self.touch_ramps:
            delay, times, areas = (item["delay_s"], item["ramp_time_s"], item["ramp_area"]) \
                if isinstance(item, Mapping) else item
            one = ForceRamp(base, tuple(times), tuple(areas), self.force_fraction)   # validates the ramp
            touches.append((float(delay), one.ramp_time_s, one.ramp_area))
        object.__setattr__(self, "touch_ramps", tuple(touches))

    def touch(self, j: int) -> tuple["ForceRamp", float]:
        """Touch ``j``'s own ramp (a ramp without touch ramps) and its first contact's delay [s] after the
        nominal one's: its reading at model time ``t`` is ``ramp.response(t - delay)``."""
        return self._touches[int(j)]

    @functools.cached_property
    def _touches(self) -> tuple:
        """Every touch's ``(ramp, delay)``, made once (a simulated class asks for them class after class)."""
        return tuple((ForceRamp(self.base, times, areas, self.force_fraction, self.source), delay)
                     for delay, times, areas in self.touch_ramps)

    def nominal(self) -> "ForceRamp":
        """This ramp without the touch ramps (every touch pressing as the nominal one)."""
        return dataclasses.replace(self, touch_ramps=()) if self.touch_ramps else self

    @classmethod
    def from_force_profile(cls, base, time_s, force_rel, fraction: float, *, source: str = "",
                           touch_force_rel=()) -> "ForceRamp":
        """The ramp of a nominal force profile ``F / F_p`` at ``time_s`` after the detected onset.

        The area ``A = clip((F/F_p - c) / (1 - c), 0, 1)`` (made non-decreasing:
        an area in contact stays in contact, a force overshoot does not add
        area) starts its heat flow when it comes into contact; ``t = 0`` of the
        result is the first share's contact (a calibrated time offset of the
        heat flow relative to the detected onset moves every share alike, so it
        does not enter). After the profile's last time the whole area is in
        contact. ``touch_force_rel``: each calibration touch's own ``F / F_p`` on ``time_s`` (rows), kept as
        :attr:`touch_ramps` with the delay of its first contact after the nominal one's.

        Examples
        --------
        >>> from designkit.models.semi_infinite import SemiInfinite
        >>> r = ForceRamp.from_force_profile(SemiInfinite(), [0.0, 0.1, 0.2, 0.3], [0.1, 0.5, 0.9, 1.0], 0.3,
        ...                                  touch_force_rel=[[0.5, 1.0, 1.0, 1.0]])
        >>> r.ramp_time_s, [round(a, 3) for a in r.ramp_area], r.touch_ramps[0][0]
        ((0.0, 0.1, 0.2), [0.286, 0.857, 1.0], -0.1)
        """
        nominal = cls._profile_ramp(time_s, force_rel, fraction)
        touches = []
        for row in touch_force_rel:
            first, times, shares = cls._profile_ramp(time_s, row, fraction)
            touches.append((round(first - nominal[0], 9), times, shares))
        return cls(base, nominal[1], nominal[2], float(fraction), source, tuple(touches))

    @staticmethod
    def _profile_ramp(time_s, force_rel, fraction: float) -> tuple[float, tuple, tuple]:
        """(time of the first contact, ramp times from it, area shares) of one force profile."""
        t = np.asarray(time_s, dtype=np.float64).ravel()
        area = np.maximum.accumulate(area_share(force_rel, fraction))
        if t.size != area.size or t.size == 0:
            raise InputError(f"a force profile needs as many forces as times, got {area.size} and {t.size}")
        on = np.flatnonzero(area > 0)
        if on.size == 0:
            raise InputError(f"the force profile never exceeds the contact threshold c = {fraction:g} of its "
                             "plateau: no contact area")
        first = int(on[0])
        full = np.flatnonzero(area >= 1.0)
        last = int(full[0]) if full.size else area.size - 1
        times = np.round(t[first:last + 1] - t[first], 9)
        shares = area[first:last + 1].copy()
        if shares[-1] < 1.0:  # the plateau from the next sample on
            step = float(t[1] - t[0]) if t.size > 1 else 0.0
            times = np.append(times, times[-1] + step)
            shares = np.append(shares, 1.0)
        return float(t[first]), tuple(float(v) for v in times), tuple(float(v) for v in shares)

    # ------------------------------------------------------------ the physics
    def _step_model(self):
        """The base model without the host smoothing (applied once, to the summed reading)."""
        if getattr(self.base, "smoothing_window", 0) > 1:
            return dataclasses.replace(self.base, smoothing_window=0)
        return self.base

    @functools.cached_property
    def _shares(self) -> tuple[np.ndarray, np.ndarray]:
        """The ramp's contact times [s] and area increments ``dA_j`` (those > 0), made once."""
        tj = np.asarray(self.ramp_time_s)
        da = np.diff(np.asarray(self.ramp_area), prepend=0.0)
        return tj[da > 0], da[da > 0]

    def __hash__(self) -> int:
        return self._hash

    def __getstate__(self) -> dict:
        """The fields and made-once parts, not the hash (a string's hash differs from process to process)."""
        return {k: v for k, v in self.__dict__.items() if k != "_hash"}

    @functools.cached_property
    def _hash(self) -> int:
        """The dataclass's field hash, made once (a scene's cached panels are looked up class after class, and a
        calibrated rig's 24 touch ramps take 0.3 ms to hash)."""
        return hash((self.base, self.ramp_time_s, self.ramp_area, self.force_fraction, self.source,
                     self.touch_ramps))

    @staticmethod
    def _duhamel(step, parts, e, sensor, diffusivity_m2_s, tolerance: float) -> list:
        """Unsmoothed readings (K_p, m_p) of each part ``(t, tj, dA, rows)``: objects ``e[rows]`` at times ``t``, the
        dA-weighted sum of ``step``'s responses to shares in contact from ``tj`` (uniform grids: :meth:`_on_grid`)."""
        outs, grid = [], []
        for p, (t, tj, da, rows) in enumerate(parts):
            idx = np.arange(e.size)[rows]
            outs.append(np.zeros((idx.size, t.size)))
            if t.size == 0 or not t.max() > tj.min():                   # no share in contact by the last time
                continue
            dt = float(t[1] - t[0]) if t.size > 1 else 0.0
            if dt > 0 and np.all(np.abs(np.diff(t) - dt) <= 1e-9 * dt) \
                    and (not grid or abs(dt - grid[0][1]) <= 1e-9 * dt):
                grid.append((p, dt, idx))
                continue
            # any times: one evaluation of the step response at the distinct lags, then the sum share by share
            lags = t[None, :] - tj[:, None]                             # (J, m)
            pos = lags > 0
            key = np.round(lags[pos] * 1e9).astype(np.int64)
            uniq, first, inverse = np.unique(key, return_index=True, return_inverse=True)
            u = step.response(lags[pos][first], e[idx], sensor, tolerance=tolerance,
                              diffusivity_m2_s=None if diffusivity_m2_s is None else diffusivity_m2_s[idx])
            where = np.zeros(lags.shape, dtype=np.int64)
            where[pos] = inverse.ravel()
            for j in range(tj.size):
                cols = np.flatnonzero(pos[j])
                outs[p][:, cols] += da[j] * u[:, where[j, cols]]
        if grid:
            ForceRamp._on_grid(outs, grid, parts, step, e, sensor, diffusivity_m2_s, tolerance)
        return outs

    @staticmethod
    def _on_grid(outs, grid, parts, step, e, sensor, diffusivity_m2_s, tolerance) -> None:
        """The Duhamel sums on uniform grids of step ``dt`` as convolutions: ``out[i] += sum_j dA_j S[n_j + i]``.

        Share ``j``'s lags are ``t_0 + i dt - t_j = (n_j + f_j + i) dt`` with ``n_j`` whole and the phase
        ``f_j`` in [0, 1) (phases within 1e-6 of a step of each other taken as the smallest of them: ramp times
        on the grid's own step differ there only by the rounding of ``t - t_j`` and ``dt``, a shift of ~1e-9
        ``dt``, far below the readings' tolerance): the shares of one phase, of every part (a class's touch ramps,
        read at their own delays), read one step response ``S_l = u_step((f + l) dt)`` of all their distinct
        objects, long enough for the latest share; each part's sum is the correlation of ``S`` with its kernel
        ``c_n = sum_{n_j = n} dA_j``, all parts in one real FFT (pocketfft: the same bits on every run).
        """
        from scipy import fft

        dt = grid[0][1]
        shift = np.concatenate([(parts[p][0][0] - parts[p][1]) / dt for p, _, _ in grid])
        whole = np.floor(shift + 1e-9)
        frac, whole = np.maximum(shift - whole, 0.0), whole.astype(np.int64)
        sizes = [parts[p][1].size for p, _, _ in grid]
        part = np.repeat(np.arange(len(grid)), sizes)                   # each share's part (index into grid)
        m_of = np.array([parts[p][0].size for p, _, _ in grid])[part]
        da_all = np.concatenate([parts[p][2] for p, _, _ in grid])
        order = np.argsort(frac, kind="stable")
        new = np.diff(frac[order], prepend=-1.0) > 1e-6
        label = np.empty(frac.size, dtype=np.int64)
        label[order] = np.cumsum(new) - 1
        for g, f in enumerate(frac[order][new].tolist()):
            sel = np.flatnonzero((label == g) & (whole > -m_of))   # a share in contact after the last time adds nothing
            if not sel.size:
                continue
            n, q = whole[sel], part[sel]
            members = np.unique(q)
            pad = max(0, -int(n.min()))                                 # zeros before contact where n_j < 0
            width = pad + int(n.max()) + 1                              # kernel length
            length = int((n + m_of[sel]).max())                         # l = 0 .. n_j + m - 1 (> 0)
            rows = np.concatenate([grid[k][2] for k in members.tolist()])
            # distinct objects (an object read under several ramps is read once)
            key = e[rows] if diffusivity_m2_s is None else rows
            objects, at, where = np.unique(key, return_index=True, return_inverse=True)
            at = rows[at]                                               # a row of each distinct object
            lag = (f + np.arange(length)) * dt
            live = lag > 0
            S = np.zeros((objects.size, pad + length))
            if live.any():
                S[:, pad + np.flatnonzero(live)] = step.response(
                    lag[live], e[at], sensor, tolerance=tolerance,
                    diffusivity_m2_s=None if diffusivity_m2_s is None else diffusivity_m2_s[at])
            kernel = np.zeros((members.size, width))                    # reversed, share by share: a correlation
            np.add.at(kernel, (np.searchsorted(members, q), width - 1 - (n + pad)), da_all[sel])
            size = fft.next_fast_len(S.shape[1], real=True)
            counts = [grid[k][2].size for k in members.tolist()]
            full = fft.irfft(fft.rfft(S, size, axis=1)[where.ravel()]
                             * np.repeat(fft.rfft(kernel, size, axis=1), counts, axis=0), size, axis=1)
            first = 0
            for k, count in zip(members.tolist(), counts):
                p = grid[k][0]
                outs[p] += full[first:first + count, width - 1:width - 1 + parts[p][0].size]
                first += count

    def response(self, time_s, e_object, sensor, *, diffusivity_m2_s=None, tolerance: float = 1e-9) -> np.ndarray:
        """Normalized reading (K, m): the area-weighted sum of the base model's step responses.

        With a base model that smooths (the host's Savitzky-Golay filter), the
        sum is smoothed once, as the host smoothed the recorded touch; then the
        times must be uniform.
        """
        return self._read(time_s, e_object, [(self, 0.0, slice(None))], sensor, diffusivity_m2_s, tolerance)

    def touch_readings(self, time_s, e_object, touch, sensor, *, diffusivity_m2_s=None,
                       tolerance: float = 1e-9) -> np.ndarray:
        """Normalized readings (K, m) of objects ``e_object`` (K,), object ``k`` pressing as touch ramp ``touch[k]``
        (:meth:`touch`: its reading at ``time_s - delay``): each touch ramp's :meth:`response`, smoothed at once."""
        touch = np.asarray(touch)
        groups = [(*self.touch(j), touch == j) for j in np.unique(touch).tolist()]
        return self._read(time_s, e_object, groups, sensor, diffusivity_m2_s, tolerance)

    def touch_responses(self, time_s, e_object, sensor, *, tolerance: float = 1e-9) -> np.ndarray:
        """Normalized readings (K, R, m) of objects ``e_object`` (K,) pressing as each of the ``R`` touch ramps:
        one step response of the K objects for all ramps (:meth:`_on_grid`), what a scene's panels of every touch
        ramp at once read (:func:`designkit.models.shared.class_readings` with ``touch``)."""
        e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
        k, r = e.size, len(self.touch_ramps)
        groups = [(*self.touch(j), slice(j * k, (j + 1) * k)) for j in range(r)]
        return self._read(time_s, np.tile(e, r), groups, sensor, None, tolerance).reshape(r, k, -1).transpose(1, 0, 2)

    def _read(self, time_s, e_object, groups, sensor, diffusivity_m2_s, tolerance: float) -> np.ndarray:
        """Objects ``e_object[rows]`` read as ``ramp`` at ``time_s - delay``, for each ``(ramp, delay, rows)``;
        with a base model that smooths, every row's sum smoothed in one call."""
        from .layered import smooth_cut, smoothing_grid

        t = np.atleast_1d(np.asarray(time_s, dtype=np.float64))
        e = np.atleast_1d(np.asarray(e_object, dtype=np.float64))
        window = int(getattr(self.base, "smoothing_window", 0) or 0)
        grid = t if window <= 1 else smoothing_grid(t, sensor.sample_rate_hz, window,
                                                    what="a smoothed model with a force ramp")
        parts = [(grid - delay, *ramp._shares, rows) for ramp, delay, rows in groups]
        d = None if diffusivity_m2_s is None else np.broadcast_to(np.asarray(diffusivity_m2_s, dtype=np.float64),
                                                                    e.shape)
        raw = np.zeros((e.size, t.size)) if not groups else None
        for (_, _, _, rows), u in zip(parts, self._duhamel(self._step_model(), parts, e, sensor, d, tolerance)):
            raw = np.empty((e.size, u.shape[1])) if raw is None else raw
            raw[rows] = u
        if window <= 1 or not groups:
            return np.clip(raw, 0.0, 1.0, out=raw)     # the FFT's rounding around 0 before contact
        return smooth_cut(raw, t.size, window, int(self.base.smoothing_order))

    def check(self, objects, sensor, *, contact_s: float, noise_c: float, delta_t_c: float):
        """The base model's check (the ramp adds no validity limit of its own)."""
        return self.base.check(objects, sensor, contact_s=contact_s, noise_c=noise_c, delta_t_c=delta_t_c)

    # ------------------------------------------------------------ the catalogue entry
    @property
    def ramp_duration_s(self) -> float:
        """Time [s] from the first contact until the whole area is in contact."""
        return float(self.ramp_time_s[-1])

    def parameters(self) -> dict[str, Any]:
        out = {"base": self.base.to_dict(), "ramp_time_s": list(self.ramp_time_s),
               "ramp_area": list(self.ramp_area), "force_fraction": self.force_fraction, "source": self.source}
        if self.touch_ramps:
            out["touch_ramps"] = [{"delay_s": d, "ramp_time_s": list(t), "ramp_area": list(a)}
                                  for d, t, a in self.touch_ramps]
        return out

    def describe(self) -> str:
        """The base model, and the ramp in one phrase."""
        how = f", {self.source}" if self.source else ""
        touches = f"; each touch pressing as one of {len(self.touch_ramps)} calibration touches" \
            if self.touch_ramps else ""
        return (f"{self.base.describe()} with a contact area growing over {self.ramp_duration_s:.2f} s "
                f"(c = {self.force_fraction:.3g}{how}{touches})")
