"""The FMUs' face: what a co-simulation or model-exchange master sees.

- ``axes``: the ports and units of the one- and six-axis FMUs, their coupled groups;
- ``variables``: the FMU's variables, declared once;
- ``dependencies``: each output's dependencies, from the activity analysis of the kernels;
- ``model_description``: modelDescription.xml, one writer for both FMUs (FMI 2 and 3);
- ``pythonfmu_slave``: the pythonfmu adapter and its error policy;
- ``native``: the native FMU (``generate``: the C generated from the kernels; ``build``; ``c/``: the
  hand-written FMI layer).

May import: ``..model`` and ``..kernels`` (and the project's version); ``parameter_files`` imports it.
"""
