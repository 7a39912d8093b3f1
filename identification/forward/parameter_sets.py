"""One reading of "the parameters" for the front door: ``simulate``, ``predict`` and
``characterise`` accept the same things alike.

Accepted: a mapping of one set (names to values in the paper's N-mm-s units), a
``ParameterSet``, a ``ParameterEnsemble``, a ``FitResult`` (its ensemble, the best fit first),
a path of a parameter or ensemble file (.json or .ssv, as ``read_ensemble`` reads it), or a
list of mappings (best first).
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

from fmu_src.model.registry import BushingModel, DEFAULT_BUSHING, resolve_model
from fmu_src.parameter_files import ParameterEnsemble, ParameterSet, read_ensemble
from identification.errors import IdentificationError


class FittedParameters:
    """What a fit returns, as the front door reads it: ``parameters``, the best fit (a
    ``ParameterSet``), and ``ensemble``, the sets best first. ``identification.fitting.result.
    FitResult`` derives from it, so that this layer recognises a fit without naming the fitting
    layer above it."""
    parameters: ParameterSet
    ensemble: list[dict[str, float]]


def parameter_sets(parameters, model: str | BushingModel | None = None) -> tuple[BushingModel, list[dict[str, float]]]:
    """The model and the validated parameter sets (best first) of any accepted ``parameters``.

    ``model``: a ``BushingModel``, or the model's name or FMI identifier (resolved here, once);
    for a mapping or a list of mappings it says which model they are for (default
    ``"proposed"``), for the others it is checked against the model they name. Raises
    ``ParameterError`` for an invalid set, ``IdentificationError`` for a model that differs,
    ``TypeError`` for anything else.
    """
    expected = resolve_model(model) if model is not None else None
    if isinstance(parameters, FittedParameters):
        bushing, sets = parameters.parameters.model, parameters.ensemble          # a FitResult
    elif isinstance(parameters, (str, Path)):
        ensemble = read_ensemble(parameters)
        bushing, sets = ensemble.model, ensemble.members
    elif isinstance(parameters, ParameterEnsemble):
        bushing, sets = parameters.model, parameters.members
    elif isinstance(parameters, ParameterSet):
        bushing, sets = parameters.model, [parameters.parameters]
    elif isinstance(parameters, Mapping):
        bushing, sets = expected, [parameters]
    else:
        sets = list(parameters) if isinstance(parameters, (list, tuple)) else []
        if not sets or not all(isinstance(s, Mapping) for s in sets):
            raise TypeError(f"parameters: give a mapping of names to values, a ParameterSet, a ParameterEnsemble, "
                            f"a FitResult, a parameter file's path or a list of mappings, not "
                            f"{type(parameters).__name__}")
        bushing = expected
    if bushing is None:         # bare values: the default model's
        bushing = DEFAULT_BUSHING
    if expected is not None and expected is not bushing:
        raise IdentificationError(f"the parameters are for the {bushing.name} model, not "
                                  f"{model if isinstance(model, str) else expected.name}")
    return bushing, [bushing.check(s) for s in sets]
