"""The FMUs' face: what a co-simulation or model-exchange master sees.

- ``axes``: the ports and units of the one- and six-axis FMUs, their coupled groups;
- ``variables``: the FMU's variables, declared once;
- ``dependencies``: each output's dependencies, from the activity analysis of the kernels;
- ``model_description``: modelDescription.xml, one writer for both FMUs (FMI 2 and 3);
- ``runtime_messages``: the runtime policy's words, every message both FMUs log, defined once
  (the C's ``bushing_messages.h`` is generated from it);
- ``pythonfmu_slave``: the pythonfmu adapter;
- ``fmu_inputs``: a model and a parameter file read into what the builders take;
- ``pythonfmu_package``: the pythonfmu FMU (the slave and ``fmu_src`` packed by pythonfmu);
- ``release``: the release bundle (its README from ``release_readme.txt``);
- ``native``: the native FMU (``generate``: the C generated from the kernels; ``messages_header``:
  the messages' C header; ``build``;
  ``platforms``: its platforms and their toolchains; ``macho``: the universal macOS library;
  ``c/``: the hand-written FMI layer).

May import: ``..model`` and ``..kernels`` (and the project's version); ``parameter_files`` imports
its ``axes``, and the builders (``fmu_inputs``, ``pythonfmu_package``, ``release``, ``native.build``)
read parameter files.
"""
