"""Assemble a six-axis parameter file from one fit per axis (``python -m identification assemble``).

Each axis of ``SixAxisBushing`` (``fmu_src/fmi/axes.py``) is fitted on its own, from its own tests,
with ``fit`` as for a one-axis bushing. A rotational axis (rx, ry, rz) is fitted from a torsion or
tilt test with the angle in the displacement column and the moment in the force column, in
rad and N.mm: its parameters then read in N.mm, rad, s, as the six-axis FMU takes them.
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

from fmu_src.fmi.axes import SIX_AXES, SIX_AXIS_NAMES, six_axis
from fmu_src.model.registry import LINEAR_BASELINE
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.parameter_files import read_parameter_set, read_six_axis, save_six_axis

RIGID_STIFFNESS = 1e7
"""k of a rigid axis (--rigid-missing): 1e7 N/mm = 1e10 N/m, or 1e7 N.mm/rad = 1e4 N.m/rad, with
no damping. Stiff for an explicit co-simulation step: a master may need a shorter step."""


def assemble(axis_files: Mapping[str, str | Path], out: str | Path, rigid_missing: bool = False,
             default: str | Path | None = None, coupling=None) -> Path:
    """Write the six-axis file ``out`` (JSON or .ssv) from ``axis_files`` {axis: one-axis parameter
    or fit file}. An axis without a file takes its set from the six-axis file ``default``, or,
    with ``rigid_missing``, a rigid Kelvin-Voigt spring (RIGID_STIFFNESS); otherwise it is an error.
    ``coupling`` (``axes.Coupling`` or what ``Coupling.of`` takes; default: the ``default`` file's,
    else none) couples groups of axes: the isotropic coupled model has the one-axis parameters, so
    one fit along one axis gives a group's set (``--axis x=P --axis y=P``); a group whose axes differ
    is refused (``parameter_files.check_groups``), and a coupled set must be JSON."""
    for name in axis_files:
        six_axis(name)   # an unknown axis name is an error naming the six
    if rigid_missing and default is not None:
        raise ParameterError("give either --rigid-missing or --default, not both")
    fallback = read_six_axis(default) if default is not None else None
    axes, sources = {}, {}
    for axis in SIX_AXES:
        if axis.name in axis_files:
            path = Path(axis_files[axis.name])
            try:
                one = read_parameter_set(path)
            except ParameterError as exc:
                raise ParameterError(f"axis {axis.name}: {exc}") from None
            axes[axis.name] = (one.model.name, one.parameters)
            sources[axis.name] = str(path)
        elif fallback is not None:
            one = fallback.axes[axis.name]
            axes[axis.name] = (one.model.name, one.parameters)
            sources[axis.name] = f"{default} (default)"
        elif rigid_missing:
            axes[axis.name] = (LINEAR_BASELINE.name, {"k": RIGID_STIFFNESS, "c": 0.0, "preload": 0.0})
            sources[axis.name] = "rigid (--rigid-missing)"
        else:
            missing = [name for name in SIX_AXIS_NAMES if name not in axis_files]
            raise ParameterError(f"no parameter file for the axes {', '.join(missing)}: give --axis NAME=FILE for "
                                 "each, or --rigid-missing (a stiff spring), or --default SIX.json (those axes "
                                 "from another six-axis file)")
    if coupling is None and fallback is not None:
        coupling = fallback.coupling
    return save_six_axis(out, axes, {"assembled_from": sources}, coupling)
