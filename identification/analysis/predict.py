"""Predict a test with a parameter set or an ensemble: the force, and the ensemble's band.

``predict(parameters, time_s, displacement_mm, velocity_mm_s=None, model=None)`` simulates (the forward
model, ``identification.simulate``) the best parameter set and, for an ensemble, every
member, in one compiled population call, each with its mounting (offset, preload);
``predict_multiaxis`` does the same on a multi-axis path with a coupling. The band is the members' envelope (min, max) at
every sample: the spread of the parameter sets the training tests cannot tell apart (a
confidence band). Add the noise level for where a measurement may fall (a prediction band).

``parameters``: anything ``identification.forward.parameter_sets`` accepts (a mapping, a
``ParameterSet`` or ``ParameterEnsemble``, a ``FitResult``, a parameter file's path, a list of
mappings, best first).
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fmu_src.model.registry import BushingModel
from identification.forward.population import parameter_matrix
from identification.errors import IdentificationError
from identification.forward.input_path import prepare_input
from identification.forward.parameter_sets import parameter_sets
from identification.forward.simulate import model_rest_force, simulate_driven, temperature_conditions
from identification.forward.population import conditioned_set


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
    misfit_N: float = math.nan       # the fit's rms residual over its training tests (NaN: not known)

    @property
    def band_width_N(self) -> np.ndarray:
        return self.upper_N - self.lower_N

    @property
    def likely_lower_N(self) -> np.ndarray:
        """Where a measurement likely falls, as far as the fit's own records say: the members'
        envelope widened by ``MISFIT_WIDENING`` times the fit's training misfit (the envelope where
        that is not known). The envelope alone is the parameters' uncertainty; the misfit is what
        the model misses even at its best, which on a device it does not describe dominates."""
        return self.lower_N - self._likely_margin_N

    @property
    def likely_upper_N(self) -> np.ndarray:
        """The upper side of :attr:`likely_lower_N`'s band."""
        return self.upper_N + self._likely_margin_N

    @property
    def _likely_margin_N(self) -> float:
        return MISFIT_WIDENING * self.misfit_N if self.misfit_N == self.misfit_N else 0.0

    def write_csv(self, path: str | Path) -> Path:
        """``time_s,displacement_mm,force_N`` and, for an ensemble, ``force_min_N,force_max_N``;
        where the fit's training misfit is known, ``likely_min_N,likely_max_N``."""
        path = Path(path)
        columns = [self.time_s, self.displacement_mm, self.force_N]
        header = ["time_s", "displacement_mm", "force_N"]
        if self.members > 1:
            columns += [self.lower_N, self.upper_N]
            header += ["force_min_N", "force_max_N"]
        if self.misfit_N == self.misfit_N:
            columns += [self.likely_lower_N, self.likely_upper_N]
            header += ["likely_min_N", "likely_max_N"]
        with open(path, "w", newline="", encoding="utf-8") as stream:
            stream.write(f"# predicted by identification.predict from {self.members} parameter set(s)\n")
            writer = csv.writer(stream)
            writer.writerow(header)
            for row in zip(*columns):
                writer.writerow([f"{row[0]:.6f}", f"{row[1]:.6f}", *(f"{value:.4f}" for value in row[2:])])
        return path


def predict(parameters, time_s, displacement_mm, velocity_mm_s=None,
            model: str | BushingModel | None = None, rest_force_N: float = math.nan,
            temperature_K: float = math.nan) -> Prediction:
    """Predict a test: the best set's force and the ensemble's band at every sample.

    Parameters
    ----------
    parameters : mapping, ParameterSet, ParameterEnsemble, FitResult, str or Path
        A set or an ensemble (paper's N-mm-s units), in any form ``parameter_sets`` accepts.
    time_s, displacement_mm : array_like
        Sample times [s] and displacement [mm].
    velocity_mm_s : array_like, optional
        Measured velocity [mm/s] at the samples.
    model : str or BushingModel, optional
        The model the parameters must be for (or its name).
    rest_force_N : float, optional
        The force [N] the test holds at rest before it moves (``measured.offsets.held_force``):
        a model that can hold a force at rest starts holding it; NaN (default): relaxed.
    temperature_K : float, optional
        The rubber's temperature [K] (a model with a temperature law runs at it); NaN (default):
        at each set's own ``temperature``.

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
    if isinstance(parameters, (str, Path)):      # read once: its sets and its fit's record
        from fmu_src.parameter_files import read_ensemble
        parameters = read_ensemble(parameters)
    bushing, sets = parameter_sets(parameters, model)
    at = temperature_conditions(temperature_K)
    sets = [bushing.check(conditioned_set(bushing, values, at)) for values in sets]    # a temperature refused here
    return predict_sets(bushing, sets, time_s, displacement_mm, velocity_mm_s, rest_force_N,
                        training_misfit_N(parameters))


def predict_sets(bushing: BushingModel, sets: list[dict[str, float]], time_s, displacement_mm, velocity_mm_s=None,
                 rest_force_N: float = math.nan, misfit_N: float = math.nan) -> Prediction:
    """:func:`predict` of sets already read and checked (``parameter_sets``): ``bushing`` the
    model, ``sets`` its sets (best first), ``misfit_N`` the fit's training misfit [N]
    (:func:`training_misfit_N`; NaN: not known); for a caller that resolved them once."""
    x = np.asarray(displacement_mm, dtype=float)
    forces = _mounted_population(bushing, sets, lambda matrix, values, offset: simulate_driven(
        matrix, prepare_input(time_s, x - offset, velocity_mm_s,
                              rest_force_N=model_rest_force(bushing, values, float(x.flat[0]) - offset, rest_force_N)),
        model=bushing), by_start=True)
    _refuse_failed(forces[0], time_s)
    return Prediction(np.asarray(time_s, dtype=float), x, forces[0], np.nanmin(forces, axis=0),
                      np.nanmax(forces, axis=0), len(sets), misfit_N)


@dataclass
class MultiAxisPrediction:
    """What ``predict_multiaxis`` returns: as :class:`Prediction`, with displacement and force
    vectors (samples, d) [mm, N] and the coupling they were simulated with."""
    time_s: np.ndarray
    displacement_mm: np.ndarray
    force_N: np.ndarray
    lower_N: np.ndarray
    upper_N: np.ndarray
    members: int
    coupling: str

    @property
    def band_width_N(self) -> np.ndarray:
        return self.upper_N - self.lower_N

    def write_csv(self, path: str | Path) -> Path:
        """A multi-axis file (``multiaxis.write_multiaxis``: ``time_s,dx_mm,dy_mm,Fx_N,Fy_N``...) and,
        for an ensemble, ``Fx_min_N,Fx_max_N``... of each axis."""
        from identification.measured.multiaxis import AXIS_NAMES
        axes = AXIS_NAMES[:self.force_N.shape[1]]
        columns = [self.time_s[:, None], self.displacement_mm, self.force_N]
        header = ["time_s"] + [f"d{a}_mm" for a in axes] + [f"F{a}_N" for a in axes]
        if self.members > 1:
            for c, a in enumerate(axes):
                columns += [self.lower_N[:, c:c + 1], self.upper_N[:, c:c + 1]]
                header += [f"F{a}_min_N", f"F{a}_max_N"]
        table = np.hstack(columns)
        path = Path(path)
        with open(path, "w", newline="", encoding="utf-8") as stream:
            stream.write(f"# predicted by identification.predict from {self.members} parameter set(s), "
                         f"{self.coupling} coupling\n" + ",".join(header) + "\n")
            d = len(axes)
            np.savetxt(stream, table, delimiter=",", fmt=["%.6f"] * (1 + d) + ["%.4f"] * (table.shape[1] - 1 - d))
        return path


def predict_multiaxis(parameters, time_s, displacement_mm, coupling: str, velocity_mm_s=None,
                      model: str | BushingModel | None = None) -> MultiAxisPrediction:
    """Predict a multi-axis path (``displacement_mm`` (samples, d = 2 or 3) [mm]) as :func:`predict`
    does one axis, with ``coupling`` (``multiaxis.COUPLED_AXES``: none, radial, spherical):
    ``simulate.simulate_multiaxis`` of every member in one population call. Raises
    IdentificationError for a coupling the path cannot carry or a best set whose simulation fails."""
    from identification.forward.input_path import prepare_vector_input
    from identification.measured.multiaxis import coupled_axes
    from identification.forward.simulate import simulate_driven_vector
    bushing, sets = parameter_sets(parameters, model)
    x = np.atleast_2d(np.asarray(displacement_mm, dtype=float))
    t = np.asarray(time_s, dtype=float)
    if x.ndim != 2 or x.shape[0] != t.size or x.shape[1] not in (2, 3):
        raise IdentificationError(f"a multi-axis path has 2 or 3 displacement columns, one row per time: got "
                                  f"{x.shape} for {t.size} times")
    coupled = coupled_axes(coupling, x.shape[1])
    forces = _mounted_population(bushing, sets, lambda matrix, values, offset: simulate_driven_vector(
        matrix, prepare_vector_input(t, x - offset, velocity_mm_s), model=bushing, coupled_axes=coupled))
    _refuse_failed(forces[0], t)
    return MultiAxisPrediction(t, x, forces[0], np.nanmin(forces, axis=0), np.nanmax(forces, axis=0), len(sets),
                               coupling)


MISFIT_WIDENING = 1.96
"""Times the fit's rms training misfit a measurement likely falls beyond the members' envelope
(``Prediction.likely_lower_N``): the 95 % point of a normal residual."""


def training_misfit_N(parameters) -> float:
    """The rms [N] of the fit's residual over every sample of its training time series (each
    test's ``misfit_N`` weighted by its samples), from a FitResult or a parameter file's record
    of its fit; NaN where neither says (a set typed by hand, a fit to a data sheet alone)."""
    from fmu_src.parameter_files import ParameterEnsemble, ParameterSet, read_ensemble
    from identification.fitting.result import FitResult
    if isinstance(parameters, (str, Path)):
        parameters = read_ensemble(parameters)
    if isinstance(parameters, FitResult):
        record = parameters.provenance()
    elif isinstance(parameters, (ParameterEnsemble, ParameterSet)):
        record = parameters.provenance
    else:
        return math.nan
    tests = [t for t in (record or {}).get("tests", []) if "misfit_N" in t and t.get("samples")]
    if not tests:
        return math.nan
    samples = sum(t["samples"] for t in tests)
    return math.sqrt(sum(t["samples"] * t["misfit_N"] ** 2 for t in tests) / samples)


def _mounted_population(bushing: BushingModel, sets, simulate_at, by_start: bool = False) -> np.ndarray:
    """Forces (P, ...) of the parameter sets, each with its mounting (F = model(x - offset) +
    preload, ``BushingModel.mounting``): ``simulate_at(matrix, a member's values, offset)`` once for
    each mounting the sets carry (a fit's members share one); with ``by_start``, once for each
    member of a set that holds a ``held_force`` at its start (its relaxed force, and so the force
    it starts holding, is its own)."""
    def key(i, values):
        start = i if by_start and bushing.held_force(values) != 0.0 else None
        return (*bushing.mounting(values), start)
    keys = [key(i, values) for i, values in enumerate(sets)]
    forces = [None] * len(sets)
    for offset, preload, start in dict.fromkeys(keys):
        members = [i for i, k in enumerate(keys) if k == (offset, preload, start)]
        result = simulate_at(parameter_matrix([sets[i] for i in members], bushing), sets[members[0]], offset) + preload
        for row, i in zip(result, members):
            forces[i] = row
    return np.array(forces)


def _refuse_failed(force: np.ndarray, time_s) -> None:
    failed = ~np.isfinite(force)
    if failed.any():
        first = np.argmax(failed.reshape(failed.shape[0], -1).any(axis=1))
        raise IdentificationError(f"the simulation of the best parameter set fails from t = "
                                  f"{np.asarray(time_s)[first]:g} s (overflow or too many substeps): "
                                  "check the units of the displacement (mm) and the amplitude")
