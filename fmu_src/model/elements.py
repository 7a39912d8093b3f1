"""Elements the models share, written in the kernel language: no model's equations live here.

- ``softplus``: log(1 + exp(z)), the smooth corner every element below rounds with;
- ``dead_zone``: free play of +-gap around a centre, its corners rounded over a width (0: hard);

Like ``integration``, this module is compiled by numba once for every model that imports it
(``fmu_src/kernels/numba_binding.py``), translated into C with the kernels that call it, and
differentiated with them (``fmu_src/kernels/tangents.py``). Units are the caller's (mm, N).
"""
from __future__ import annotations

import math

SOFTPLUS_FLOOR = -37.0
"""Below it log(1 + exp(z)) < 8.6e-17, under half a unit of the last place of 1: :func:`softplus`
is 0 there, and a dead zone's far side costs no exp."""


def softplus(z):
    """log(1 + exp(z)), written so that exp never overflows (both branches are the same analytic
    function); 0 below SOFTPLUS_FLOOR."""
    if z > 0.0:
        return z + math.log(1.0 + math.exp(-z))
    if z < SOFTPLUS_FLOOR:
        return 0.0
    return math.log(1.0 + math.exp(z))


def dead_zone(e, gap, width):
    """Free play: 0 for |e| <= gap, e -+ gap beyond (``gap`` >= 0, same unit as e); with
    ``width`` > 0 the corners are rounded by a softplus over that width,
    width*(softplus((e - gap)/width) - softplus((-e - gap)/width)), odd in e and smooth; ``width``
    = 0 the hard corners."""
    if width <= 0.0:
        if e > gap:
            return e - gap
        if e < -gap:
            return e + gap
        return 0.0
    return width * (softplus((e - gap) / width) - softplus((-e - gap) / width))
