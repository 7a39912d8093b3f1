"""What an FMU is built from: a model (a name of ``fmu_src/model/registry.py``, or ``six_axis``:
six axes, each one of the models, see ``axes.py``) and a parameter set, project JSON or SSP 1.0
``.ssv`` in the paper's N-mm-s units, read into what both FMU builders take: the FMU's identifier,
its axes and the defaults document with its coupled groups.

A model's default set is its file in the checkout's ``data/`` (the paper's Table 5 for the
proposed model, the baselines' fits to the synthetic Table 5 tests, illustrative sets for the
others), or the same file in the installed package ``bushing_data``.
"""
from __future__ import annotations

import importlib.resources
from pathlib import Path

from ..model.parameter_specs import ParameterError
from ..model.registry import DEFAULT_MODEL, get_model
from ..parameter_files import parameter_document, read_parameter_set, read_six_axis, six_axis_document
from .axes import ONE_AXIS, SIX_AXIS_IDENTIFIER, SIX_AXIS_NAMES, Coupling

CHECKOUT_DATA = Path(__file__).resolve().parents[2] / "data"
SIX_AXIS = "six_axis"
SIX_AXIS_DEFAULT_FILE = "params_six_axis_illustrative.json"


class BuildError(RuntimeError):
    """An FMU that cannot be built as asked (a missing default set, an FMU that fails validation)."""


def check_valid(fmu: Path) -> Path:
    """``fmu`` if fmpy's validation finds no problem in it, else BuildError naming each problem."""
    from fmpy.validation import validate_fmu
    problems = validate_fmu(str(fmu))
    if problems:
        raise BuildError(f"{fmu} fails validation:\n  " + "\n  ".join(problems))
    return fmu


def is_six_axis(model: str) -> bool:
    """Whether ``model`` names the six-axis FMU (by its name or its identifier)."""
    return model in (SIX_AXIS, SIX_AXIS_IDENTIFIER)


def identifier_of(model: str) -> str:
    """The FMU's modelIdentifier: ``BoucWenBushing`` for ``proposed``, ``SixAxisBushing`` ..."""
    return SIX_AXIS_IDENTIFIER if is_six_axis(model) else get_model(model).identifier


def default_parameter_file(model: str = DEFAULT_MODEL) -> Path:
    """The parameter set an FMU of ``model`` gets when no other is given: in the checkout's
    data/, or in the installed package ``bushing_data`` (the same files)."""
    name = SIX_AXIS_DEFAULT_FILE if is_six_axis(model) else get_model(model).default_file
    checkout = CHECKOUT_DATA / name
    if checkout.is_file():
        return checkout
    try:
        return Path(str(importlib.resources.files("bushing_data") / name))
    except ModuleNotFoundError:
        raise BuildError(f"the default parameter set {name} is neither in {CHECKOUT_DATA} nor installed "
                         "(package bushing_data); reinstall the project or give --params FILE") from None


def model_of_file(params_file: str | Path) -> str:
    """The model a parameter file is for: the one it names (a one-axis set) or ``six_axis``."""
    try:
        return read_parameter_set(params_file).model.name
    except ParameterError as one_axis_error:
        try:
            read_six_axis(params_file)
        except ParameterError:
            raise one_axis_error from None
        return SIX_AXIS


def fmu_axes(params_file: str | Path | None = None, model: str = DEFAULT_MODEL):
    """(identifier, title, axes [(axes.Axis, model on it, parameters)], the defaults document) of
    the FMU of ``model`` with the parameter set in ``params_file`` (default:
    :func:`default_parameter_file`)."""
    name = SIX_AXIS if is_six_axis(model) else get_model(model).name
    params_file = Path(params_file) if params_file is not None else default_parameter_file(name)
    source = {"source": f"build_fmu.py --model {name} --params {params_file.name}"}
    if name == SIX_AXIS:
        six_axes = read_six_axis(params_file)
        document = six_axis_document({axis: (one.model.identifier, one.parameters)
                                      for axis, one in six_axes.axes.items()}, source, six_axes.coupling)
        return SIX_AXIS_IDENTIFIER, "six-axis bushing", six_axes.fmu_axes(), document
    bushing = get_model(name)
    parameters = read_parameter_set(params_file, name).parameters
    return (bushing.identifier, f"{bushing.title} model", [(ONE_AXIS, bushing, parameters)],
            parameter_document(parameters, name, source))


def groups_of(document: dict) -> tuple[tuple[int, ...], ...]:
    """The coupled groups of a defaults document (positions of the six axes; none for one axis)."""
    return tuple(tuple(SIX_AXIS_NAMES.index(name) for name in group)
                 for group in Coupling.of(document.get("coupling")).groups)
