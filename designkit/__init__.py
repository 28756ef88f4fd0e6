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

# The one place the version is written: pyproject.toml reads it from here (setuptools
# dynamic metadata), the CLI prints it (designkit --version), CHANGELOG.md names it.
__version__ = "0.1.0"

_LAZY = {
    "InputError": "._validation",
    "Scene": ".scene",
    "SENSORS": ".sensor",
    "Sensor": ".sensor",
    "load_sensor": ".sensor",
}


def __getattr__(name: str):
    # PEP 562: the command line imports ``designkit.cli`` without paying for numpy
    # work it does not need; ``designkit.Scene`` etc. load on first use.
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module 'designkit' has no attribute {name!r}")

__all__ = ["InputError", "SENSORS", "Scene", "Sensor", "__version__", "load_sensor"]
