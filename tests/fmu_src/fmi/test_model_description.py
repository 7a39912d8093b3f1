"""One writer describes both FMUs (``fmu_src/fmi/model_description.py``): the pythonfmu FMU and the
native FMU of every model, one axis, six-axis and coupled, declare the same variables and the same
output dependencies, and the dependencies are true: an output moves with each input it lists and
with no other (a master that orders its connections by them sees the FMU as it is)."""
from __future__ import annotations

import math

import pytest
from fmpy import read_model_description

from fmu_harness import BushingFmu
from fmu_src.model.registry import MODELS

ME_ONLY = ("der(", "event.", "time")
"""What the native FMU adds for model exchange: the states' derivatives, event indicators, time."""


def _input_dependencies(description) -> dict[str, list[str]]:
    return {u.variable.name: sorted(d.name for d in u.dependencies if d.causality == "input")
            for u in description.outputs}


def assert_described_alike(pythonfmu_path, native_path):
    python_side, native = read_model_description(pythonfmu_path), read_model_description(native_path)
    native_variables = {v.name: v for v in native.modelVariables}
    for v in python_side.modelVariables:
        twin = native_variables.get(v.name)
        assert twin is not None, f"{v.name} is not a variable of the native FMU"
        assert (v.valueReference, v.causality, v.variability, v.unit, v.start, v.description) == \
            (twin.valueReference, twin.causality, twin.variability, twin.unit, twin.start, twin.description), v.name
    extra = set(native_variables) - {v.name for v in python_side.modelVariables}
    assert all(any(mark in name for mark in ME_ONLY) for name in extra), sorted(extra)
    assert _input_dependencies(python_side) == _input_dependencies(native)
    # co-simulation alone: an output is computed from the inputs (its states are the step's, not the host's)
    assert all(d.causality == "input" for u in python_side.outputs for d in u.dependencies)
    assert {u.name for u in python_side.unitDefinitions} <= {u.name for u in native.unitDefinitions}


@pytest.mark.parametrize("name", [*MODELS, "six_axis"])
def test_both_fmus_declare_the_same_variables_and_output_dependencies(name, pythonfmu_model_fmus, native_model_fmus):
    assert_described_alike(pythonfmu_model_fmus[name], native_model_fmus[name])


@pytest.fixture(scope="module")
def coupled_fmus(coupled_six_axis_fmus):
    """The pythonfmu and the native six-axis FMU with spherical (x, y, z: the proposed model) and
    conical (rx, ry: Berg) groups."""
    return coupled_six_axis_fmus["pythonfmu"], coupled_six_axis_fmus["fmi2"]


def test_both_coupled_six_axis_fmus_declare_the_same_variables_and_output_dependencies(coupled_fmus):
    assert_described_alike(*coupled_fmus)


def moved_outputs(path) -> dict[str, list[str]]:
    """{output: the inputs whose change moves it}, seen in ``path``'s FMU 37 steps into a sine on
    every axis (2 mm or 0.02 rad, 10 Hz, each axis in its own phase): every state away from rest."""
    description = read_model_description(path)
    inputs = [v for v in description.modelVariables if v.causality == "input"]
    outputs = [v.name for v in description.modelVariables if v.causality == "output"]
    pairs = [(inputs[i], inputs[i + 1]) for i in range(0, len(inputs), 2)]   # (displacement, velocity) per axis
    fmu = BushingFmu(path, initial_inputs={})
    h, w = 1e-3, 2 * math.pi * 10.0

    def path_at(k):
        values = {}
        for i, (d, v) in enumerate(pairs):
            amplitude = 2e-2 if d.unit == "rad" else 2e-3
            values[d.name] = amplitude * math.sin(w * k * h + 0.7 * i)
            values[v.name] = amplitude * w * math.cos(w * k * h + 0.7 * i)
        return values
    try:
        for k in range(37):
            for name, value in path_at(k).items():
                fmu.set(name, value)
            assert fmu.do_step(h) == "ok"
        now = path_at(37)
        for name, value in now.items():
            fmu.set(name, value)
        before = {name: fmu.get(name) for name in outputs}
        moved = {name: [] for name in outputs}
        for known in inputs:
            step = 1e-5 if known.unit in ("m", "rad") else 1e-2
            fmu.set(known.name, now[known.name] + step)
            for name in outputs:
                if fmu.get(name) != before[name]:
                    moved[name].append(known.name)
            fmu.set(known.name, now[known.name])
            assert {name: fmu.get(name) for name in outputs} == before
    finally:
        fmu.free()
    return {name: sorted(found) for name, found in moved.items()}


@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
@pytest.mark.parametrize("name", list(MODELS))
def test_an_output_moves_with_the_inputs_it_declares_and_with_no_other(name, kind, pythonfmu_model_fmus,
                                                                        native_model_fmus):
    path = (pythonfmu_model_fmus if kind == "pythonfmu" else native_model_fmus)[name]
    assert moved_outputs(path) == _input_dependencies(read_model_description(path))


@pytest.mark.parametrize("kind", ["pythonfmu", "native"])
def test_a_coupled_groups_outputs_move_with_the_inputs_they_declare_and_with_no_other(kind, coupled_fmus):
    path = coupled_fmus[0 if kind == "pythonfmu" else 1]
    declared = _input_dependencies(read_model_description(path))
    assert moved_outputs(path) == declared
    # the spherical group's hysteresis turns with every member's displacement, its dashpots do not couple
    assert declared["Fx"] == ["dx", "dy", "dz", "vx"] and declared["Fz"] == ["dx", "dy", "dz", "vz"]
