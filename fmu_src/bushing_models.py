"""The registry of bushing models: one line per model module (``model_definition`` says what a
model module gives).

- ``proposed``: the paper's model, eqs. 1-5, 16 parameters (``proposed_model``);
- ``spencer``: Spencer et al. (1997), Fig. 7 of the paper (``spencer_model``);
- ``single_bouc_wen``: the classic single Bouc-Wen element, Fig. 6 of the paper (``single_bouc_wen_model``;
  ``bouc_wen``, its earlier name, is accepted as an alias in files and on the command line);
- ``kelvin_voigt``: the linear bushing of ADAMS/RecurDyn, one axis (``kelvin_voigt_model``).
"""
from __future__ import annotations

from . import kelvin_voigt_model, proposed_model, single_bouc_wen_model, spencer_model
from .bushing_params import ParameterError
from .model_definition import BushingModel

MODELS: dict[str, BushingModel] = {
    module.MODEL.name: module.MODEL
    for module in (proposed_model, spencer_model, single_bouc_wen_model, kelvin_voigt_model)
}
MODEL_NAMES = tuple(MODELS)
ALIASES = {"bouc_wen": "single_bouc_wen"}
"""Older names still accepted: ``bouc_wen`` read as the proposed model's block, so it was renamed."""
MODEL_CHOICES = MODEL_NAMES + tuple(ALIASES)
"""Every name a user may give (the command line's choices)."""


def get_model(name: str) -> BushingModel:
    """The model called ``name`` (command-line name or FMI identifier)."""
    name = ALIASES.get(name, name)
    if name in MODELS:
        return MODELS[name]
    for model in MODELS.values():
        if model.identifier == name:
            return model
    raise ParameterError(f"unknown model {name!r}; choose one of {', '.join(MODEL_NAMES)} "
                         f"(identifiers {', '.join(m.identifier for m in MODELS.values())})")
