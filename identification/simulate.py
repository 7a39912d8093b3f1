"""Simulate any of the project's models on a sampled test: the identification's forward model.

``simulate(parameters, time_s, displacement_mm, velocity_mm_s=None, model="proposed")``
returns the force [N] at every sample of a parameter set of the proposed model, Spencer's,
the single Bouc-Wen or Kelvin-Voigt (``fmu_src.bushing_models``), driven by a smooth
interpolant of the sampled displacement (``identification.forward_model``): the
continuous-time model, which the fit compares with measurements. The FMU, a co-simulation
slave, sees its inputs held over each communication step instead
(``compiled_core.simulate_population_held``).

Units: time in s, displacement in mm, velocity in mm/s, force in N, parameters in the
paper's N-mm-s units. The bushing starts in relaxed equilibrium at the first displacement.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from fmu_src.bushing_models import get_model
from identification.compiled_core import parameter_matrix, simulate_population_at
from identification.forward_model import DrivenInput, prepare_input


def simulate(parameters, time_s, displacement_mm, velocity_mm_s=None, model: str | None = None,
             steps_per_sample: int | None = None) -> np.ndarray:
    """Force [N] at every sample.

    ``parameters``: a mapping of the model's parameters (paper units), or a
    ``parameter_files.ParameterSet`` (which names its model). ``model``: the model's name or
    FMI identifier (default: the one of the ParameterSet, else ``"proposed"``).
    ``velocity_mm_s``: the test's velocity at the samples, if known (else derived from the
    interpolant). ``steps_per_sample``: communication steps per sample interval (default:
    chosen from the signal, see ``forward_model``); more give a finer reference solution.
    Raises ``ParameterError`` for an invalid set, ``ValueError`` for bad arrays.
    """
    values, bushing = _parameters_and_model(parameters, model)
    driven = prepare_input(time_s, displacement_mm, velocity_mm_s, steps=steps_per_sample)
    return simulate_driven(parameter_matrix([values], bushing.name), driven, model=bushing.name)[0]


def simulate_driven(matrix: np.ndarray, driven: DrivenInput, max_substeps: int | None = None,
                    model: str = "proposed") -> np.ndarray:
    """Forces [N], shape (P, outputs), of a (P, m) matrix of ``model``'s parameters
    (``compiled_core.parameter_matrix``) on a prepared input, at its output samples
    (``driven.sample_index``). NaN from where a candidate fails."""
    kwargs = {} if max_substeps is None else {"max_substeps": max_substeps}
    return simulate_population_at(matrix, driven.time_s, driven.displacement_mm, driven.velocity_mm_s,
                                  driven.output_index, driven.output_velocity_mm_s, model=model, **kwargs)


def _parameters_and_model(parameters, model):
    if hasattr(parameters, "model") and hasattr(parameters, "parameters"):  # a ParameterSet
        bushing = get_model(model) if model is not None else parameters.model
        return bushing.check(parameters.parameters), bushing
    if not isinstance(parameters, Mapping):
        raise TypeError(f"parameters must be a mapping of names to values or a ParameterSet, "
                        f"not {type(parameters).__name__}")
    bushing = get_model(model or "proposed")
    return bushing.check(parameters), bushing
