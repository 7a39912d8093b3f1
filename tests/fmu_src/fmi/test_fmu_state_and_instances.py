"""FMU state (get/set/serialize), tunable parameters, several instances and builds; each test on
the pythonfmu FMU and on the native one (``build_fmu.py --native``)."""
import numpy as np
import pytest

from conftest import paper_parameters
from fmu_harness import BushingFmu
from identification.measured.signals import Sine, sample_times
from python_core import simulate_python_core

MM = 1e-3
STEP = 1e-3
SINE = Sine(2.0, 10.0)


@pytest.fixture(params=["pythonfmu", "native"])
def fmu_path(request):
    """The Table 5 FMU of each kind (conftest's session fixtures)."""
    return request.getfixturevalue("fmu_path" if request.param == "pythonfmu" else "native_fmu_path")


@pytest.fixture
def fmu_path_table2(fmu_path, tmp_path_factory, request):
    """A second build of the same kind as ``fmu_path``, with Table 2 as defaults."""
    from conftest import DATA, is_native
    import build_fmu
    if not is_native(fmu_path):
        return request.getfixturevalue("fmu_path_table2")
    return build_fmu.build_native_fmu(DATA / "params_table2_sine.json", tmp_path_factory.mktemp("native_table2")).path


def drive(fmu, first_step, count):
    """Step the sine from step index ``first_step``; return the forces after each step."""
    forces = []
    for k in range(first_step, first_step + count):
        x, v = SINE.signals(np.array([k * STEP]))
        assert fmu.step(x[0] * MM, v[0] * MM, STEP) == "ok"
        forces.append(fmu.get("F"))
    return forces


def test_restored_state_repeats_the_steps_bit_for_bit(fmu_path):
    fmu = BushingFmu(fmu_path)
    drive(fmu, 0, 37)
    saved = fmu.fmu.getFMUstate()
    first = drive(fmu, 37, 40) + list(fmu.states())
    fmu.fmu.setFMUstate(saved)
    fmu.time = 37 * STEP
    second = drive(fmu, 37, 40) + list(fmu.states())
    assert first == second
    fmu.fmu.freeFMUstate(saved)
    fmu.free()


def test_serialized_state_continues_bit_for_bit_in_another_instance(fmu_path):
    fmu = BushingFmu(fmu_path, instance_name="original")
    drive(fmu, 0, 53)
    state = fmu.fmu.getFMUstate()
    serialized = fmu.fmu.serializeFMUstate(state)
    expected = drive(fmu, 53, 30)

    other = BushingFmu(fmu_path, instance_name="restored")
    restored = other.fmu.deSerializeFMUstate(serialized)
    other.fmu.setFMUstate(restored)
    other.time = 53 * STEP
    assert drive(other, 53, 30) == expected
    for instance in (fmu, other):
        instance.free()


def test_tunable_parameter_change_continues_from_the_current_state(fmu_path):
    table2 = paper_parameters("table2")
    fmu = BushingFmu(fmu_path)
    drive(fmu, 0, 50)
    before = fmu.states()
    for name, value in table2.items():
        fmu.set(name, value)
    assert fmu.states() == before  # a parameter change moves no state
    after_change = drive(fmu, 50, 50)
    fmu.free()

    # Reference: the core with Table 5 for 50 steps, then Table 2 from that state.
    from fmu_src.model.integration import advance
    from fmu_src.models.proposed_model import MODEL
    table5 = paper_parameters("table5")
    t = sample_times(0.1, 1000.0)
    x, v = SINE.signals(t)
    state, state_x = MODEL.initial_state(MODEL.constants(table5), 0.0), 0.0
    for k in range(100):
        constants = MODEL.constants(table5 if k < 50 else table2)
        state, _ = advance(MODEL, constants, state, state_x, x[k], v[k], STEP)
        state_x = x[k] + v[k] * STEP
        if k >= 50:
            assert after_change[k - 50] == pytest.approx(MODEL.force(constants, state, state_x, v[k]), rel=1e-12)


def test_instances_with_different_parameters_stay_independent(fmu_path):
    tables = ["table2", "table4", "table5"]
    t = sample_times(0.1, 1000.0)
    x, v = SINE.signals(t)
    instances = [BushingFmu(fmu_path, instance_name=name, start_values=paper_parameters(name), v0_m_s=v[0] * MM)
                 for name in tables]
    forces = {name: [instance.get("F")] for name, instance in zip(tables, instances)}
    for k in range(t.size - 1):  # interleaved, as a master steps a vehicle's bushings
        for name, instance in zip(tables, instances):
            assert instance.step(x[k] * MM, v[k] * MM, STEP) == "ok"
            forces[name].append(instance.get("F"))
    for name, instance in zip(tables, instances):
        np.testing.assert_allclose(forces[name], simulate_python_core(paper_parameters(name), t, x, v), rtol=1e-12, atol=1e-9)
        instance.free()


def test_two_builds_with_different_defaults_run_their_own_code_in_one_process(fmu_path, fmu_path_table2):
    t = sample_times(0.05, 1000.0)
    x, v = SINE.signals(t)
    for path, table in ((fmu_path, "table5"), (fmu_path_table2, "table2"), (fmu_path, "table5")):
        fmu = BushingFmu(path, v0_m_s=v[0] * MM)
        forces = [fmu.get("F")] + drive(fmu, 0, t.size - 1)
        fmu.free()
        np.testing.assert_allclose(forces, simulate_python_core(paper_parameters(table), t, x, v), rtol=1e-12, atol=1e-9)


def test_fmu_can_be_instantiated_many_times_after_its_extraction_was_deleted(fmu_path):
    # pythonfmu re-executes the slave module at every instantiation; fmpy's simulate_fmu
    # deletes its extraction afterwards. Both together once crashed the host.
    from fmpy import simulate_fmu
    for _ in range(5):
        result = simulate_fmu(str(fmu_path), stop_time=0.01, step_size=STEP, output=["F"])
        assert np.all(result["F"] == 0.0)
