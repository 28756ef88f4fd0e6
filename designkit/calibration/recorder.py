"""Recording touches from a serial device: detect each contact, cut the trial, write it at once.

:class:`SerialRecorder` reads a serial port with pyserial, splits the byte
stream into lines, parses them with the profile and feeds a
:class:`~designkit.calibration.cutter.TrialCutter` (which detects each contact,
cuts the trial and writes it). It survives garbled, partial or non-numeric
lines, wrong field counts, out-of-range readings (each reported once per kind
with an example, then counted), bursts, gaps (from the device clock, or from
silences longer than the profile's ``stall_s`` when there is no timestamp), a
device that disappears (it tries to reopen the port for ``reconnect_s``) and a
device that never speaks (``no_data_timeout_s``). Trials already written are
never touched again; Ctrl-C (KeyboardInterrupt) leaves them all in place. A reopened port
records only once it shows the session's device (:mod:`~designkit.calibration.reconnect`).

Without a timestamp channel, time is the count of lines received divided by
the sample rate; a line that cannot be read still counts (its sample is
missing from the trial, the times of the others stay right).

Lines that lie. A line that parses may still be wrong. With device
timestamps, a line whose time is not just after the previous line's (the same
time: sent twice; earlier: out of order; far ahead) is skipped as a bad line
and the touch in progress goes on; only ``CONFIRM_SAMPLES`` lines in a row
that continue from the new time make it a real clock jump (a reset, or
samples lost), which ends the trial in progress. Every sample then passes a
plausibility filter: a heated thermistor and a force sensor cannot reverse
within one sample (their time constants are many sample periods), so a
sample outside the range of its two neighbours by more than ``SPIKE_SIGMAS``
times the stream's noise (measured on the session's samples out of contact,
or one quantization step if larger) is a corrupted line (``24.9884`` read as
``26.9884``): it is dropped, reported (on the event stream, and in the
sidecar's ``dropped_samples`` of the trial it fell in, with the reason) and
counted. A profile's line checksum (``line.checksum``) catches what is below
that margin.

Give-up rule for a stream that never lets a touch be kept: when
``GIVE_UP_TOUCHES`` touches in a row were skipped (their trial discarded by a
clock jump, too few readable samples, too little clean data before contact)
and no touch was kept for ``GIVE_UP_WINDOWS`` trial windows of stream
(``5 x (pre_s + post_s)``, 40 s of device time by default), the recorder stops
(:class:`NoProgress`, exit 2 in the CLI, naming the last reason; trials already
written stay).

Give-up rule for unreadable lines: a trial is kept only when at least
``MIN_READABLE_FRACTION`` (80 %) of its samples could be read, so once the
last trial-length of lines (``(pre_s + post_s) * sample_rate_hz + 1``, at
least 200) holds more than 20 % unreadable ones, a trial over them could not
be kept and the recorder stops (:class:`TooManyBadLines`, naming the fraction
and an example line; trials already written stay). A stream none of whose first
200 lines is readable stops sooner (:class:`NoData`: wrong profile or baud
rate).
"""

from __future__ import annotations

import errno
import math
import os
import stat
import time
import uuid
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from .._validation import InputError, check_positive, error_line
from .profiles import ROLES, DeviceProfile
from .reconnect import Probation
from .cutter import COL_FORCE, MIN_READABLE_FRACTION, RecordEvent, TrialCutter
from .trials import FolderLock, check_material_label, check_trial_folder

__all__ = ["CONFIRM_SAMPLES", "DeviceChanged", "GIVE_UP_TOUCHES", "GIVE_UP_WINDOWS", "NoProgress", "SPIKE_SIGMAS",
           "RecorderStatus", "SerialRecorder"]

# Lines that parse but cannot be right (module docstring, "Lines that lie")
#: Samples in a row, each within ``stall_s`` of the one before, that make a jump of the device clock real.
CONFIRM_SAMPLES = 3
#: Margin of the plausibility filter in units of the stream's own noise (measured out of contact).
SPIKE_SIGMAS = 8.0
#: Samples out of contact the noise must be measured on before the plausibility filter acts.
_SPIKE_MIN_REFERENCE = 50
# Give-up rule for a stream that never lets a touch be kept (module docstring)
#: Touches in a row not kept, at the least, before giving up.
GIVE_UP_TOUCHES = 3
#: Trial windows (pre_s + post_s) of stream without a touch kept, at the least, before giving up.
GIVE_UP_WINDOWS = 5

#: Device seconds of samples out of contact the session's reference temperatures are the median of.
_REFERENCE_S = 20.0

_BAD_KIND_TEXT = {
    "garbled": "garbled bytes (not text in the profile's encoding)",
    "field_count": "wrong number of fields",
    "non_numeric": "a field that is not a finite number",
    "out_of_range": "a reading out of range (ADC rail, open/shorted thermistor, or outside 'valid')",
    "too_long": "a line far too long (no newline)",
    "checksum": "a missing or wrong checksum (the line changed on the wire)",
    "duplicate": "a repeated timestamp (the line was sent twice)",
    "out_of_order": "a timestamp before the previous line's (out of order)",
    "time_jump": "a timestamp ahead of the lines around it (out of order, or damaged)",
    "implausible": "a physically impossible jump (outside its neighbours' range by more than "
                   f"{SPIKE_SIGMAS:g} times the stream's noise)",
}
_EXAMPLES_PER_KIND = 3


@dataclass
class RecorderStatus:
    """Live numbers for a display."""

    port: str = ""
    material: str = ""
    state: str = "connecting"
    trials: int = 0
    target: int = 0
    sensor_c: float = float("nan")
    object_c: float = float("nan")
    force_n: float = float("nan")
    device_time_s: float = 0.0
    lines_ok: int = 0
    lines_bad: int = 0
    bad_by_kind: dict[str, int] = field(default_factory=dict)
    gaps: int = 0
    skipped: int = 0
    last_message: str = ""


class DeviceGone(InputError):
    """The port disappeared and could not be reopened."""


class NoData(InputError):
    """Nothing usable arrived within the time limit."""


class NoProgress(InputError):
    """Touch after touch was skipped and none kept for a long stretch of stream (module docstring)."""


class TooManyBadLines(InputError):
    """So many lines are unreadable that no trial can be kept (see the module docstring)."""


class DeviceChanged(InputError):
    """After a reconnect the port streams data unlike the session's device (see the module docstring)."""


class SerialRecorder:
    """Record touches from a serial port into a folder.

    Parameters
    ----------
    port : str
        Serial device (``/dev/ttyACM0``, ``COM3``, a pty from the emulator).
    profile : DeviceProfile
    out_dir : Path
    no_data_timeout_s : float, optional
        Overrides the profile's limit for a device that never speaks [s]
        (positive and finite).
    on_event : callable(RecordEvent), optional
    on_status : callable(RecorderStatus), optional
        Called a few times a second with live numbers.

    Raises
    ------
    InputError
        ``out_dir`` has an index that recording would spoil (see
        :func:`~designkit.calibration.trials.check_trial_folder`), or a bad
        ``no_data_timeout_s``.
    """

    def __init__(self, port: str, profile: DeviceProfile, out_dir: Path | None, *,
                 no_data_timeout_s: float | None = None,
                 on_event: Callable[[RecordEvent], None] | None = None,
                 on_status: Callable[[RecorderStatus], None] | None = None) -> None:
        self.port = str(port)
        self.profile = profile
        self.out_dir = Path(out_dir) if out_dir is not None else None  # None: a subclass writes no trials
        if self.out_dir is not None:
            check_trial_folder(self.out_dir)
        #: Names this recording session in every trial's sidecar (``session``).
        self.session = uuid.uuid4().hex
        self._lock = FolderLock(self.out_dir) if self.out_dir is not None else None
        if no_data_timeout_s is None:
            no_data_timeout_s = profile.serial.no_data_timeout_s
        self.no_data_timeout_s = check_positive("no_data_timeout_s [s]", no_data_timeout_s)
        self.on_event = on_event or (lambda e: None)
        self.on_status = on_status or (lambda s: None)
        self.status = RecorderStatus(port=self.port)
        self.written: list[Path] = []
        self.events: list[RecordEvent] = []
        self._ser = None
        self._buf = b""
        self._first_line = True
        self._slot = 0  # sample slots seen since the clock started (no timestamp)
        self._last_t: float | None = None
        self._examples: dict[str, int] = {}
        self._valid_seen = False
        self._lines_seen = 0
        fs, window = profile.sample_rate_hz, profile.trial.pre_s + profile.trial.post_s
        self._bad_window = max(200, int(round(window * fs)) + 1)  # lines the give-up rule looks at
        self._recent_bad = np.zeros(0, dtype=bool)
        self._last_bad_text = ""
        self._pre_contact: list[tuple[float, float]] = []   # the trials' (sensor, object) before contact
        self._idle_t = np.zeros(0)        # recent samples out of contact: the session's reference
        self._idle_v = np.zeros((0, 3))
        self._verify: Probation | None = None
        self._pend: list[tuple[float, np.ndarray]] = []   # samples after a clock jump, until confirmed
        self._held: tuple[np.ndarray, np.ndarray] | None = None   # the last sample, until its successor comes
        self._prev_row: np.ndarray | None = None   # the last sample fed: the left neighbour of the next
        self._idle_seen = 0   # samples out of contact remembered so far
        self._margin: tuple[int, np.ndarray | None] = (-1, None)   # (at _idle_seen, per-channel margin)
        self._skips: list[str] = []   # touches skipped since the last one kept
        self._kept_at = 0   # _lines_seen when the last touch was kept (or the recording started)
        win = profile.trial.pre_s + profile.trial.post_s
        #: Stream seconds without a touch kept (and GIVE_UP_TOUCHES skipped) after which the recorder gives up.
        self.give_up_s = GIVE_UP_WINDOWS * win

    #: What becomes of a touch that is not skipped (messages of the give-up rule).
    _KEPT = "kept"

    # ------------------------------------------------------------ port
    def open(self) -> None:
        """Lock the trial folder, then open the port with the profile's settings (one-line error if it cannot).

        The folder is created and locked first (:class:`~designkit.calibration.trials.FolderLock`,
        held until :meth:`close`): another recorder writing into it is refused
        (:class:`~designkit.calibration.trials.FolderBusy`) before any touch. A
        path that is a regular file, a folder, or a device that is not a
        terminal (``/dev/null``) is refused as not a serial device.
        """
        locked_here = self._lock is not None and not self._lock.held
        if locked_here:
            self._lock.acquire()
        try:
            if locked_here:
                check_trial_folder(self.out_dir)   # what it holds now, under the lock
            self._open_port()
        except BaseException:
            if locked_here:   # a port that never opened records nothing: let go (a reconnect keeps the lock)
                self._lock.release()
            raise

    def _open_port(self) -> None:
        import serial

        kind = _not_a_serial_device(self.port)
        if kind:
            raise InputError(f"{self.port} is not a serial device ({kind})")
        s = self.profile.serial
        try:
            self._ser = serial.Serial(self.port, baudrate=s.baudrate, bytesize=s.bytesize, parity=s.parity,
                                      stopbits=s.stopbits, timeout=s.read_timeout_s)
        except (serial.SerialException, OSError, ValueError) as exc:
            if _is_enotty(exc):
                raise InputError(f"{self.port} is not a serial device (not a terminal)") from None
            raise InputError(f"cannot open serial port {self.port}: {error_line(exc)}") from None
        self._restart_stream()

    def close(self) -> None:
        """Close the port and let go of the trial folder."""
        self._close_port()
        if self._lock is not None:
            self._lock.release()

    def _close_port(self) -> None:
        if self._ser is not None:
            try:
                self._ser.close()
            except Exception:  # noqa: BLE001 - closing a vanished port may fail any way
                pass
            self._ser = None

    def __enter__(self) -> "SerialRecorder":
        self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def flush_input(self) -> None:
        """Drop what the device sent while nobody was looking (between materials)."""
        if self._ser is not None:
            self._ser.reset_input_buffer()
        self._restart_stream()

    def _restart_stream(self) -> None:
        self._buf = b""
        self._first_line = True
        self._last_t = None
        self._recent_bad = np.zeros(0, dtype=bool)
        self._pend = []
        self._held = None
        self._prev_row = None

    def _emit(self, event: RecordEvent) -> None:
        self.events.append(event)
        self.status.last_message = event.message
        self.on_event(event)

    # ------------------------------------------------------------ main loop
    def record(self, material: str, trials: int) -> list[Path]:
        """Record ``trials`` touches of ``material``; returns the CSV paths written.

        Raises
        ------
        NoData
            Nothing (or nothing readable) within the time limit.
        DeviceGone
            The port vanished and did not come back within ``reconnect_s``.
        TooManyBadLines
            Too many lines unreadable to keep any trial (module docstring).
        NoProgress
            Touch after touch skipped and none kept for ``give_up_s`` of stream (module docstring).
        TrialNotWritten
            The folder could not take a trial; the message says where it was kept instead.
        FolderBusy
            Another recorder holds the trial folder (raised by :meth:`open`, before any touch).
        InputError
            An empty material label, or the trial folder cannot be created.
        KeyboardInterrupt
            Passed on; everything written so far stays.
        """
        import serial

        if trials < 1:
            raise InputError(f"trials must be >= 1, got {trials}")
        check_material_label(material)   # before recording: a label no file can carry lost the touch
        if self._ser is None:
            self.open()
        cutter = self._new_cutter(material)
        st = self.status
        st.material, st.target, st.trials, st.state = material, trials, 0, cutter.state
        start_written = len(self.written)
        self._skips, self._kept_at = [], self._lines_seen
        last_data = time.monotonic()
        last_status = 0.0
        stall = self.profile.serial.stall_s
        while len(cutter.written) < trials:
            try:
                waiting = self._ser.in_waiting
                chunk = self._ser.read(waiting or 1)
            except (serial.SerialException, OSError, TypeError) as exc:
                # pyserial raises TypeError from in_waiting once the fd is gone
                self._device_lost(cutter, exc)
                last_data = time.monotonic()
                continue
            now = time.monotonic()
            if not chunk:
                silent = now - last_data
                if silent > self.no_data_timeout_s:
                    kept = self._kept(cutter)
                    what = ("never sent anything" if self._lines_seen == 0 else
                            "sent nothing readable" if not self._valid_seen else "stopped sending")
                    raise NoData(f"the device on {self.port} {what} for {silent:.1f} s (check the port, the baud "
                                 f"rate {self.profile.serial.baudrate} and that it is streaming); {kept}")
                if now - last_status > 0.2:
                    self._publish(cutter)
                    last_status = now
                continue
            if not self.profile.has_timestamp and self._lines_seen and now - last_data > stall:
                self.status.gaps += 1
                self._discontinuity(cutter, f"the stream stalled for {now - last_data:.2f} s (samples may be lost)")
            last_data = now
            self._consume(chunk, cutter)
            self._sync(cutter)
            if now - last_status > 0.2:
                self._publish(cutter)
                last_status = now
        self._publish(cutter)
        return self.written[start_written:]

    def _new_cutter(self, material: str) -> TrialCutter:
        """What the samples are fed to: a :class:`TrialCutter` writing into ``out_dir``.

        A subclass may return another object with the cutter's interface
        (``feed``, ``discontinuity``, ``state``, ``in_trial``, ``written``):
        :class:`designkit.calibration.live.LiveClassifier` decides each touch live.
        """
        self._lock.acquire()   # creates the folder: now, not when the first touch is complete (held already)
        return TrialCutter(self.profile, self.out_dir, material,
                           meta={"profile": self.profile.name, "port": self.port, "session": self.session,
                                 "timestamps": "device" if self.profile.has_timestamp else "line count"},
                           lock=self._lock)

    def _sync(self, cutter: TrialCutter) -> None:
        for p in cutter.written:
            if p not in self.written:
                self.written.append(p)

    def _kept(self, cutter: TrialCutter) -> str:
        self._sync(cutter)
        lost = " (the trial in progress was discarded)" if cutter.in_trial else ""
        return self._kept_words() + lost

    def _kept_words(self) -> str:
        """What the session kept so far, for a message that ends it (a classifier keeps decisions, not trials)."""
        n = len(self.written)
        return f"{n} trial(s) kept" + (f" in {self.out_dir}" if n else "")

    def _publish(self, cutter: TrialCutter) -> None:
        self.status.state = cutter.state
        self.status.trials = len(cutter.written)
        self.on_status(self.status)

    def _discontinuity(self, cutter: TrialCutter, reason: str) -> None:
        self._flush_held(cutter)   # the sample before the break belongs before it
        self._pend = []
        self._prev_row = None
        self._emit(RecordEvent("gap", reason))
        for e in cutter.discontinuity(reason):
            self.status.skipped += 1
            self._skips.append(e.message)
            self._emit(e)
        self._last_t = None
        self._check_progress(cutter)

    def _device_lost(self, cutter: TrialCutter, exc: BaseException) -> None:
        in_trial = cutter.in_trial
        last_t = self._last_t
        self._discontinuity(cutter, "the device disconnected")
        self._close_port()   # the folder stays locked: the session goes on
        lost_at = time.monotonic()
        deadline = lost_at + self.profile.serial.reconnect_s
        while True:
            try:
                self.open()
                self._verify = Probation.start(self._idle_t, self._idle_v, self._pre_contact, last_t,
                                               time.monotonic() - lost_at, self.profile.sample_rate_hz)
                self._emit(RecordEvent("reconnect", f"reopened {self.port}; checking that it streams this "
                                                    "session's device before recording from it"))
                return
            except InputError:
                if time.monotonic() >= deadline:
                    break
                time.sleep(0.1)
        self._sync(cutter)
        lost = "; the trial in progress was discarded" if in_trial else ""
        raise DeviceGone(f"the device on {self.port} disappeared ({error_line(exc)}) and did not come back within "
                         f"{self.profile.serial.reconnect_s:g} s; {self._kept_words()}{lost}")

    def _consume(self, chunk: bytes, cutter: TrialCutter) -> None:
        prof = self.profile
        data = self._buf + chunk
        lines = data.split(b"\n")
        self._buf = lines.pop()
        unreadable = []
        if len(self._buf) > 4096:
            self._bad("too_long", self._buf[:40].decode("ascii", "replace"))
            self._buf = b""
            self._slot += 1
            unreadable.append(np.ones(1, dtype=bool))
        if self._first_line and lines:
            lines = lines[1:]  # the port may have opened in the middle of a line
            self._first_line = False
        if not lines:
            return
        parsed = prof.parse_lines(lines)
        self._lines_seen += parsed.n_slots
        for msg in parsed.messages:
            self._emit(RecordEvent("device", f"device: {msg}"))
        for _, kind, text in parsed.errors:
            self._bad(kind, text)
        values, bad = prof.convert(parsed.raw)
        for row in np.flatnonzero(bad):
            self._bad("out_of_range", lines[parsed.rows[row]].strip()[:60].decode(prof.encoding, "replace"))
        good = ~bad
        if prof.has_timestamp:
            t = values[good, ROLES.index("timestamp")]
        else:
            t = (self._slot + parsed.slots[good]) / prof.sample_rate_hz
        self._slot += parsed.n_slots
        flags = np.ones(parsed.n_slots, dtype=bool)
        flags[parsed.slots[good]] = False
        unreadable = np.concatenate(unreadable + [flags])
        vals = values[good][:, :3]
        self.status.lines_ok += int(good.sum())
        if t.size == 0:
            if not self._valid_seen and self._lines_seen >= 200:
                example = lines[-1].strip()[:60].decode(prof.encoding, "replace")
                raise NoData(f"none of the first {self._lines_seen} lines from {self.port} matches profile "
                             f"{prof.name!r} (e.g. {example!r}): wrong profile or baud rate?")
            self._check_readable(unreadable, cutter)
            return
        self._valid_seen = True
        if self._verify is not None:
            self._verify.t.append(t)
            self._verify.v.append(vals)
            self._check_device(cutter)   # feeds what it held back once the stream shows the same device
        else:
            self._feed_checked(t, vals, cutter)  # first, so that a trial this completes is kept
        last = vals[-1]
        self.status.sensor_c, self.status.object_c, self.status.force_n = (float(x) for x in last)
        self.status.device_time_s = float(t[-1])
        self._check_readable(unreadable, cutter)

    def _check_readable(self, unreadable: np.ndarray, cutter: TrialCutter) -> None:
        """Apply the give-up rule (module docstring) to the lines just read (True: unreadable)."""
        n = self._bad_window
        self._recent_bad = np.concatenate([self._recent_bad, unreadable])[-n:]
        if self._recent_bad.size < n or not self._valid_seen:
            return  # not a full window yet; or nothing readable yet: NoData names the likely cause
        frac = float(self._recent_bad.mean())
        if frac > 1.0 - MIN_READABLE_FRACTION:
            raise TooManyBadLines(
                f"{100 * frac:.1f} % of the last {n} lines from {self.port} were unreadable (e.g. "
                f"{self._last_bad_text!r}): a trial needs {100 * MIN_READABLE_FRACTION:.0f} % of its samples "
                f"readable, so none can be kept; check the cable, the baud rate {self.profile.serial.baudrate} "
                f"and the profile {self.profile.name!r}; {self._kept(cutter)}")

    def _feed_checked(self, t: np.ndarray, vals: np.ndarray, cutter: TrialCutter) -> None:
        """Feed samples whose device times follow on; skip the lines whose times cannot be right.

        With device timestamps, a sample up to 1.5 sample periods after the
        last one kept continues the stream. Any other (the same time, an
        earlier one, a hole) is held back, and the samples after it decide,
        each going with whichever it follows more closely, the last one kept
        or the held ones: when a sample follows the last one kept, the held
        ones were bad lines (sent twice, out of order, a damaged time) and are
        skipped, the trial in progress goes on; when ``CONFIRM_SAMPLES`` held
        samples follow each other, they are the stream: after a hole of at
        most ``stall_s`` (lines lost to garbling) it simply goes on, after a
        longer one or a step back the clock really jumped (samples lost, a
        reset): a discontinuity. Counted time (no timestamp) has no holes to
        check: lost samples are found from silences instead (see :meth:`record`).
        """
        fs = self.profile.sample_rate_hz
        if not self.profile.has_timestamp:
            self._feed(t, vals, cutter)
            self._last_t = float(t[-1])
            return
        hole = max(self.profile.serial.stall_s, 1.5 / fs)
        step_max = 1.5 / fs
        last = self._last_t
        run: list[int] = []       # indices of t continuing the stream, fed in one go
        for i, ti in enumerate(t.tolist()):
            if last is None or (not self._pend and 0.0 < ti - last <= step_max):
                run.append(i)
                last = ti
                continue
            d_last = ti - last
            d_pend = ti - self._pend[-1][0] if self._pend else -1.0
            follows_last = 0.0 < d_last <= hole
            follows_pend = 0.0 < d_pend <= hole
            if follows_pend and (not follows_last or d_pend < d_last):
                self._pend.append((ti, vals[i]))
                if len(self._pend) < CONFIRM_SAMPLES:
                    continue
                confirmed, self._pend = self._pend, []
                step = confirmed[0][0] - last
                if run:                               # the samples before them go first
                    self._feed(t[run], vals[run], cutter)
                    run = []
                if not 0.0 < step <= hole:
                    if step < 0:
                        reason = (f"the device clock went back by {-step:.3f} s, from {last:.3f} s to "
                                  f"{confirmed[0][0]:.3f} s (device reset?)")
                    elif step == 0:
                        reason = f"the device clock restarted at {last:.3f} s"
                    else:
                        reason = f"{step - 1.0 / fs:.3f} s of samples missing at device time {last:.2f} s"
                    self.status.gaps += 1
                    self._discontinuity(cutter, reason)
                self._feed(np.array([c[0] for c in confirmed]), np.array([c[1] for c in confirmed]), cutter)
                last = confirmed[-1][0]
                continue
            if self._pend:                            # the held samples continue nothing: bad lines
                self._skip_times(last, ti)
            if follows_last and d_last <= step_max:
                run.append(i)
                last = ti
            else:
                self._pend = [(ti, vals[i])]
        if run:
            self._feed(t[run], vals[run], cutter)
        self._last_t = last

    def _skip_times(self, last: float, nxt: float) -> None:
        """The held samples were lines with wrong times (see :meth:`_feed_checked`): count and report them.

        ``last``: the last time kept; ``nxt``: the time that showed them wrong.
        """
        hole = max(self.profile.serial.stall_s, 1.5 / self.profile.sample_rate_hz)
        for ti, _ in self._pend:
            if ti == last:
                self._bad("duplicate", f"time {ti:.4f} s twice")
            elif last < nxt < ti <= nxt + hole:
                self._bad("out_of_order", f"time {ti:.4f} s before {nxt:.4f} s")
            elif ti < last:
                self._bad("out_of_order", f"time {ti:.4f} s after {last:.4f} s")
            else:
                self._bad("time_jump", f"time {ti:.4f} s after {last:.4f} s, the next line continuing from "
                                       f"{last:.4f} s")
        self._pend = []

    # ------------------------------------------------------- same device?
    def _out_of_contact(self, vals: np.ndarray) -> np.ndarray:
        """Rows of ``vals`` taken with nothing touching: force below release (without force: every row)."""
        f = vals[:, COL_FORCE]
        if self.profile.contact.rule != "force" or not np.isfinite(f).any():
            return np.ones(f.size, dtype=bool)
        return np.isfinite(f) & (f < self.profile.contact.release_n)

    def _remember_idle(self, t: np.ndarray, vals: np.ndarray) -> None:
        """Keep the last ``_REFERENCE_S`` of samples out of contact (the session's reference)."""
        idle = self._out_of_contact(vals)
        if not idle.any():
            return
        self._idle_seen += int(idle.sum())
        keep = int(round(_REFERENCE_S * self.profile.sample_rate_hz))
        self._idle_t = np.concatenate([self._idle_t, t[idle]])[-keep:]
        self._idle_v = np.concatenate([self._idle_v, vals[idle]])[-keep:]

    def _note_pre_contact(self, path: Path) -> None:
        """Remember a written trial's pre-contact temperatures (its sidecar) as the session's reference."""
        import json

        try:
            meta = json.loads(Path(path).with_suffix(".json").read_text())
            obj = meta.get("object_temp_before_c")
            self._pre_contact.append((float(meta["sensor_temp_before_c"]),
                                      float("nan") if obj is None else float(obj)))
        except (OSError, ValueError, KeyError, TypeError):
            pass   # the idle samples remain the reference

    def _check_device(self, cutter: TrialCutter) -> None:
        """Judge a reopened port once it showed enough samples (:mod:`~designkit.calibration.reconnect`).

        Raises
        ------
        DeviceChanged
            The stream differs from the session's device; nothing of it was fed to the cutter.
        """
        verdict = self._verify.judge(self._out_of_contact, self.profile.has_timestamp, self.profile.sample_rate_hz)
        if verdict is None:
            return                                      # not enough seen yet, or still settling
        reasons, same, t, vals = verdict
        if reasons:
            self._verify = None
            raise DeviceChanged(
                f"after reconnecting, {self.port} streams another device than this session's ("
                + "; ".join(reasons) + "): its port may now belong to another program's device, so nothing "
                f"more is recorded from it; {self._kept(cutter)}. Check what is on {self.port} and record the "
                "remaining touches in a new run")
        self._verify = None
        self._emit(RecordEvent("reconnect", f"{self.port} streams this session's device again ("
                                            + (", ".join(same) or "nothing to compare yet") + "); recording on"))
        self._feed_checked(t, vals, cutter)

    def _feed(self, t, vals, cutter: TrialCutter) -> None:
        """Pass samples through the plausibility filter (module docstring) to the cutter.

        The last sample is held back until the next one arrives: a sample is
        judged against both its neighbours.
        """
        t = np.asarray(t, dtype=np.float64)
        vals = np.asarray(vals, dtype=np.float64).reshape(-1, 3)
        if self._held is not None:
            t = np.concatenate([self._held[0], t])
            vals = np.concatenate([self._held[1], vals])
            self._held = None
        if t.size == 0:
            return
        self._held = (t[-1:], vals[-1:])
        t, vals, nxt = t[:-1], vals[:-1], vals[1:]
        if t.size == 0:
            return
        margin = self._spike_margin()
        if margin is not None and self._prev_row is not None:
            prev = np.concatenate([self._prev_row[None, :], vals[:-1]])
            with np.errstate(invalid="ignore"):
                lo = np.fmin(prev, nxt) - margin
                hi = np.fmax(prev, nxt) + margin
                odd = (vals < lo) | (vals > hi)           # NaN (no such channel) compares False
            bad = odd.any(axis=1)
            for i in np.flatnonzero(bad):
                c = int(np.flatnonzero(odd[i])[0])
                why = (f"{('sensor', 'object', 'force')[c]} {vals[i, c]:.4f} at device time {t[i]:.3f} s between "
                       f"neighbours {prev[i, c]:.4f} and {nxt[i, c]:.4f}")
                self._bad("implausible", why)
                if hasattr(cutter, "note_dropped"):
                    cutter.note_dropped(float(t[i]), f"implausible: {why}")
            if bad.any():
                t, vals = t[~bad], vals[~bad]
        if t.size:
            self._prev_row = vals[-1].copy()
            self._to_cutter(t, vals, cutter)

    def _flush_held(self, cutter: TrialCutter) -> None:
        """Feed the held-back last sample unjudged (it has no successor: the stream breaks after it)."""
        if self._held is not None:
            t, v = self._held
            self._held = None
            self._to_cutter(t, v, cutter)

    def _spike_margin(self) -> np.ndarray | None:
        """Per-channel margin of the plausibility filter [channel units]; None until enough samples out of contact.

        ``SPIKE_SIGMAS`` times the noise (the median absolute second difference
        of the samples out of contact, scaled to a standard deviation), or
        times the median non-zero step when that is larger (a quantized
        reading steadier than one step).
        """
        at, margin = self._margin
        n = self._idle_v.shape[0]
        if n < _SPIKE_MIN_REFERENCE:
            return None
        if margin is not None and self._idle_seen - at < 200:
            return margin
        ref = self._idle_v
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)   # all-NaN: a channel the rig does not have
            sigma = np.nanmedian(np.abs(np.diff(ref, 2, axis=0)), axis=0) * 1.4826 / math.sqrt(6.0)
            d1 = np.abs(np.diff(ref, axis=0))
            step = np.array([np.nanmedian(c[c > 0]) if (c > 0).any() else 0.0 for c in d1.T])
        margin = SPIKE_SIGMAS * np.fmax(sigma, step)
        margin = np.where(np.isfinite(margin) & (margin > 0), margin, np.inf)
        self._margin = (self._idle_seen, margin)
        return margin

    def _to_cutter(self, t, vals, cutter: TrialCutter) -> None:
        self._remember_idle(t, vals)
        for e in cutter.feed(t, vals):
            if e.kind == "trial" and e.path is not None:
                self._note_pre_contact(e.path)
            if e.kind in ("trial", "decision"):
                self._skips, self._kept_at = [], self._lines_seen
            if e.kind == "skipped":
                self.status.skipped += 1
                self._skips.append(e.message)
            self._emit(e)
        self._check_progress(cutter)

    def _check_progress(self, cutter: TrialCutter) -> None:
        """Apply the give-up rule for a stream that never lets a touch be kept (module docstring)."""
        if len(self._skips) < GIVE_UP_TOUCHES:
            return
        span = (self._lines_seen - self._kept_at) / self.profile.sample_rate_hz
        if span < self.give_up_s:
            return
        raise NoProgress(
            f"{len(self._skips)} touches in a row were skipped and none {self._KEPT} in the last {span:.0f} s of "
            f"stream from {self.port} (the last: {self._skips[-1]}): the stream is too damaged for a touch; check "
            f"the cable and the device; {self._kept(cutter)}")

    def _bad(self, kind: str, text: str) -> None:
        self._last_bad_text = text
        st = self.status
        st.lines_bad += 1
        st.bad_by_kind[kind] = st.bad_by_kind.get(kind, 0) + 1
        seen = self._examples.get(kind, 0)
        self._examples[kind] = seen + 1
        if seen < _EXAMPLES_PER_KIND:
            more = " (further ones are only counted)" if seen == _EXAMPLES_PER_KIND - 1 else ""
            self._emit(RecordEvent("bad_line", f"skipped a line with {_BAD_KIND_TEXT[kind]}: {text!r}{more}"))


def _not_a_serial_device(port: str) -> str:
    """What ``port`` is instead, when it is a path to something that cannot be a serial device ("" otherwise).

    Names that are not paths (``COM3``, pyserial URLs) are left to pyserial.
    """
    try:
        mode = os.stat(port).st_mode
    except (OSError, ValueError):
        return ""
    if stat.S_ISCHR(mode):
        return ""
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISREG(mode):
        return "a regular file"
    return "not a character device"


def _is_enotty(exc: BaseException | None) -> bool:
    """Whether ``exc`` or an exception it was raised from is "not a terminal" (ENOTTY).

    pyserial turns the termios error into ``SerialException("Could not
    configure port: (25, ...)")``; the original stays as its context.
    """
    try:
        import termios
    except ImportError:  # pragma: no cover - Windows
        termios = None
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno == errno.ENOTTY:
            return True
        if termios is not None and isinstance(exc, termios.error) and exc.args[:1] == (errno.ENOTTY,):
            return True
        exc = exc.__cause__ or exc.__context__
    return False
