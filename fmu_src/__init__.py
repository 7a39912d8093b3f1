"""The bushing models and their FMI face (see README.md).

The subpackages, each only importing those listed before it (but ``model.registry``, which finds
the modules of ``models`` by name):

- ``model``: the model contract (``definition``: what a model module gives; ``parameter_specs``:
  parameter specs, constraints and units; ``search_coordinates``: the fit's coordinate kinds;
  ``integration``: the shared integration machinery and the step protocol; ``registry``: every
  model, found in ``models``);
- ``models``: one module per model, its parameters, states, equations and search box, no FMI;
- ``kernels``: the kernel language and what reads it (the C translation, the tangent generator
  and its lanes, unrolling, the numba binding);
- ``fmi``: the FMUs' face (ports and axes, variables, the pythonfmu slave, the output
  dependencies, ``native``: the native FMU's generator and its C layer).

Beside them, ``parameter_files``: the JSON and SSV parameter files and ensembles users hand to
the FMUs; ``syntax_trees``: source parsed one thread at a time (every subpackage may import it).

``__version__`` is the project's version, in one place: pyproject.toml reads it, both command
line tools print it (``--version``) and every FMU carries it in its modelDescription.
"""
__version__ = "0.2.0"
