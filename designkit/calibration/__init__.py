"""Calibration: turn one's own sensor into a sensor file (``designkit calibrate``).

- :mod:`~designkit.calibration.profiles`: device profiles (serial settings,
  line format, channel conversions incl. thermistors, contact rule, trial window).
- :mod:`~designkit.calibration.emulator`: a simulated rig on a pseudo-terminal.
- :mod:`~designkit.calibration.recorder`: recording touches over serial.
- :mod:`~designkit.calibration.trials`: trials on disk (CSV + JSON sidecar + index).
- :mod:`~designkit.calibration.fit`: identifying e_s and alpha_s (paper appendix).

Submodules are imported on use; this package imports nothing heavy.
"""

__all__ = ["emulator", "fit", "profiles", "recorder", "trials"]
