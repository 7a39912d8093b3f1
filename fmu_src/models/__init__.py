"""The models, one module each (``<name>_model.py``): parameters in the paper's N-mm-s units,
states, equations as kernels, search box. No FMI, no fitting.

- ``proposed_model``: the paper's model, eqs. 1-5, 16 parameters;
- ``spencer_model``, ``single_bouc_wen_model``: the paper's baselines;
- ``asymmetric_bouc_wen_model``: a Bouc-Wen element whose yield differs by direction, with free
  play and breakaway (friction devices, asymmetric hysteresis);
- ``berg_model``, ``fractional_model``: filled rubber;
- ``hydraulic_model``: a hydraulic bushing or mount with a membrane decoupler;
- ``hydraulic_free_decoupler_model``: a hydraulic mount whose decoupler is a free plate in a cage;
- ``kelvin_voigt_model``: the linear bushing of the multibody tools.

May import: ``..model`` (the contract and the shared machinery) and one another, in the forms
``kernels.numba_binding`` allows; ``model.registry`` finds every module here.
"""
