"""The model contract: what every model module gives and the machinery all of them share.

- ``definition``: ``BushingModel`` and its parts (states, search box, coupled kernels, slow loop,
  track start), checked when a model is defined;
- ``parameter_specs``: a parameter's spec (name, unit, meaning, range), constraints and
  validation;
- ``units``: a unit's SI form and its form on a rotational axis, read from its name;
- ``search_coordinates``: the fit's coordinate kinds (map, inverse, bounds);
- ``integration``: the shared integration machinery (the Bouc-Wen block and its walk, vector
  algebra) and the step protocol, written in the kernel language;
- ``elements``: the elements the models share (free play, the softplus corner, travel limits, the
  monotone cubic, the fluid column's substeps, Berg's friction, the Maxwell element), in the
  kernel language, compiled and translated as ``integration`` is;
- ``options``: the options any model takes, one element per module (a measured backbone, travel
  limits, a Maxwell element, an Iwan element, the rig's offsets; the contract ``options.element``), and the set
  of them a model has (``Options``);
- ``derived``: a model composed with options: its parameters, name, states, switches, search
  box, the model;
- ``derived_source``: that model's kernel module, written as source (the base's kernels renamed,
  the options' parts put into the wrappers);
- ``registry``: every model of ``fmu_src.models``, by name and identifier.

May import: nothing of fmu_src but itself (``registry`` finds ``models`` by name, at import).
"""
