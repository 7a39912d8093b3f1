"""Feed a measurement to the FMU the way the fit's forward model drives its kernel.

The FMU, a co-simulation slave, takes over each communication step the path x(t) + v*(t - t_k)
from the inputs x and v set at the step's start t_k; where x differs from where the previous
step ended, it takes a displacement jump, which the dashpots carry. A measured table
(time, x, v) whose v is not the derivative of the sampled x (a velocity transducer, a filtered or
differentiated signal: on the friction-damper data in ``data/brfd`` the measured v is 13 % RMS off
the secant Δx/Δt) therefore drives the FMU through a jump at every step, and its force is not the
one the fit computed.

:func:`fmu_input` builds the input the fit's forward model (``identification.forward.input_path``)
uses: its interpolant of the sampled displacement (a cubic spline, or the cubic Hermite
interpolant of the displacement and the measured velocity where the file has a velocity column),
each sample interval split into ``m`` communication steps with the interpolant's displacement at
their ends and v the secant velocity of each step: a continuous piecewise-linear path with no
jumps, in the FMU's SI units (m, m/s; rad, rad/s on a rotational axis). The result is a
structured array as fmpy's ``simulate_fmu(input=...)`` takes it: fields ``time`` and the FMU's
input names (``x``, ``v`` for a one-axis FMU, ``dx``, ``vx`` ... for an axis of the six-axis one).

fmpy interpolates a continuous input linearly between the table's rows and sets it at each
communication point only. The FMU therefore sees exactly the table's (x_j, v_j) where the
communication points are the table's times: x is continuous, and v = (x_(j+1) - x_j)/(t_(j+1) - t_j)
holds over each step. :func:`simulate_measurement` steps the FMU at exactly those times (fmpy's
low-level API: ``simulate_fmu`` steps on the regular grid start + n*output_interval, which a
measurement's rounded time stamps miss by a little) and returns the force at the measurement's
samples; with fmpy's ``simulate_fmu``, pass ``output_interval`` equal to the table's step
(:func:`table_step`), which is exact where the measurement's times are uniform.

The FMU's force at a sample is eq. 5 with the velocity of the step that ends there (the secant);
the forward model evaluates eq. 5 with the interpolant's velocity at the sample. The two differ by
the viscous feedthrough c0*c2/(c0 + c2) times the difference of the two velocities (first order
in the step). :func:`simulate_measurement` (by default, ``sample_velocity=True``) sets the interpolant's
velocity before it reads the force at each sample (eq. 5 only: the state is not touched), as the
forward model does.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from identification.forward.input_path import DrivenInput, prepare_input

__all__ = ["fmu_input", "simulate_measurement", "table_step"]


def _signals(measurement) -> tuple:
    """(time_s, displacement_mm, velocity_mm_s or None) of a Measurement, a CSV path, or a tuple
    (time_s, displacement_mm[, velocity_mm_s])."""
    if isinstance(measurement, (str, Path)):
        from identification.measured.measurements import load_measurement
        measurement = load_measurement(measurement, force_optional=True)
    if isinstance(measurement, tuple):
        time_s, displacement_mm, *rest = measurement
        return time_s, displacement_mm, (rest[0] if rest else None)
    return measurement.time_s, measurement.displacement_mm, measurement.measured_velocity_mm_s


def _driven(signals: tuple, steps_per_sample: int | None) -> DrivenInput:
    """The forward model's driven input of ``_signals``' result (every sample an output)."""
    return prepare_input(*signals, steps=steps_per_sample)


def _axis(axis: str | None):
    from fmu_src.fmi.axes import ONE_AXIS, six_axis
    return ONE_AXIS if axis is None else six_axis(axis)


def fmu_input(measurement, axis: str | None = None, steps_per_sample: int | None = None) -> np.ndarray:
    """The FMU's input table of a measurement: the fit's continuous path, v the secant velocity.

    Parameters
    ----------
    measurement : Measurement, str, Path or tuple
        What ``load_measurement`` returns, a CSV path it reads, or ``(time_s, displacement_mm)``
        or ``(time_s, displacement_mm, velocity_mm_s)`` (s, mm, mm/s; rad and rad/s for a
        rotational axis). A measured velocity shapes the path between samples (the Hermite
        interpolant, as in the fit); the table's v is always the path's secant velocity.
    axis : str, optional
        None for a one-axis FMU (inputs ``x``, ``v``); ``"x"``, ``"y"``, ``"z"``, ``"rx"``,
        ``"ry"``, ``"rz"`` for that axis of the six-axis FMU (``dx``/``vx`` ... ``rz``/``wz``;
        the other axes' inputs stay at their start values).
    steps_per_sample : int, optional
        Communication steps per sample interval (default: the forward model's choice,
        ``input_path.steps_per_sample``); the fit's forces need the fit's steps.

    Returns
    -------
    numpy.ndarray
        Structured array with fields ``time`` [s], the displacement input [m or rad] and the
        velocity input [m/s or rad/s], one row per communication point (the measurement's samples
        and the steps between them); the last row repeats the previous velocity.
    """
    driven = _driven(_signals(measurement), steps_per_sample)
    port = _axis(axis)
    velocity = driven.velocity_mm_s.copy()
    if velocity.size > 1:
        velocity[-1] = velocity[-2]
    table = np.empty(driven.time_s.size, dtype=[("time", np.float64), (port.displacement, np.float64),
                                                 (port.velocity, np.float64)])
    table["time"] = driven.time_s
    table[port.displacement] = driven.displacement_mm / port.to_kernel
    table[port.velocity] = velocity / port.to_kernel
    return table


def table_step(table: np.ndarray) -> float:
    """The communication step of a table from :func:`fmu_input`: its median time step, the
    ``output_interval`` to give fmpy's ``simulate_fmu``."""
    return float(np.median(np.diff(table["time"])))


def simulate_measurement(fmu_path, measurement, start_values=None, step_size: float | None = None,
                         axis: str | None = None, sample_velocity: bool = True) -> np.ndarray:
    """Run an FMU on a measurement as the fit runs its forward model: the force at its samples.

    Parameters
    ----------
    fmu_path : str or Path
        A bushing FMU (pythonfmu or native, FMI 2 or 3).
    measurement : Measurement, str, Path or tuple
        As :func:`fmu_input` takes it.
    start_values : dict, str or Path, optional
        FMU variable name -> value (parameters in the N-mm-s units the FMU declares), or a
        parameter file (a fit's ``params.json``) for a one-axis FMU.
    step_size : float, optional
        Communication step [s]: each sample interval is split into ceil(interval/step_size) equal
        steps (the median interval decides). Default: the forward model's choice, which the fit used.
    axis : str, optional
        The six-axis FMU's axis the measurement drives (as :func:`fmu_input`).
    sample_velocity : bool
        Read the force at each sample with the interpolant's velocity there, as the forward model
        does (default). False: the velocity of the step that ends there, as a master that reads the
        output right after ``doStep`` sees it (eq. 5's viscous feedthrough differs by
        c0*c2/(c0 + c2) times the two velocities' difference).

    Returns
    -------
    numpy.ndarray
        The FMU's output [N, or N.m on a rotational axis] at every sample of the measurement.
    """
    import math
    import shutil

    from fmpy import extract, instantiate_fmu, read_model_description

    if isinstance(start_values, (str, Path)):
        from fmu_src.parameter_files import load_parameters
        start_values = load_parameters(start_values)
    signals = _signals(measurement)
    steps = None
    if step_size is not None:
        interval = float(np.median(np.diff(np.asarray(signals[0], dtype=float))))
        steps = max(1, math.ceil(interval / step_size * (1.0 - 1e-12)))
    driven = _driven(signals, steps)
    port = _axis(axis)
    description = read_model_description(str(fmu_path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    x_ref, v_ref, out_ref = refs[port.displacement], refs[port.velocity], refs[port.output]
    fmi3 = description.fmiVersion.startswith("3")
    unzip = extract(str(fmu_path))
    fmu = instantiate_fmu(unzip, description, fmi_type="CoSimulation")
    set_real = fmu.setFloat64 if fmi3 else fmu.setReal
    get_real = fmu.getFloat64 if fmi3 else fmu.getReal
    t = driven.time_s
    x = driven.displacement_mm / port.to_kernel
    v = driven.velocity_mm_s / port.to_kernel
    out_v = driven.output_velocity_mm_s / port.to_kernel
    force = np.empty(driven.output_index.size)
    try:
        if fmi3:
            fmu.enterInitializationMode(startTime=t[0])
        else:
            fmu.setupExperiment(startTime=t[0])
            fmu.enterInitializationMode()
        for name, value in (start_values or {}).items():
            set_real([refs[name]], [float(value)])
        set_real([x_ref, v_ref], [x[0], v[0]])
        fmu.exitInitializationMode()
        outputs = iter(enumerate(driven.output_index))
        k, j_out = next(outputs)
        for j in range(t.size):
            if j == j_out:
                if sample_velocity:
                    set_real([v_ref], [out_v[k]])
                force[k] = get_real([out_ref])[0]
                k, j_out = next(outputs, (k, -1))
            if j + 1 == t.size:
                break
            set_real([x_ref, v_ref], [x[j], v[j]])
            fmu.doStep(currentCommunicationPoint=float(t[j]), communicationStepSize=float(t[j + 1] - t[j]))
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)
    return force
