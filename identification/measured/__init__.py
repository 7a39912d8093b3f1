"""Measured data: what a rig gives and how it is read, before any model is involved.

- ``measurements``: one-axis tests in CSV files (time, displacement, force; read and written);
- ``rig_tests``: which measurement is which kind of test (sine, step, random), and the manifest;
- ``multiaxis``: tests along two or three axes at once (their CSV files, the couplings a test
  can be run with, the force-vector error);
- ``kdyn_table``: the dynamic-stiffness and loss-angle table a supplier gives (its CSV file);
- ``noise``: each test's force-noise level, from the data alone;
- ``static_curve``: a quasi-static test's backbone (the mean of its loading and unloading branches);
- ``repeatability``: what a sine test's device repeats from cycle to cycle (the floor beside the noise);
- ``offsets``: the zeros a record shows before any fit (its stroke's centre, its force at rest,
  its cycles' mean force, whether it is quasi-static);
- ``signals``: the paper's test signals (sine, step, random) as sampled displacement and velocity.

May import: ``identification.errors`` and ``fmu_src`` (a model's names and units); nothing else
of ``identification``.
"""
