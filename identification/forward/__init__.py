"""The forward model: a parameter set and a sampled test in, the force at every sample out.

- ``simulate``: the front door (``simulate``, ``simulate_multiaxis``);
- ``parameter_sets``: what counts as "the parameters" at the front door (a mapping, a file, a
  ``ParameterSet``, an ensemble, a fit's result);
- ``input_path``: a sampled test turned into the path the kernels are driven along;
- ``population``: every model compiled with numba, run over a whole population of parameter sets;
- ``steady_state``: the compiled sine loop of the dynamic-stiffness characterisation;
- ``dynamic_stiffness``: ``characterise``, a parameter set described the way a data sheet is;
- ``parameter_jacobian``: the forces' derivatives with respect to the search coordinates,
  computed with the forces (the fit's exact Jacobian).

May import: ``identification.measured``, ``identification.errors``, ``identification.extras`` and
``fmu_src``.
"""
