"""Cutting a sample stream into trials: detect each contact, cut the trial, write it at once.

:class:`TrialCutter` is pure logic. It is fed samples (time [s], sensor [degC], object [degC],
force [N]), detects contact with the profile's rule (force threshold, 5 N by default as in the
paper, or a temperature-slope rule), cuts ``pre_s`` before to ``post_s`` after the onset and
writes the trial (CSV + JSON sidecar, atomically, then the folder index) as soon as the window is
complete. A discontinuity (samples lost, device reset, reconnect) discards the trial in progress
and waits for a full clean ``pre_s`` before the next onset. :class:`~designkit.calibration.recorder.SerialRecorder`
feeds it from a serial port.
"""

from __future__ import annotations

import datetime as _dt
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import InputError, error_line
from .profiles import DeviceProfile
from .trials import FolderLock, check_material_label, write_trial

__all__ = ["COL_FORCE", "COL_OBJECT", "COL_SENSOR", "MIN_READABLE_FRACTION", "RecordEvent", "TrialCutter",
           "TrialNotWritten"]

#: Fewest samples of a trial's window that must be readable for the trial to be kept.
MIN_READABLE_FRACTION = 0.8
#: Columns of the samples a cutter is fed: sensor [degC], object [degC], force [N].
COL_SENSOR, COL_OBJECT, COL_FORCE = 0, 1, 2


@dataclass(frozen=True)
class RecordEvent:
    """Something worth telling the user.

    ``kind``: ``trial`` (written; ``path`` set), ``skipped`` (a touch not
    recorded, with the reason), ``bad_line``, ``gap``, ``reconnect``,
    ``device`` (a device message line), ``info``.
    """

    kind: str
    message: str
    path: Path | None = None


class TrialNotWritten(InputError):
    """The trial folder cannot be written; the touch was kept elsewhere when possible (message says where)."""


class TrialCutter:
    """Detect touches in a sample stream and write each trial as soon as it is complete.

    Parameters
    ----------
    profile : DeviceProfile
        Contact rule, trial window, sample rate.
    out_dir : Path
        Folder for the trials (created).
    material : str
        Label written with each trial.
    meta : dict
        Extra sidecar fields (port, profile name...).
    lock : FolderLock, optional
        The caller's held lock of ``out_dir`` (without one, each write locks the folder itself).
    """

    WAIT_RELEASE, ARMED, COLLECT, WAIT_STEADY = "waiting for release", "armed", "in contact", "waiting for steady"

    def __init__(self, profile: DeviceProfile, out_dir: Path, material: str,
                 meta: dict[str, Any] | None = None, lock: FolderLock | None = None) -> None:
        self.profile = profile
        self.out_dir = Path(out_dir)
        self.material = check_material_label(material)
        self.lock = lock
        self.meta = dict(meta or {})
        self.fs = profile.sample_rate_hz
        self.pre = profile.trial.pre_s
        self.post = profile.trial.post_s
        self.rule = profile.contact
        self.written: list[Path] = []
        self.events: list[RecordEvent] = []
        self._dropped: list[tuple[float, str]] = []   # (device time [s], why) of samples dropped upstream
        self._t = np.zeros(0)
        self._v = np.zeros((0, 3))
        self._scan = 0
        self._clean_since = -np.inf
        self._onset = np.nan
        self._state = self.WAIT_RELEASE if self.rule.rule == "force" else self.WAIT_STEADY

    @property
    def state(self) -> str:
        return self._state

    @property
    def in_trial(self) -> bool:
        return self._state == self.COLLECT

    # ------------------------------------------------------------- input
    def feed(self, time_s: np.ndarray, values: np.ndarray) -> list[RecordEvent]:
        """Add samples (times increasing, continuing the stream) and act on them.

        ``values`` has columns sensor [degC], object [degC], force [N] (NaN
        where the rig has no such channel). Returns the events raised.
        """
        t = np.asarray(time_s, dtype=np.float64)
        if t.size == 0:
            return []
        if not np.isfinite(self._clean_since):
            self._clean_since = float(t[0])
        self._t = np.concatenate([self._t, t])
        self._v = np.concatenate([self._v, np.asarray(values, dtype=np.float64).reshape(-1, 3)])
        events: list[RecordEvent] = []
        self._advance(events)
        self._trim()
        self.events.extend(events)
        return events

    def note_dropped(self, time_s: float, why: str) -> None:
        """A sample at device time ``time_s`` [s] was dropped before reaching here (the trial's sidecar says so)."""
        self._dropped.append((float(time_s), why))

    def discontinuity(self, reason: str) -> list[RecordEvent]:
        """Samples were lost or the clock restarted: drop the buffer and any trial in progress."""
        events = []
        if self._state == self.COLLECT:
            events.append(RecordEvent("skipped", f"trial in progress discarded: {reason}"))
        self._state = self.WAIT_RELEASE if self.rule.rule == "force" else self.WAIT_STEADY
        self._t = np.zeros(0)
        self._v = np.zeros((0, 3))
        self._dropped = []
        self._scan = 0
        self._clean_since = -np.inf
        self.events.extend(events)
        return events

    # ------------------------------------------------------------- logic
    def _slope(self) -> np.ndarray:
        """Smoothed temperature slope [degC/s] at each buffered sample (NaN where too early)."""
        h = max(2, int(round(self.rule.slope_window_s * self.fs / 2)))
        s = self._v[:, COL_SENSOR]
        out = np.full(s.size, np.nan)
        if s.size >= 2 * h:
            c = np.concatenate([[0.0], np.cumsum(s)])
            mean_new = (c[2 * h:] - c[h:-h]) / h
            mean_old = (c[h:-h] - c[:-2 * h]) / h
            out[2 * h - 1:] = (mean_new - mean_old) / (h / self.fs)
        return out

    def _advance(self, events: list[RecordEvent]) -> None:
        t, v = self._t, self._v
        eps = 0.5 / self.fs
        while True:
            if self._state == self.COLLECT:
                if t[-1] >= self._onset + self.post - eps:
                    self._finish(events)
                    self._state = self.WAIT_RELEASE if self.rule.rule == "force" else self.WAIT_STEADY
                    continue
                return
            if self._scan >= t.size:
                return
            if self._state == self.WAIT_RELEASE:
                below = np.flatnonzero(v[self._scan:, COL_FORCE] < self.rule.release_n)
                if below.size == 0:
                    self._scan = t.size
                    return
                self._scan += int(below[0])
                self._state = self.ARMED
                continue
            if self._state == self.WAIT_STEADY:
                slope = self._slope()[self._scan:]
                steady = np.abs(slope) < self.rule.slope_c_per_s / 2  # NaN -> False
                need = max(1, int(round(self.pre * self.fs)))
                run = np.convolve(steady.astype(np.int64), np.ones(need, dtype=np.int64), "valid")
                hit = np.flatnonzero(run == need)
                if hit.size == 0:
                    self._scan = max(self._scan, t.size - need + 1)
                    return
                self._scan += int(hit[0]) + need - 1
                self._state = self.ARMED
                continue
            # ARMED
            if self.rule.rule == "force":
                cross = np.flatnonzero(v[self._scan:, COL_FORCE] >= self.rule.force_threshold_n)
            else:
                cross = np.flatnonzero(self._slope()[self._scan:] <= -self.rule.slope_c_per_s)
            if cross.size == 0:
                self._scan = t.size
                return
            i = self._scan + int(cross[0])
            onset = float(t[i])
            self._scan = i + 1
            if onset - self.pre < self._clean_since - eps:
                have = max(0.0, onset - self._clean_since)
                events.append(RecordEvent(
                    "skipped", f"touch at device time {onset:.2f} s skipped: only {have:.2f} s of clean data "
                               f"before contact (need {self.pre:g} s)"))
                self._state = self.WAIT_RELEASE if self.rule.rule == "force" else self.WAIT_STEADY
                continue
            self._onset = onset
            self._state = self.COLLECT

    def _finish(self, events: list[RecordEvent]) -> None:
        t, v = self._t, self._v
        eps = 0.5 / self.fs
        onset = self._onset
        sel = (t >= onset - self.pre - eps) & (t <= onset + self.post + eps)
        tt = t[sel] - onset
        vv = v[sel]
        expected = int(round((self.pre + self.post) * self.fs)) + 1
        if tt.size < MIN_READABLE_FRACTION * expected:
            events.append(RecordEvent(
                "skipped", f"touch at device time {onset:.2f} s skipped: only {tt.size} of {expected} samples "
                           "readable"))
            return
        pre = tt < 0
        release_s = None
        if self.rule.rule == "force":
            after = np.flatnonzero((tt > 0) & (vv[:, COL_FORCE] < self.rule.release_n))
            if after.size:
                release_s = float(tt[after[0]])
        ts0 = float(np.mean(vv[pre, COL_SENSOR]))
        to0 = float(np.mean(vv[pre, COL_OBJECT])) if np.isfinite(vv[pre, COL_OBJECT]).any() else None
        meta = {
            **self.meta,
            "recorded_at": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
            "sensor_temp_before_c": ts0,
            "object_temp_before_c": to0,
            "onset_device_time_s": onset,
            "contact_rule": self.rule.to_dict(),
            "pre_s": self.pre,
            "post_s": self.post,
            "release_s": release_s,
            "sample_rate_hz": self.fs,
            "n_samples": int(tt.size),
            "n_missing": int(expected - tt.size),
        }
        dropped = [{"time_s": d - onset, "why": why} for d, why in self._dropped
                   if onset - self.pre - eps <= d <= onset + self.post + eps]
        if dropped:
            meta["dropped_samples"] = dropped
        path = self._write(tt, vv, meta, events)
        self.written.append(path)
        note = f", released at {release_s:.2f} s" if release_s is not None else ""
        if dropped:
            note += f"; {len(dropped)} implausible sample(s) dropped, listed in its sidecar"
        obj = f", object {to0:.2f} °C" if to0 is not None else ""
        events.append(RecordEvent("trial", f"trial {len(self.written)}: {path.name} (sensor {ts0:.2f} °C{obj}"
                                           f" before contact{note})", path))

    def _write(self, tt: np.ndarray, vv: np.ndarray, meta: dict, events: list[RecordEvent]) -> Path:
        """Write the trial; whatever fails, the touch is kept somewhere and the user is told where.

        First under the label's name; then under the plain name ``trial_NNN``
        in the same folder (a name the file system refused); then, when the
        folder cannot take it at all (disk full, gone, read-only), in a new
        folder under the system's temporary folder, after which recording
        stops (:class:`TrialNotWritten`, naming both).
        """
        cols = (tt, vv[:, COL_SENSOR], vv[:, COL_OBJECT], vv[:, COL_FORCE])
        try:
            return write_trial(self.out_dir, self.material, *cols, meta, lock=self.lock)
        except (OSError, InputError) as exc:
            first = exc
        try:
            path = write_trial(self.out_dir, self.material, *cols, meta, lock=self.lock, stem="trial")
            events.append(RecordEvent("info", f"could not write the trial under its label's name "
                                              f"({error_line(first)}): written as {path.name} instead (its sidecar and "
                                              "the index keep the label)"))
            return path
        except (OSError, InputError):
            pass
        n = len(self.written)
        kept = f"{n} trial(s) kept in {self.out_dir}"
        try:
            rescue = Path(tempfile.mkdtemp(prefix="designkit-rescued-trial-"))
            path = write_trial(rescue, self.material, *cols, meta)
        except (OSError, InputError) as exc:
            raise TrialNotWritten(f"cannot write the trial just recorded into {self.out_dir} ({error_line(first)}), nor "
                                  f"into a temporary folder ({error_line(exc)}): that touch is lost; {kept}") from None
        raise TrialNotWritten(f"cannot write into {self.out_dir} ({error_line(first)}): the trial just recorded was kept "
                              f"as {path} (move it and its .json into the folder once it can be written); {kept}")

    def _trim(self) -> None:
        if self._state == self.COLLECT or self._t.size == 0:
            return
        keep_from = self._t[-1] - self.pre - max(1.0, 2 * self.rule.slope_window_s)
        cut = int(np.searchsorted(self._t, keep_from))
        if self._state == self.WAIT_STEADY:
            need = max(1, int(round(self.pre * self.fs))) + int(round(self.rule.slope_window_s * self.fs)) + 2
            cut = min(cut, max(0, self._scan - need))
        cut = min(cut, self._scan)
        if self._dropped and cut < self._t.size:
            self._dropped = [d for d in self._dropped if d[0] >= self._t[cut]]
        if cut > 0:
            self._t = self._t[cut:]
            self._v = self._v[cut:]
            self._scan -= cut
