"""Predict a test with a parameter set or an ensemble: the force, and the ensemble's band.

``predict(parameters, time_s, displacement_mm, velocity_mm_s=None, model=None)`` simulates (the forward
model, ``identification.simulate``) the best parameter set and, for an ensemble, every
member, in one compiled population call. The band is the members' envelope (min, max) at
every sample: the spread of the parameter sets the training tests cannot tell apart (a
confidence band). Add the noise level for where a measurement may fall (a prediction band).

``parameters``: anything ``identification.parameter_input`` accepts (a mapping, a
``ParameterSet`` or ``ParameterEnsemble``, a ``FitResult``, a parameter file's path, a list of
mappings, best first).
"""
from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_src.bushing_models import BushingModel
from identification.compiled_core import parameter_matrix
from identification.errors import IdentificationError
from identification.forward_model import prepare_input
from identification.parameter_input import parameter_sets
from identification.simulate import simulate_driven


@dataclass
class Prediction:
    """What ``predict`` returns.

    Attributes
    ----------
    time_s : numpy.ndarray
        Sample times [s].
    displacement_mm : numpy.ndarray
        Displacement [mm] at the samples.
    force_N : numpy.ndarray
        Force [N] of the best (first) parameter set.
    lower_N, upper_N : numpy.ndarray
        The envelope [N] of every member (equal to ``force_N`` for one set).
    members : int
        How many parameter sets were simulated.
    """
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


def predict(parameters, time_s, displacement_mm, velocity_mm_s=None,
            model: str | BushingModel | None = None) -> Prediction:
    """Predict a test: the best set's force and the ensemble's band at every sample.

    Parameters
    ----------
    parameters : mapping, ParameterSet, ParameterEnsemble, FitResult, str or Path
        A set or an ensemble (paper's N-mm-s units), in any form ``parameter_input`` accepts.
    time_s, displacement_mm : array_like
        Sample times [s] and displacement [mm].
    velocity_mm_s : array_like, optional
        Measured velocity [mm/s] at the samples.
    model : str or BushingModel, optional
        The model the parameters must be for (or its name).

    Returns
    -------
    Prediction
        ``force_N`` of the best set, ``lower_N``/``upper_N`` the members' envelope (a
        confidence band; add the noise level for where a measurement may fall).

    Raises
    ------
    IdentificationError
        The best set's simulation fails (overflow), with the time it fails from.
    """
    bushing, sets = parameter_sets(parameters, model)
    driven = prepare_input(time_s, displacement_mm, velocity_mm_s)
    forces = simulate_driven(parameter_matrix(sets, bushing), driven, model=bushing)
    failed = ~np.isfinite(forces[0])
    if failed.any():
        raise IdentificationError(f"the simulation of the best parameter set fails from t = "
                         f"{np.asarray(time_s)[np.argmax(failed)]:g} s (overflow or too many substeps): "
                         "check the units of the displacement (mm) and the amplitude")
    return Prediction(np.asarray(time_s, dtype=float), np.asarray(displacement_mm, dtype=float), forces[0],
                      np.nanmin(forces, axis=0), np.nanmax(forces, axis=0), len(sets))
