"""designkit: design guidelines for active thermal tactile sensors.

Which contact time, noise level and sensor-object temperature difference does
a heated thermal sensor need to tell two materials apart? designkit answers
from the semi-infinite heat-transfer model and the SVM recognition protocol of
Bai et al. (sensor physics -> simulated touches -> recognition -> sweeps ->
lookup tables -> queries), with the ideal observer as the bound no classifier
can beat.

The top-level namespace is kept light (no scikit-learn, no scipy.optimize):
``import designkit`` gives the model's nouns; the heavier layers are imported
from their modules (``designkit.recognition``, ``designkit.query`` ...).
"""

from ._validation import InputError
from .scene import Scene
from .sensor import SENSORS, Sensor, load_sensor

__version__ = "0.1.0"

__all__ = ["InputError", "SENSORS", "Scene", "Sensor", "__version__", "load_sensor"]
