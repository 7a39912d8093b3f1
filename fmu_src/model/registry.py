"""The registry of bushing models: every module of the ``models`` package whose name ends in
``_model`` and that defines ``MODEL`` (``definition`` says what a model module gives). Adding a
model is adding such a module; this registry, the FMUs, parameter files, the fit and
``compare`` find it here. Listed in the order of ``BushingModel.rank``:

- ``proposed``: the paper's model, eqs. 1-5, 16 parameters (``proposed_model``);
- ``spencer``: Spencer et al. (1997), Fig. 7 of the paper (``spencer_model``);
- ``single_bouc_wen``: the classic single Bouc-Wen element, Fig. 6 of the paper (``single_bouc_wen_model``;
  ``bouc_wen`` is accepted as an alias in files and on the command line);
- ``asymmetric_bouc_wen``: a Bouc-Wen element whose yield differs by direction, with free play
  and breakaway (``asymmetric_bouc_wen_model``);
- ``berg``: Berg (1998), a progressive spring, Berg's rate-independent friction and two Maxwell
  elements, for filled rubber (``berg_model``);
- ``fractional``: the same spring and friction with a fractional-derivative element b*D^alpha x
  (Sjoberg and Kari 2002), realised by 20 Maxwell elements and a dashpot (``fractional_model``);
- ``kelvin_voigt``: the linear bushing of ADAMS/RecurDyn, one axis (``kelvin_voigt_model``).
"""
from __future__ import annotations

import copyreg
import importlib
import pickle
import pkgutil

from .parameter_specs import ParameterError
from .definition import BushingModel
from .derived import derive, split_name

MODEL_MODULE_SUFFIX = "_model"
MODELS_PACKAGE = "models"
"""The package beside this one that holds the model modules."""


def _discover() -> dict[str, BushingModel]:
    """{name: model} of the models package's modules, in rank order (the packed copy inside a
    pythonfmu FMU finds its own the same way)."""
    models = f"{__package__.rpartition('.')[0]}.{MODELS_PACKAGE}"
    package = importlib.import_module(models)
    found = []
    for module in pkgutil.iter_modules(package.__path__):
        if module.name.endswith(MODEL_MODULE_SUFFIX):
            model = getattr(importlib.import_module(f"{models}.{module.name}"), "MODEL", None)
            if isinstance(model, BushingModel):
                found.append(model)
    names = [model.name for model in found]
    if len(set(names)) != len(names):
        raise RuntimeError(f"two model modules define the same model name: {sorted(names)}")
    return {model.name: model for model in sorted(found, key=lambda model: (model.rank, model.name))}


MODELS: dict[str, BushingModel] = _discover()
MODEL_NAMES = tuple(MODELS)
ALIASES = {"bouc_wen": "single_bouc_wen"}
"""Older names still accepted: ``bouc_wen`` read as the proposed model's block, so it was renamed."""
MODEL_CHOICES = MODEL_NAMES + tuple(ALIASES)
"""Every name a user may give (the command line's choices)."""
DEFAULT_MODEL = "proposed"
"""The model a command, a file or a call that names none is for: the paper's."""
LINEAR_BASELINE = MODELS["kelvin_voigt"]
"""The linear bushing the paper's figures and the reports compare against (a least-squares fit
of F = k*x + c*v), and the rigid spring ``assemble --rigid-missing`` puts on a missing axis."""


def get_model(name: str) -> BushingModel:
    """The model called ``name`` (command-line name or FMI identifier), or a registered model
    with options (``proposed+limits``, ``BoucWenBushing_Limits``: ``derived``), made on demand."""
    if isinstance(name, BushingModel):
        return name
    name = ALIASES.get(name, name)
    if name in MODELS:
        return MODELS[name]
    for model in MODELS.values():
        if model.identifier == name:
            return model
    base, options = split_name(name)
    if options and base != name:
        return derive(get_model(base), options)
    raise ParameterError(f"unknown model {name!r}; choose one of {', '.join(MODEL_NAMES)} "
                         f"(identifiers {', '.join(m.identifier for m in MODELS.values())})")


def resolve_model(model: str | BushingModel) -> BushingModel:
    """``model`` itself if it is a ``BushingModel``, else the model of that name (:func:`get_model`):
    what a front door that takes either resolves once, to pass the model on."""
    return model if isinstance(model, BushingModel) else get_model(model)


DEFAULT_BUSHING = MODELS[DEFAULT_MODEL]
"""The model of ``DEFAULT_MODEL``: the default of the functions that take a model, not a name."""


def required_model(model: BushingModel) -> BushingModel:
    """``model``, which must be a ``BushingModel``: the inner functions take the model their front
    door resolved (:func:`resolve_model`, once), never a name to resolve again."""
    if not isinstance(model, BushingModel):
        raise TypeError(f"model = {model!r}: give the model (fmu_src.model.registry.get_model({model!r})), "
                        "not its name")
    return model


def _by_name(model: BushingModel):
    """A model pickles as its name, and the process that loads it finds it again by that name
    (:func:`get_model`, which derives a model with options from its name): its kernels are
    functions made at import or generated on demand, which do not pickle. A model that is not the
    one its name finds (``dataclasses.replace`` of a registered one) refuses to pickle rather than
    arrive as another."""
    if get_model(model.name) is not model:
        raise pickle.PicklingError(f"the model {model.name!r} here is not the registered model of that name "
                                   "(made by dataclasses.replace?): it cannot be sent by name")
    return get_model, (model.name,)


copyreg.pickle(BushingModel, _by_name)
