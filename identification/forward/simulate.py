"""Simulate any of the project's models on a sampled test: the forward model's front door (the input
it drives the kernels with is ``identification.forward.input_path``'s).

``simulate(parameters, time_s, displacement_mm, velocity_mm_s=None, model=None, steps_per_sample=None)``
returns the force [N] at every sample of a parameter set of any of the models
(``fmu_src.model.registry``), driven by a smooth
interpolant of the sampled displacement (``identification.forward.input_path``): the
continuous-time model, which the fit compares with measurements. The FMU, a co-simulation
slave, sees its inputs held over each communication step instead
(``population.simulate_population_held``). ``simulate_driven_vector`` drives a multi-axis path
(:func:`simulate_multiaxis`), coupled or one model per axis.

Units: time in s, displacement in mm, velocity in mm/s, force in N, parameters in the
paper's N-mm-s units. The bushing starts in relaxed equilibrium at the first displacement, or at
rest holding a given force (``rest_force_N``, for a model that can hold one).
"""
from __future__ import annotations

import math

import numpy as np

from fmu_src.model.registry import BushingModel, DEFAULT_BUSHING, required_model
from identification.forward.population import parameter_matrix, simulate_coupled_at, simulate_population_at
from identification.forward.input_path import DrivenInput, DrivenVectorInput, prepare_input, prepare_vector_input
from identification.forward.parameter_sets import parameter_sets
from identification.measured.multiaxis import coupled_axes


def simulate(parameters, time_s, displacement_mm, velocity_mm_s=None, model: str | BushingModel | None = None,
             steps_per_sample: int | None = None, rest_force_N: float = math.nan) -> np.ndarray:
    """Simulate a model on a sampled displacement: the force at every sample.

    Parameters
    ----------
    parameters : mapping, ParameterSet, ParameterEnsemble, FitResult, str or Path
        The parameter set (paper's N-mm-s units), in any form ``parameter_sets`` accepts; of
        an ensemble or a fit, the best set.
    time_s : array_like
        Sample times [s], increasing.
    displacement_mm : array_like
        Displacement [mm] at the samples.
    velocity_mm_s : array_like, optional
        Velocity [mm/s] at the samples, if measured (else from the displacement's interpolant).
    model : str or BushingModel, optional
        The model, or its name or FMI identifier; default: the one the parameters name, else
        ``"proposed"``.
    steps_per_sample : int, optional
        Communication steps per sample interval (default: chosen from the signal); more give a
        finer reference solution.
    rest_force_N : float, optional
        The force [N] the test holds at rest before it moves (``measured.offsets.held_force``): a
        model that can hold a force at rest (``BushingModel.resting_state``) starts holding it, its
        mounting's preload aside; NaN (default): relaxed, or holding the set's ``held_force`` [N]
        beyond its relaxed force at the first displacement, as the FMU starts.

    Returns
    -------
    numpy.ndarray
        Force [N] at every sample; the bushing starts in relaxed equilibrium at the first
        displacement. A set with a mounting (``offset`` [mm], ``preload`` [N]) gives
        model(x - offset) + preload, as the FMU does.

    Raises
    ------
    ParameterError
        An invalid parameter set (named, with its unit and allowed range).
    ValueError
        Arrays of different lengths, or times that do not increase.
    """
    values, bushing = _parameters_and_model(parameters, model)
    return simulate_set(bushing, values, time_s, displacement_mm, velocity_mm_s, steps_per_sample, rest_force_N)


def temperature_conditions(temperature_K: float) -> tuple[tuple[str, float], ...]:
    """A run's conditions (``DrivenInput.conditions``) of a temperature [K]; none for NaN."""
    return () if temperature_K != temperature_K else (("temperature_K", float(temperature_K)),)


def simulate_record(parameters, measurement, model: str | BushingModel | None = None,
                         steps_per_sample: int | None = None) -> np.ndarray:
    """:func:`simulate` on a measured test as the fit takes it: its measured velocity, started at
    rest holding the force it holds before it moves (``offsets.held_force``) and at its own
    conditions (``Measurement.conditions``: a model with a temperature law at the test's mean
    temperature). Force [N] at every sample."""
    from identification.measured.offsets import held_force
    from identification.forward.population import conditioned_set
    values, bushing = _parameters_and_model(parameters, model)
    m = measurement
    values = bushing.check(conditioned_set(bushing, values, m.conditions))     # a test's temperature refused here
    return simulate_set(bushing, values, m.time_s, m.displacement_mm, m.measured_velocity_mm_s, steps_per_sample,
                        held_force(m) if m.has_force else math.nan)


def simulate_set(bushing: BushingModel, values, time_s, displacement_mm, velocity_mm_s=None,
                 steps_per_sample: int | None = None, rest_force_N: float = math.nan) -> np.ndarray:
    """:func:`simulate` of one set already read and checked (``parameter_sets``): ``bushing`` the
    model, ``values`` its set (paper's N-mm-s units); for a caller that resolved them once."""
    bushing = required_model(bushing)
    offset, preload = bushing.mounting(values)      # F = model(x - offset) + preload; 0 and 0: as it is
    x = np.asarray(displacement_mm, dtype=float) - offset
    driven = prepare_input(time_s, x, velocity_mm_s, steps=steps_per_sample,
                           rest_force_N=model_rest_force(bushing, values, float(x.flat[0]), rest_force_N))
    return simulate_driven(parameter_matrix([values], bushing), driven, model=bushing)[0] + preload


def model_rest_force(bushing: BushingModel, values, x0_mm: float, rest_force_N: float = math.nan) -> float:
    """The force [N] the model (its mounting aside) starts holding at rest at its displacement
    ``x0_mm`` [mm] (the offset taken off): a record's ``rest_force_N`` less the set's preload where
    that is a number, else the set's ``held_force`` beyond its relaxed force there (the FMU's start,
    ``BushingModel.holding_state``), else NaN: relaxed."""
    if rest_force_N == rest_force_N:
        return rest_force_N - bushing.mounting(values)[1]
    held = bushing.held_force(values)
    if held == 0.0:
        return math.nan
    return bushing.relaxed_force(bushing.constants(values), x0_mm) + held


def simulate_driven(matrix: np.ndarray, driven: DrivenInput, max_substeps: int | None = None,
                    model: BushingModel = DEFAULT_BUSHING) -> np.ndarray:
    """Forces [N], shape (P, outputs), of a (P, m) matrix of ``model``'s parameters
    (``population.parameter_matrix``) on a prepared input, at its output samples
    (``driven.sample_index``). NaN from where a candidate fails."""
    kwargs = {} if max_substeps is None else {"max_substeps": max_substeps}
    return simulate_population_at(matrix, driven, model=model, **kwargs)


def simulate_driven_vector(matrix: np.ndarray, driven: DrivenVectorInput, max_substeps: int | None = None,
                           model: BushingModel = DEFAULT_BUSHING, coupled_axes: int = 0) -> np.ndarray:
    """Force vectors [N], shape (P, outputs, d), of a (P, m) matrix of ``model``'s parameters on a
    prepared multi-axis input, at its output samples: the first ``coupled_axes`` axes (2 or 3) run
    the model's coupled form on their displacement vector (``definition.CoupledKernels``),
    every other axis its one-axis model alone (0: every axis alone; so does Kelvin-Voigt, whose
    linear elements couple nothing). NaN from where a candidate fails."""
    bushing = required_model(model)
    kwargs = {} if max_substeps is None else {"max_substeps": max_substeps}
    parts = []
    if coupled_axes and bushing.coupled is not None:
        group = DrivenVectorInput(driven.components[:coupled_axes])
        parts.append(simulate_coupled_at(matrix, group, model=bushing, **kwargs))
    alone = driven.components[coupled_axes if bushing.coupled is not None else 0:]
    parts += [simulate_driven(matrix, c, max_substeps, bushing)[:, :, None] for c in alone]
    return np.concatenate(parts, axis=2)


def _parameters_and_model(parameters, model):
    """The best set of any accepted ``parameters`` (``parameter_sets``) and its model."""
    bushing, sets = parameter_sets(parameters, model)
    return sets[0], bushing


def simulate_multiaxis(parameters, time_s, displacement_mm, model: str | BushingModel | None = None,
                       coupling: str | None = None, velocity_mm_s=None, steps_per_sample: int | None = None
                       ) -> np.ndarray:
    """The force vectors [N], (samples, d), of a parameter set on a multi-axis path ``displacement_mm``
    (samples, d = 2 or 3) [mm] at the times ``time_s`` [s] (and its measured ``velocity_mm_s``, if
    any), driven as the fit drives a test (``identification.measured.multiaxis``), with ``coupling`` (COUPLED_AXES;
    default: every axis of the path coupled, radial on a plane, spherical in 3-space). The bushing
    starts relaxed at the first sample. ``parameters``: any form ``parameter_sets`` takes (a
    mounting's offset [mm] and preload [N] apply to every axis alike)."""
    bushing, sets = parameter_sets(parameters, model)
    values = sets[0]
    t = np.asarray(time_s, dtype=float)
    x = np.atleast_2d(np.asarray(displacement_mm, dtype=float))
    if x.ndim != 2 or x.shape[0] != t.size or x.shape[1] not in (2, 3):
        raise ValueError(f"displacement_mm must be (samples, 2 or 3) with one row per time, got {x.shape} for "
                         f"{t.size} times")
    coupled = coupled_axes(coupling, x.shape[1]) if coupling is not None else x.shape[1]
    offset, preload = bushing.mounting(values)
    driven = prepare_vector_input(t, x - offset, velocity_mm_s, steps=steps_per_sample)
    return simulate_driven_vector(parameter_matrix([values], bushing), driven, model=bushing,
                                  coupled_axes=coupled)[0] + preload
