"""Predict a test with a parameter set or an ensemble: the force, and the ensemble's band.

``predict(parameters, time_s, displacement_mm, velocity_mm_s=None)`` simulates (the forward
model, ``identification.simulate``) the best parameter set and, for an ensemble, every
member, in one compiled population call. The band is the members' envelope (min, max) at
every sample: the spread of the parameter sets the training tests cannot tell apart (a
confidence band). Add the noise level for where a measurement may fall (a prediction band).

``parameters``: a ``parameter_files.ParameterEnsemble`` or ``ParameterSet``, a fit's
``FitResult``, a mapping of one set, or a list of mappings (best first).
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from fmu_src.bushing_models import BushingModel, get_model
from fmu_src.parameter_files import ParameterEnsemble, ParameterSet
from identification.compiled_core import parameter_matrix
from identification.errors import IdentificationError
from identification.forward_model import prepare_input
from identification.simulate import simulate_driven


@dataclass
class Prediction:
    time_s: np.ndarray
    displacement_mm: np.ndarray
    force_N: np.ndarray              # the best (first) member
    lower_N: np.ndarray              # the envelope of every member (equal to force_N for one set)
    upper_N: np.ndarray
    members: int

    @property
    def band_width_N(self) -> np.ndarray:
        return self.upper_N - self.lower_N

    def write_csv(self, path: str | Path) -> Path:
        """``time_s,displacement_mm,force_N`` and, for an ensemble, ``force_min_N,force_max_N``."""
        path = Path(path)
        columns = [self.time_s, self.displacement_mm, self.force_N]
        header = ["time_s", "displacement_mm", "force_N"]
        if self.members > 1:
            columns += [self.lower_N, self.upper_N]
            header += ["force_min_N", "force_max_N"]
        with open(path, "w", newline="", encoding="utf-8") as stream:
            stream.write(f"# predicted by identification.predict from {self.members} parameter set(s)\n")
            writer = csv.writer(stream)
            writer.writerow(header)
            for row in zip(*columns):
                writer.writerow([f"{row[0]:.6f}", f"{row[1]:.6f}", *(f"{value:.4f}" for value in row[2:])])
        return path


def members_of(parameters, model: str | None = None) -> tuple[BushingModel, list[dict[str, float]]]:
    """The model and the validated parameter sets (best first) of any accepted ``parameters``."""
    if hasattr(parameters, "ensemble") and hasattr(parameters, "parameters") and hasattr(parameters, "misfit"):
        bushing = parameters.parameters.model          # a FitResult
        sets = parameters.ensemble
    elif isinstance(parameters, ParameterEnsemble):
        bushing, sets = parameters.model, parameters.members
    elif isinstance(parameters, ParameterSet):
        bushing, sets = parameters.model, [parameters.parameters]
    elif isinstance(parameters, Mapping):
        bushing, sets = get_model(model or "proposed"), [parameters]
    else:
        sets = list(parameters)
        if not sets or not all(isinstance(s, Mapping) for s in sets):
            raise TypeError("parameters must be a parameter set, an ensemble, a fit result or a list of mappings")
        bushing = get_model(model or "proposed")
    if model is not None and get_model(model) is not bushing:
        raise IdentificationError(f"the parameters are for the {bushing.name} model, not {model}")
    return bushing, [bushing.check(s) for s in sets]


def predict(parameters, time_s, displacement_mm, velocity_mm_s=None, model: str | None = None) -> Prediction:
    """Force [N] of the best set and the ensemble's envelope at every sample (see the module
    docstring). Units: s, mm, mm/s, N."""
    bushing, sets = members_of(parameters, model)
    driven = prepare_input(time_s, displacement_mm, velocity_mm_s)
    forces = simulate_driven(parameter_matrix(sets, bushing.name), driven, model=bushing.name)
    failed = ~np.isfinite(forces[0])
    if failed.any():
        raise IdentificationError(f"the simulation of the best parameter set fails from t = "
                         f"{np.asarray(time_s)[np.argmax(failed)]:g} s (overflow or too many substeps): "
                         "check the units of the displacement (mm) and the amplitude")
    return Prediction(np.asarray(time_s, dtype=float), np.asarray(displacement_mm, dtype=float), forces[0],
                      np.nanmin(forces, axis=0), np.nanmax(forces, axis=0), len(sets))
