"""Sensor design: which sensor to build for the materials a robot must tell apart.

:mod:`~designkit.design.search` searches thermistor depth (tau), skin material (sensor
effusivity), sampling rate and set-point temperature difference with the ideal observer's
closed form (:mod:`designkit.query.ideal_bound`) and confirms the recommendation with the
paper's SVM. :mod:`~designkit.design.contact` holds a rig's contact (a calibrated sensor file's
contact conductance, contact area ramp, thermistor lag, noise and onset, or values given) under which
the same search varies the skin's thickness, the thermistor's own time constant and the press too,
screened through the rig's noise; the SVM then states the recommendation's contact with its interval
and confirms it. Import from the modules.
"""

__all__: list[str] = []
