"""Calibration: turn one's own sensor into a sensor file (``designkit calibrate``).

- :mod:`~designkit.calibration.profiles`: device profiles (serial settings,
  line format, channels, contact rule, trial window).
- :mod:`~designkit.calibration.conversions`: a channel's raw numbers to engineering values
  (linear, thermistors) and back.
- :mod:`~designkit.calibration.touch_plan`: what an emulated rig (``designkit emulate``, the lab's
  :mod:`designkit_lab.emulator`) touches and when, and how it announces it on the wire.
- :mod:`~designkit.calibration.recorder`: recording touches over serial; :mod:`~designkit.calibration.cutter`
  cuts the stream into trials, :mod:`~designkit.calibration.reconnect` checks a reopened port.
- :mod:`~designkit.calibration.trials`: trials on disk (CSV + JSON sidecar + index).
- :mod:`~designkit.calibration.identify`: the one identification engine: every sensor model (the
  paper's semi-infinite one among them); :mod:`~designkit.calibration.candidates` the models it
  fits, :mod:`~designkit.calibration.results` what it finds, :mod:`~designkit.calibration.robust`
  the cluster-robust covariance, :mod:`~designkit.calibration.force` a touch's force and contact area.
- :mod:`~designkit.calibration.split` held-out touches; :mod:`~designkit.calibration.compare` the
  choice between models on them.
- :mod:`~designkit.calibration.fit`: the materials' effusivity ranges, object temperatures and the
  checks that make a calibration unusable.

Submodules are imported on use; this package imports nothing heavy.
"""

__all__ = ["candidates", "compare", "conversions", "cutter", "fit", "force", "identify", "profiles", "reconnect",
           "recorder", "results", "robust", "split", "touch_plan", "trials"]
