"""What a fitted (or typed-in) parameter set is used for once it exists.

- ``predict``: a test's force with the best set and the ensemble's band;
- ``fmu_input``: a measurement as an FMU's input table, and the FMU run on it;
- ``design``: which test to run next (where the ensemble disagrees most);
- ``parameter_sensitivity``: the force's sensitivity to each parameter (the paper's §4);
- ``compare``: every model fitted on the same tests, weighed, one recommended;
- ``race``: compare's race: every model screened, the stages only for those that can still win;
- ``first_contact``: what compare assumes of a new device's tests before the fits (the rig's
  offsets, a backbone, a Maxwell element, travel limits), and why;
- ``paper_verification``: the paper's §5 error tables and force plots;
- ``plots``: the figures (forces, loops, the multistart waterfall, data sheets).

May import: ``identification.fitting``, ``identification.forward``, ``identification.measured``,
the top-level modules and ``fmu_src``.
"""
