"""Command-line interface: a thin skin over the library (see ``designkit --help``)."""

import os

#: The BLAS thread variables a user can set; where none is set, the command-line application runs its
#: BLAS on one thread per process. Its matrices are small (a 133 x 133 Gram matrix per SVM fold, the
#: identification's Jacobians): extra threads cost more than they save (the sweep's chunks and the
#: identification already limit BLAS to one thread for that reason, and parallelism comes from
#: worker processes). It also makes the start-up cheaper: OpenBLAS starts its thread pool when numpy is
#: imported, 50 ms of a 150 ms ``import numpy`` on a 2-core machine (benchmarks/bench_startup.py).
#: Set in the application's entry only (before numpy is imported), never by ``import designkit``.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
if not any(v in os.environ for v in BLAS_THREAD_VARIABLES):
    os.environ["OPENBLAS_NUM_THREADS"] = "1"

from ._app import app, main  # noqa: E402

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
