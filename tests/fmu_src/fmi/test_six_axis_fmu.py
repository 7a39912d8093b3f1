"""The six-axis bushing FMU (SixAxisBushing): declaration, each axis against the one-axis model,
FMU state, instances side by side, bad input, and its parameter files."""
import json
import math

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

import build_fmu
from conftest import DATA
from fmu_harness import BushingFmu
from fmu_src.fmi.axes import SIX_AXES, SIX_AXIS_NAMES
from fmu_src.model.parameter_specs import ParameterError
from fmu_src.parameter_files import read_six_axis, save_six_axis
from identification.forward.population import simulate_model_held

DEFAULT = DATA / "params_six_axis_illustrative.json"
AMPLITUDE = {"x": 2e-3, "y": 1e-3, "z": 1.5e-3, "rx": 0.02, "ry": 0.05, "rz": 0.1}     # m or rad
FREQUENCY_HZ = {"x": 10.0, "y": 7.0, "z": 5.0, "rx": 3.0, "ry": 13.0, "rz": 2.0}


@pytest.fixture(scope="module")
def six_axis_fmu(tmp_path_factory):
    return build_fmu.build_fmu(out_dir=tmp_path_factory.mktemp("six_axis"), model="six_axis")


def axis_signals(t):
    """A different sine on every axis: {port: values} in SI."""
    signals = {}
    for axis in SIX_AXES:
        omega = 2 * np.pi * FREQUENCY_HZ[axis.name]
        signals[axis.displacement] = AMPLITUDE[axis.name] * np.sin(omega * t)
        signals[axis.velocity] = AMPLITUDE[axis.name] * omega * np.cos(omega * t)
    return signals


def run_with_fmpy(fmu, t, signals, start_values=None):
    inputs = np.array(list(zip(t, *signals.values())), dtype=[("time", float)] + [(k, float) for k in signals])
    result = simulate_fmu(str(fmu), start_time=0.0, stop_time=t[-1], step_size=t[1] - t[0], output_interval=t[1] - t[0],
                          input=inputs, output=[axis.output for axis in SIX_AXES], start_values=start_values or {})
    return {axis.output: result[axis.output][:t.size] for axis in SIX_AXES}


def test_six_axis_fmu_validates_and_declares_ports_units_and_dependencies(six_axis_fmu):
    assert validate_fmu(str(six_axis_fmu)) == []
    description = read_model_description(six_axis_fmu)
    assert description.coSimulation.modelIdentifier == "SixAxisBushing"
    variables = {v.name: v for v in description.modelVariables}
    expected = {"dx": ("input", "m"), "vz": ("input", "m/s"), "rx": ("input", "rad"), "wz": ("input", "rad/s"),
                "Fy": ("output", "N"), "Mz": ("output", "N.m"), "x.k0": ("parameter", "N/mm"),
                "z.x0": ("parameter", "mm"), "rz.k": ("parameter", "N.mm/rad"), "rx.c": ("parameter", "N.mm.s/rad"),
                "x.z1": ("local", "N"), "z.y": ("local", "m")}
    for name, (causality, unit) in expected.items():
        assert (variables[name].causality, variables[name].unit) == (causality, unit), name
    units = {u.name: u for u in description.unitDefinitions}
    assert units["N.mm/rad"].baseUnit.rad == -1 and units["N.mm/rad"].baseUnit.factor == pytest.approx(1e-3)
    for axis in SIX_AXES:   # each output depends on its own axis's two inputs, and on nothing else
        output = next(u for u in description.outputs if u.variable.name == axis.output)
        assert sorted(v.name for v in output.dependencies) == sorted([axis.displacement, axis.velocity])
    assert variables["x.k0"].start == repr(read_six_axis(DEFAULT).axes["x"].parameters["k0"])


def test_every_axis_equals_its_one_axis_model_fed_with_that_axis_alone(six_axis_fmu):
    # The reference: each axis's model on its own (the compiled path, bitwise equal to the
    # one-axis FMU's kernels), a rotational axis reading rad as the kernels read mm and giving
    # N.mm, which the six-axis FMU reports as N.m.
    t = np.arange(0.0, 0.3, 1e-3)
    signals = axis_signals(t)
    outputs = run_with_fmpy(six_axis_fmu, t, signals)
    six = read_six_axis(DEFAULT)
    for axis in SIX_AXES:
        one = six.axes[axis.name]
        scale = 1.0 if axis.rotational else 1000.0
        expected = simulate_model_held(one.model.name, one.parameters, t, signals[axis.displacement] * scale,
                                       signals[axis.velocity] * scale) * (1e-3 if axis.rotational else 1.0)
        np.testing.assert_allclose(outputs[axis.output], expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(expected)))
    assert np.max(np.abs(outputs["Mz"])) == pytest.approx(0.1 * 300.0, rel=0.01)   # 0.1 rad x 300 N.m/rad


def test_six_axis_parameters_set_through_fmpy_change_only_their_axis(six_axis_fmu):
    t = np.arange(0.0, 0.1, 1e-3)
    signals = axis_signals(t)
    before = run_with_fmpy(six_axis_fmu, t, signals)
    after = run_with_fmpy(six_axis_fmu, t, signals, start_values={"rz.k": 6.0e5})
    for axis in SIX_AXES:
        if axis.name == "rz":
            assert np.max(np.abs(after["Mz"])) > 1.8 * np.max(np.abs(before["Mz"]))
        else:
            np.testing.assert_array_equal(after[axis.output], before[axis.output])


def drive(fmu, t, signals, first, count):
    outputs = []
    for k in range(first, first + count):
        for port, values in signals.items():
            fmu.set(port, values[k])
        assert fmu.do_step(1e-3) == "ok"
        outputs.append([fmu.get(axis.output) for axis in SIX_AXES])
    return np.array(outputs)


def test_fmu_state_get_set_and_serialisation_are_bit_identical(six_axis_fmu):
    t = np.arange(0.0, 0.2, 1e-3)
    signals = axis_signals(t)
    fmu = BushingFmu(six_axis_fmu, initial_inputs={})
    drive(fmu, t, signals, 0, 50)
    saved = fmu.fmu.getFMUstate()
    serialised = fmu.fmu.serializeFMUstate(saved)
    first = drive(fmu, t, signals, 50, 50)
    fmu.fmu.setFMUstate(saved)
    fmu.time = 0.05
    np.testing.assert_array_equal(drive(fmu, t, signals, 50, 50), first)
    fmu.fmu.setFMUstate(fmu.fmu.deSerializeFMUstate(serialised))
    fmu.time = 0.05
    np.testing.assert_array_equal(drive(fmu, t, signals, 50, 50), first)
    fmu.free()


def test_six_axis_and_one_axis_instances_run_side_by_side(six_axis_fmu, fmu_path):
    t = np.arange(0.0, 0.1, 1e-3)
    signals = axis_signals(t)
    alone = run_with_fmpy(six_axis_fmu, t, signals)
    six = BushingFmu(six_axis_fmu, "six", initial_inputs={})
    other_six = BushingFmu(six_axis_fmu, "six_b", start_values={"x.k0": 100.0}, initial_inputs={})
    one = BushingFmu(fmu_path, "one")
    together = []
    for k in range(t.size - 1):
        for port, values in signals.items():
            six.set(port, values[k])
            other_six.set(port, 0.5 * values[k])
        assert one.step(signals["dx"][k], signals["vx"][k], 1e-3) == "ok"
        assert six.do_step(1e-3) == "ok" and other_six.do_step(1e-3) == "ok"
        together.append([six.get(axis.output) for axis in SIX_AXES])
    # x of the six-axis FMU is Table 5, as the one-axis FMU's default: the same force
    assert one.get("F") == six.get("Fx")
    # (fmpy's simulate_fmu interpolates the input table at its own time points: 1e-14 apart)
    np.testing.assert_allclose(np.array(together), np.column_stack([alone[a.output][1:] for a in SIX_AXES]),
                               rtol=1e-12, atol=1e-9)
    for fmu in (six, other_six, one):
        fmu.free()


def test_non_finite_input_on_any_axis_is_refused_naming_the_port_and_state_is_kept(six_axis_fmu):
    fmu = BushingFmu(six_axis_fmu, initial_inputs={})
    fmu.set("dx", 1e-3)
    fmu.set("vx", 0.1)
    assert fmu.do_step(1e-3) == "ok"
    before = [fmu.get(name) for name in ("x.y", "x.z1", "x.w", "x.z2")]
    fmu.set("wz", math.nan)
    assert fmu.do_step(1e-3) == "discard"
    assert any("input wz = nan rad/s is not a finite number" in m for m in fmu.messages_with("error"))
    assert [fmu.get(name) for name in ("x.y", "x.z1", "x.w", "x.z2")] == before   # no axis moved
    fmu.set("wz", 0.0)
    assert fmu.do_step(1e-3) == "ok"
    fmu.free()


def test_invalid_parameter_on_an_axis_names_the_axis_unit_and_range(six_axis_fmu):
    fmu = BushingFmu(six_axis_fmu, initial_inputs={})
    assert fmu.do_step(1e-3) == "ok"
    fmu.set("rz.k", -5.0)
    assert fmu.do_step(1e-3) == "discard"
    assert any("axis rz: k = -5.0 [N.mm/rad] must be >= 0" in m for m in fmu.messages_with("error")), fmu.messages
    fmu.set("rz.k", 3e5)
    assert fmu.do_step(1e-3) == "ok"
    fmu.free()


def test_a_rotation_beyond_the_small_angle_range_is_warned_once(six_axis_fmu):
    fmu = BushingFmu(six_axis_fmu, initial_inputs={})
    fmu.set("ry", 0.5)
    fmu.set("ry", 0.6)
    warnings = [m for m in fmu.messages_with("warning") if "ry = " in m]
    assert len(warnings) == 1 and "small angles" in warnings[0]
    fmu.free()


@pytest.mark.parametrize("suffix", [".json", ".ssv"])
def test_six_axis_parameter_files_round_trip(tmp_path, suffix):
    six = read_six_axis(DEFAULT)
    axes = {name: (one.model.name, one.parameters) for name, one in six.axes.items()}
    path = save_six_axis(tmp_path / f"six{suffix}", axes)
    back = read_six_axis(path)
    assert {name: (one.model.identifier, one.parameters) for name, one in back.axes.items()} == \
        {name: (one.model.identifier, one.parameters) for name, one in six.axes.items()}
    assert list(back.axes) == list(SIX_AXIS_NAMES)


def test_six_axis_parameter_file_errors_name_the_axis(tmp_path):
    document = json.loads(DEFAULT.read_text())
    del document["axes"]["ry"]
    (tmp_path / "missing.json").write_text(json.dumps(document))
    with pytest.raises(ParameterError, match="missing axes ry"):
        read_six_axis(tmp_path / "missing.json")
    document = json.loads(DEFAULT.read_text())
    document["axes"]["rz"]["parameters"]["c"] = -1.0
    (tmp_path / "bad.json").write_text(json.dumps(document))
    with pytest.raises(ParameterError, match=r"axis rz: .*c = -1.0 \[N.mm.s/rad\] must be >= 0"):
        read_six_axis(tmp_path / "bad.json")
    ssv = save_six_axis(tmp_path / "six.ssv", {n: (o.model.name, o.parameters) for n, o in read_six_axis(DEFAULT).axes.items()})
    ssv.write_text(ssv.read_text().replace('unit="N.mm/rad"', 'unit="N/mm"', 1))
    with pytest.raises(ParameterError, match="axis rx: parameter k has unit 'N/mm'; expected 'N.mm/rad'"):
        read_six_axis(ssv)


def test_assemble_builds_the_six_axis_file_from_one_file_per_axis(tmp_path):
    from identification.cli.arguments import main
    files = {"x": DATA / "params_table5_combined.json", "y": DATA / "params_table2_sine.json",
             "z": DATA / "params_spencer_fit_synthetic_table5.json", "rx": DATA / "params_kelvin_voigt_fit_synthetic_table5.json",
             "ry": DATA / "params_single_bouc_wen_fit_synthetic_table5.json", "rz": DATA / "params_table4_step.ssv"}
    out = tmp_path / "six.json"
    assert main(["assemble", *(f"--axis={name}={path}" for name, path in files.items()), "--out", str(out)]) == 0
    six = read_six_axis(out)
    from fmu_src.parameter_files import read_parameter_set
    for name, path in files.items():
        one = read_parameter_set(path)
        assert (six.axes[name].model.name, six.axes[name].parameters) == (one.model.name, one.parameters)
    assert six.axes["rz"].model.units["k0"] == "N.mm/rad"       # read as a rotational axis
    assert json.loads(out.read_text())["fit"]["assembled_from"]["rz"] == str(files["rz"])


def test_assemble_refuses_a_missing_axis_unless_told_how_to_fill_it(tmp_path, capsys):
    from identification.cli.arguments import main
    only_x = ["assemble", "--axis", f"x={DATA / 'params_table5_combined.json'}"]
    assert main([*only_x, "--out", str(tmp_path / "a.json")]) == 2
    assert "no parameter file for the axes y, z, rx, ry, rz" in capsys.readouterr().err
    assert main([*only_x, "--rigid-missing", "--out", str(tmp_path / "b.json")]) == 0
    assert read_six_axis(tmp_path / "b.json").axes["rz"].parameters == {"k": 1e7, "c": 0.0, "preload": 0.0}
    assert main([*only_x, "--default", str(DEFAULT), "--out", str(tmp_path / "c.ssv")]) == 0
    assert read_six_axis(tmp_path / "c.ssv").axes["z"].parameters == read_six_axis(DEFAULT).axes["z"].parameters
    assert main(["assemble", "--axis", "q=x.json", "--out", str(tmp_path / "d.json")]) == 2
    assert "unknown axis 'q'" in capsys.readouterr().err


def test_six_axis_ssv_reads_in_fmpy_with_the_fmus_names(tmp_path):
    from fmpy.ssp.ssd import read_ssv
    six = read_six_axis(DEFAULT)
    path = save_six_axis(tmp_path / "six.ssv", {n: (o.model.name, o.parameters) for n, o in six.axes.items()})
    assert {p.name: float(p.value) for p in read_ssv(str(path)).parameters} == six.flat()


def test_a_kelvin_voigt_axis_is_k_d_plus_c_v_plus_preload_in_si(six_axis_fmu):
    # rx is Kelvin-Voigt: M = (k*theta + c*omega + preload) N.mm -> N.m, exactly (no state)
    fmu = BushingFmu(six_axis_fmu, start_values={"rx.preload": 50.0}, initial_inputs={})
    p = dict(read_six_axis(DEFAULT).axes["rx"].parameters, preload=50.0)
    for theta, omega in ((0.01, 0.3), (-0.02, 1.5), (0.0, -2.0)):
        fmu.set("rx", theta)
        fmu.set("wx", omega)
        assert fmu.do_step(1e-3) == "ok"
        end = theta + omega * 1e-3      # the step's input path: rx + wx*t
        assert fmu.get("Mx") == pytest.approx((p["k"] * end + p["c"] * omega + p["preload"]) * 1e-3, rel=1e-15)
    fmu.free()


def test_a_step_that_fails_inside_the_compiled_call_is_refused_naming_its_axis(six_axis_fmu):
    # x and y are both the proposed model, stepped together in one compiled call (the default
    # step where numba runs); an overflow on y alone must still be refused naming axis y, with
    # every axis's state kept, as the axis-by-axis step words it.
    fmu = BushingFmu(six_axis_fmu, initial_inputs={})
    fmu.set("dx", 1e-3)
    fmu.set("vx", 0.1)
    assert fmu.do_step(1e-3) == "ok"
    before = [fmu.get(name) for name in ("x.y", "x.z1", "x.w", "x.z2", "y.z1", "y.z2")]
    fmu.set("dy", 1e150)
    assert fmu.do_step(1e-3) == "discard"
    refusals = [m for m in fmu.messages_with("error") if "refused" in m]
    assert refusals and "axis y:" in refusals[-1], refusals
    assert [fmu.get(name) for name in ("x.y", "x.z1", "x.w", "x.z2", "y.z1", "y.z2")] == before
    fmu.set("dy", 0.0)
    assert fmu.do_step(1e-3) == "ok"
    fmu.free()
