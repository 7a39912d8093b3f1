"""numba where it is installed, else a stand-in that runs the same kernels as plain Python.

The identification's forward model (``identification.simulate``, ``predict``) compiles the
models' kernels with numba, which the ``fit`` extra installs. The base install has no numba:
there ``numba.njit`` leaves a function as it is and ``numba.prange`` is ``range``, so the same
source runs, interpreted (some 100 times slower, fine for simulating a test or two; a fit
needs the extra). Plain Python raises where numba's ``error_model="numpy"`` gives inf or NaN
(a division by zero, an overflow): the simulation of a failing parameter set stops with an
exception instead of returning NaN forces.
"""
from __future__ import annotations

import types

try:
    import numba
    AVAILABLE = True
except ImportError:   # the base install (no "fit" extra)
    AVAILABLE = False

    def _njit(*args, **options):
        if len(args) == 1 and callable(args[0]) and not options:
            return args[0]
        return lambda function: function

    numba = types.SimpleNamespace(njit=_njit, prange=range, set_num_threads=lambda count: None)

MISSING = ("numba is not installed: the models run as plain Python, some 100 times slower "
           "(pip install 'boucwen-bushing[fit]' compiles them)")
"""What to tell a user who simulates without numba."""
