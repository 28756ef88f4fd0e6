"""Sensor design: which sensor to build for the materials a robot must tell apart.

:mod:`~designkit.design.search` searches thermistor depth (tau), skin material (sensor
effusivity), sampling rate and set-point temperature difference with the ideal observer's
closed form (:mod:`designkit.query.ideal_bound`) and confirms the recommendation with the
paper's SVM. Import from the module.
"""

__all__: list[str] = []
