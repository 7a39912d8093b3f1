"""Fitting: a model's parameters from training tests, and how sure the fit is.

- ``fit``: ``fit``, the front door: the training read and checked, a linear model fitted by least
  squares, any other searched;
- ``search``: the search, step by step (the box, the starts, the stages, the ensemble, the result);
- ``result``: ``FitResult``, what a fit returns (its summary, its parameter and ensemble files);
- ``presets``: how much of each search phase a fit runs, defined once; ``FitOptions``, a fit's
  settings as one value (the front doors' keywords);
- ``search_space``: the box of dimensionless coordinates the fit searches, scaled by the data;
- ``loop_start``, ``table_start``: starts read off the data (a slow loop; a data sheet);
- ``objectives``: the misfit, every sample of every test in its noise units;
- ``multistart``: screening and the least-squares stages;
- ``refinement``: finer steps where the fitted bushing responds sharply;
- ``ensemble``: the parameter sets the data cannot tell apart (profiles, posterior);
- ``engine``: where the fit's tasks run (this process, worker processes, a Dask cluster);
- ``progress``: progress bars of long work;
- ``fleet``: many bushings, one fit each;
- ``six_axis_assembly``: one six-axis parameter file from one fit per axis.

May import: ``identification.forward``, ``identification.measured``, the top-level modules
(``errors``, ``extras``, ``interrupt``) and ``fmu_src``.
"""
