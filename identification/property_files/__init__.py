"""Other tools' bushing property files, read into the project's parameter files.

- ``chrono_json``: Project Chrono's vehicle JSON bushings as a six-axis Kelvin-Voigt set;
- ``teimorbit``: the TeimOrbit text format (blocks, values, tables) Altair's and Adams' files use;
- ``gbs``: Altair's bushing property files (``.gbs``): splines as backbones, constant stiffness
  and damping;
- ``bus``: Adams' nonlinear bushing property files (``.bus``): curves as backbones, damping;
- ``export``: a parameter file written as a ``.gbs``: each direction's static curve and an
  equivalent linear damping at an operating point.

Each reader names what it does not take in a warning (``PropertyFileWarning``) and refuses what
it cannot read with the file, the place and the value.

May import: ``identification.measured``, ``identification.forward``, ``identification.fitting``,
``identification.analysis``, the top-level modules and ``fmu_src``.
"""
from __future__ import annotations
