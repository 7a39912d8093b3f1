"""Coupled groups of the six-axis FMU (``axes.Coupling``: radial x-y, spherical x-y-z, conical
rx-ry): the parameter file's ``"coupling"``, its checks, and the pythonfmu FMU against the coupled
kernels, with the mounting, its FMU state and its ModelStructure."""
import math

import numpy as np
import pytest
from fmpy import read_model_description

import build_fmu
from conftest import DATA
from example_parameter_files import SIX_AXIS_DEFAULT, six_axis_file
from fmu_harness import BushingFmu
from fmu_src.fmi.axes import SIX_AXES, Coupling
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.integration import DEFAULT_MAX_SUBSTEPS, OK
from fmu_src.parameter_files import read_six_axis, save_six_axis, six_axis_document

DEFAULT = SIX_AXIS_DEFAULT
"""An illustrative torsion set (N.mm/rad, N.mm/rad^3, N.mm, rad, N.mm.s/rad)."""
STEP_S = 1e-3
PORTS = [name for axis in SIX_AXES for name in (axis.displacement, axis.velocity)]


@pytest.fixture(scope="module")
def coupled_fmu(coupled_six_axis_fmus):
    """The pythonfmu six-axis FMU with spherical (x, y, z: the proposed model) and conical (rx, ry:
    Berg) groups (conftest's, built once a run), and its parameter file."""
    return coupled_six_axis_fmus["pythonfmu"], coupled_six_axis_fmus["file"]


def plane_path(t, radius=2.0):
    """A circle-like path of the x-y plane [mm]: an ellipse started off its centre."""
    w = 2 * math.pi * 9.7
    return np.stack([radius * np.sin(w * t), 0.7 * radius * (1.0 - np.cos(w * t))], axis=1)


def run_fmu(fmu_path, paths, start_values=None, save_at=None):
    """Step the FMU along ``paths`` {axis name: values in kernel units (mm or rad)}; returns
    {output: values after every step} (and the FMU, kept open, where ``save_at`` asks for its
    state at that step)."""
    steps = len(next(iter(paths.values()))) - 1
    inputs = {name: 0.0 for name in PORTS} | {axis.displacement: paths[axis.name][0] * (1.0 if axis.rotational else 1e-3)
                                              for axis in SIX_AXES if axis.name in paths}
    fmu = BushingFmu(fmu_path, start_values=start_values or {}, initial_inputs=inputs)
    outputs = {axis.output: [] for axis in SIX_AXES}
    try:
        for k in range(steps):
            for axis in SIX_AXES:
                if axis.name in paths:
                    unit = 1.0 if axis.rotational else 1e-3
                    x = paths[axis.name]
                    fmu.set(axis.displacement, x[k] * unit)
                    fmu.set(axis.velocity, (x[k + 1] - x[k]) / STEP_S * unit)
            assert fmu.do_step(STEP_S) == "ok", fmu.messages
            for name in outputs:
                outputs[name].append(fmu.get(name))
    finally:
        fmu.free()
    return {name: np.array(values) for name, values in outputs.items()}


def run_group(model, params, columns, rotational=False):
    """The coupled kernels' force vectors along ``columns`` (samples, 2 or 3) [mm or rad], fed as the
    FMU feeds them: each port value (m or rad) times its factor to the kernel's units."""
    unit, to_kernel = (1.0, 1.0) if rotational else (1e-3, 1000.0)
    columns = np.column_stack([columns, np.zeros((len(columns), 3 - columns.shape[1]))])
    x = columns * unit * to_kernel
    kernels, m = model.coupled, model.constants(params)
    state, state_x, out = kernels.initial_state(m, tuple(x[0])), tuple(x[0]), []
    for k in range(len(x) - 1):
        v = tuple((columns[k + 1, i] - columns[k, i]) / STEP_S * unit * to_kernel for i in range(3))
        state, _, status = kernels.step(m, state, state_x, tuple(x[k]), v, STEP_S, DEFAULT_MAX_SUBSTEPS)
        assert status == OK
        state_x = tuple(x[k, i] + v[i] * STEP_S for i in range(3))
        out.append(kernels.force(m, state, state_x, v))
    return np.array(out)


t = np.arange(0.0, 0.4 + STEP_S / 2, STEP_S)


def test_a_coupled_group_is_the_coupled_model_on_its_axes_vector(coupled_fmu):
    fmu_path, path = coupled_fmu
    six = read_six_axis(path)
    xy = plane_path(t)
    z = 0.5 * np.sin(2 * math.pi * 4.1 * t)
    tilt = 0.01 * plane_path(t, 1.0)
    out = run_fmu(fmu_path, {"x": xy[:, 0], "y": xy[:, 1], "z": z, "rx": tilt[:, 0], "ry": tilt[:, 1]})
    expected = run_group(six.axes["x"].model, six.axes["x"].parameters, np.column_stack([xy, z]))
    np.testing.assert_array_equal(np.column_stack([out["Fx"], out["Fy"], out["Fz"]]), expected)
    tilted = run_group(six.axes["rx"].model, six.axes["rx"].parameters, tilt, rotational=True)
    np.testing.assert_array_equal(np.column_stack([out["Mx"], out["My"]]), tilted[:, :2] * 1e-3)


def test_along_one_axis_the_coupled_fmu_is_the_uncoupled_one(coupled_fmu, tmp_path):
    fmu_path, _ = coupled_fmu
    uncoupled = build_fmu.build_fmu(six_axis_file(tmp_path, "none"), tmp_path, model="six_axis")
    x = 2.0 * np.sin(2 * math.pi * 9.7 * t) + 0.4 * np.sin(2 * math.pi * 3.1 * t)
    coupled_out, plain_out = run_fmu(fmu_path, {"x": x}), run_fmu(uncoupled, {"x": x})
    assert np.max(np.abs(coupled_out["Fx"] - plain_out["Fx"])) <= 1e-12 * np.max(np.abs(plain_out["Fx"]))
    assert np.all(coupled_out["Fy"] == 0.0) and np.all(coupled_out["Fz"] == 0.0)


def test_the_mounting_of_a_group_is_a_vector_offset_and_a_preload_per_axis(coupled_fmu):
    fmu_path, _ = coupled_fmu
    xy = plane_path(t)
    offset = {"x": 0.3, "y": -0.2}
    preload = {"x": 150.0, "y": -40.0}
    plain = run_fmu(fmu_path, {"x": xy[:, 0], "y": xy[:, 1]})
    mounted = run_fmu(fmu_path, {"x": xy[:, 0] + offset["x"], "y": xy[:, 1] + offset["y"]},
                      {"x.offset": offset["x"], "y.offset": offset["y"], "x.preload": preload["x"],
                       "y.preload": preload["y"]})
    for axis, output in (("x", "Fx"), ("y", "Fy")):
        assert np.max(np.abs(mounted[output] - preload[axis] - plain[output])) <= 1e-12 * np.max(np.abs(plain[output]))


def assert_state_round_trip(fmu_path):
    """A plane run: its FMU state saved, 50 steps, restored, the same 50 steps again: the same bits,
    the group's state among them (y.z1 moved)."""
    xy = plane_path(t)
    fmu = BushingFmu(fmu_path, initial_inputs={name: 0.0 for name in PORTS})
    try:
        def step(k):
            for c, axis in enumerate(("x", "y")):
                fmu.set(f"d{axis}", xy[k, c] * 1e-3)
                fmu.set(f"v{axis}", (xy[k + 1, c] - xy[k, c]) / STEP_S * 1e-3)
            assert fmu.do_step(STEP_S) == "ok"
            return fmu.get("Fx"), fmu.get("Fy"), fmu.get("x.z1"), fmu.get("y.z1")
        for k in range(100):
            step(k)
        saved = fmu.fmu.getFMUstate()
        first = [step(k) for k in range(100, 150)]
        fmu.fmu.setFMUstate(saved)
        fmu.time = 100 * STEP_S
        again = [step(k) for k in range(100, 150)]
        assert first == again and first[-1][3] != 0.0
    finally:
        fmu.free()


def test_a_coupled_groups_state_travels_with_the_fmu_state(coupled_fmu):
    assert_state_round_trip(coupled_fmu[0])


def test_a_groups_axes_given_different_parameters_are_refused_at_the_step_naming_both(coupled_fmu):
    fmu_path, _ = coupled_fmu
    fmu = BushingFmu(fmu_path, initial_inputs={name: 0.0 for name in PORTS})
    try:
        assert fmu.do_step(STEP_S) == "ok"
        fmu.set("y.k0", 2000.0)
        assert fmu.do_step(STEP_S) == "discard"
        errors = " ".join(fmu.messages_with("error"))
        assert "spherical group (x, y, z)" in errors and "y.k0 = 2000.0" in errors and "x.k0 = 2393.28" in errors
        fmu.set("y.k0", 2393.28)
        assert fmu.do_step(STEP_S) == "ok"
    finally:
        fmu.free()


def test_each_output_depends_on_every_displacement_of_its_group(coupled_fmu):
    # the group's hysteresis turns with every member's displacement; the proposed model's dashpots
    # act per component and Berg has none (tests/fmu_src/fmi/test_model_description.py: the outputs move so)
    fmu_path, _ = coupled_fmu
    description = read_model_description(fmu_path)
    dependencies = {unknown.variable.name: sorted(v.name for v in unknown.dependencies)
                    for unknown in description.outputs}
    assert [dependencies[f"F{c}"] for c in "xyz"] == [["dx", "dy", "dz", f"v{c}"] for c in "xyz"]
    assert dependencies["Mx"] == dependencies["My"] == ["rx", "ry"] and dependencies["Mz"] == ["rz", "wz"]
    names = {v.name for v in description.modelVariables}
    assert {"x.z1", "y.z1", "z.z1", "rx.travel", "ry.F_s"} <= names and "rx.direction" not in names


@pytest.mark.parametrize("coupling, changes, message", [
    ("diagonal", {}, "unknown coupling 'diagonal'; allowed: radial, spherical, conical"),
    ({"translation": "axial"}, {}, "unknown translation coupling 'axial'; allowed: none, radial, spherical"),
    ({"shear": "radial"}, {}, "unknown coupling keys \\['shear'\\]"),
    ("radial", {"y__k0": 100.0}, r"radial group \(x, y\): x.k0 = 2393.28, y.k0 = 100.0 \[N/mm\] differ"),
    ("conical", {"ry__Ff_max": 1.0}, r"conical group \(rx, ry\): rx.Ff_max = 2000.0, ry.Ff_max = 1.0 \[N.mm\] differ"),
])
def test_a_coupling_that_cannot_be_built_is_refused_naming_what_is_allowed(tmp_path, coupling, changes, message):
    with pytest.raises(ParameterError, match=message):
        read_six_axis(six_axis_file(tmp_path, coupling, **changes))


def test_a_group_of_different_models_or_with_spencers_offset_is_refused():
    six = read_six_axis(DEFAULT)
    axes = {name: (one.model.name, one.parameters) for name, one in six.axes.items()}
    with pytest.raises(ParameterError, match=r"spherical group \(x, y, z\) carries different models \(x: proposed, "
                                             r"y: proposed, z: spencer\)"):
        six_axis_document(axes, coupling="spherical")
    spencer = dict(six.axes["z"].parameters, x0=0.5)
    axes.update({"x": ("spencer", spencer), "y": ("spencer", spencer)})
    with pytest.raises(ParameterError, match=r"x0 = 0.5 \[mm\] must be 0 in a coupled group"):
        six_axis_document(axes, coupling="radial")


def test_a_coupled_set_round_trips_in_json_and_is_refused_as_ssv(tmp_path):
    six = read_six_axis(six_axis_file(tmp_path, "radial"))
    axes = {name: (one.model.name, one.parameters) for name, one in six.axes.items()}
    save_six_axis(tmp_path / "back.json", axes, coupling=six.coupling)
    assert read_six_axis(tmp_path / "back.json").coupling == Coupling("radial", "none")
    with pytest.raises(ParameterError, match="SSP parameter values cannot hold the coupling"):
        save_six_axis(tmp_path / "back.ssv", axes, coupling=six.coupling)


def test_assemble_couples_one_fit_on_a_groups_axes_and_refuses_axes_that_differ(tmp_path, capsys):
    from identification.__main__ import main
    one, other = DATA / "params_table5_combined.json", DATA / "params_table2_sine.json"
    out = tmp_path / "six.json"
    assert main(["assemble", "--axis", f"x={one}", "--axis", f"y={one}", "--coupling", "radial,conical",
                 "--rigid-missing", "--out", str(out)]) == 0
    six = read_six_axis(out)
    assert six.coupling == Coupling("radial", "conical") and six.axes["x"].parameters == six.axes["y"].parameters
    assert main(["assemble", "--axis", f"x={one}", "--axis", f"y={other}", "--coupling", "radial",
                 "--rigid-missing", "--out", str(tmp_path / "bad.json")]) == 2
    assert "the radial group (x, y): x.c0 = 261.99, y.c0 = 256.358 [N.s/mm]" in capsys.readouterr().err
    assert main(["assemble", "--axis", f"x={one}", "--coupling", "axial", "--rigid-missing", "--out",
                 str(tmp_path / "bad.json")]) == 2
    assert "'axial' is not a group; allowed: radial, spherical, conical" in capsys.readouterr().err
