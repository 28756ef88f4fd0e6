"""Command-line interface: a thin skin over the library (see ``designkit --help``)."""

from ._app import app, main

# Each module registers its commands on ``app``; keep imports cheap (no numpy work,
# no scikit-learn) at module level.
# Registration order is the order of ``designkit --help`` within each panel: questions first.
from . import query  # noqa: E402,F401  min-contact, max-noise, min-delta-t, delta-e, distinguishable
from . import matrix  # noqa: E402,F401  matrix (one question over N materials)
from . import thin  # noqa: E402,F401  validity
from . import materials  # noqa: E402,F401  materials list, materials show
from . import tables  # noqa: E402,F401  tables list, tables show
from . import export  # noqa: E402,F401  export
from . import calibrate  # noqa: E402,F401  calibrate (record, fit, guided run), emulate
from . import classify  # noqa: E402,F401  classify (live decisions over serial)
from . import design  # noqa: E402,F401  design (recommend a sensor)
from . import core  # noqa: E402,F401  simulate, f1
from . import sweep  # noqa: E402,F401  sweep
from . import reproduce  # noqa: E402,F401  reproduce
from . import bench  # noqa: E402,F401  bench

__all__ = ["app", "main"]
