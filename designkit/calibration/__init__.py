"""Calibration: turn one's own sensor into a sensor file (``designkit calibrate``).

- :mod:`~designkit.calibration.profiles`: device profiles (serial settings,
  line format, channels, contact rule, trial window).
- :mod:`~designkit.calibration.conversions`: a channel's raw numbers to engineering values
  (linear, thermistors) and back.
- :mod:`~designkit.calibration.emulator`: a simulated rig on a pseudo-terminal.
- :mod:`~designkit.calibration.touch_plan`: what the emulated rig touches and when, and how it
  announces it on the wire.
- :mod:`~designkit.calibration.recorder`: recording touches over serial.
- :mod:`~designkit.calibration.trials`: trials on disk (CSV + JSON sidecar + index).
- :mod:`~designkit.calibration.identify`: the one identification engine: every sensor model (the
  paper's semi-infinite one among them), held-out splits and the choice between models.
- :mod:`~designkit.calibration.fit`: the materials' effusivity ranges, object temperatures and the
  checks that make a calibration unusable.

Submodules are imported on use; this package imports nothing heavy.
"""

__all__ = ["conversions", "emulator", "fit", "identify", "profiles", "recorder", "touch_plan", "trials"]
