"""The identification's forward model against the continuous-time model of the paper's eqs. 1-5."""
import numpy as np
import pytest

from conftest import paper_force, paper_parameters
from fmu_src.model.registry import MODELS
from identification.forward.population import simulate_model_held
from identification.forward.input_path import prepare_input
from identification.measured.signals import Random, Sine, Step, sample_times
from identification.forward.simulate import simulate


def sine_functions(amplitude_mm, frequency_hz):
    omega = 2 * np.pi * frequency_hz
    return (lambda t: amplitude_mm * np.sin(omega * t)), (lambda t: amplitude_mm * omega * np.cos(omega * t))


def noise_level(force):
    """1 % of the rms force: the force noise of the identification's hardest synthetic tests."""
    return 0.01 * np.sqrt(np.mean(force ** 2))


@pytest.mark.parametrize("table, frequency_hz, duration_s", [
    ("table2", 10.0, 0.3), ("table4", 10.0, 0.3), ("table5", 10.0, 0.3),
    ("table2", 30.0, 0.2), ("table5", 30.0, 0.2)])
def test_at_the_truth_the_fit_sees_under_a_tenth_of_a_1pct_noise_level(table, frequency_hz, duration_s):
    # 1 kHz samples of a 2 mm sine, simulated from the samples alone (spline), against scipy's
    # Radau on the paper's equations with the exact sine: what a fit to noise-free data would
    # see at the true parameters. The FMU's input convention (velocity held per step) sees
    # far more; it is the co-simulation semantics, not the continuous-time model.
    params = paper_parameters(table)
    t = sample_times(duration_s, 1000.0)
    displacement, velocity = sine_functions(2.0, frequency_hz)
    reference = paper_force(params, t, displacement, velocity)
    forward = simulate(params, t, displacement(t))
    held = simulate_model_held("proposed", params, t, displacement(t), velocity(t))
    rms = lambda error: np.sqrt(np.mean(error ** 2)) / noise_level(reference)
    assert rms(forward - reference) < 0.1
    assert rms(held - reference) > 0.2


def test_converges_as_the_communication_step_shrinks():
    params = paper_parameters("table2")
    t = sample_times(0.2, 1000.0)
    displacement, velocity = sine_functions(2.0, 30.0)
    fine = simulate(params, t, displacement(t), velocity(t), steps_per_sample=64)
    errors = [np.sqrt(np.mean((simulate(params, t, displacement(t), velocity(t), steps_per_sample=m) - fine) ** 2))
              for m in (2, 4, 8)]
    # measured 1.50, 0.54, 0.38 N: the input path's error falls ~3x per halving until the
    # model's own substep error (integration.THETA) is what remains
    assert errors[0] > errors[1] > errors[2] and errors[2] < errors[0] / 3, errors


def test_steps_per_sample_follow_the_signals_frequency():
    t = sample_times(0.5, 1000.0)
    counts = {f: prepare_input(t, Sine(2.0, f).signals(t)[0]).steps_per_sample for f in (1.0, 10.0, 30.0, 80.0)}
    # at most 0.07 rad of the input's phase per communication step
    assert counts == {1.0: 1, 10.0: 1, 30.0: 3, 80.0: 8}


@pytest.mark.parametrize("frequency_hz, steps", [(0.5, 1), (2.0, 1), (30.0, 3)])
def test_a_measured_displacements_noise_does_not_ask_for_steps_its_signal_does_not_need(frequency_hz, steps):
    # a rig's sine: 1024 Hz samples, the displacement with 1.5 um of noise and the rig's own
    # velocity signal with 2 mm/s (the real friction damper's). At most 0.07 rad of the sine's
    # phase per step: 2*pi*f/1024 Hz is 0.003 and 0.012 rad at 0.5 and 2 Hz (1 step), 0.18 at 30 Hz (3)
    t = np.arange(0.0, 6.0, 1.0 / 1024.0)
    rng = np.random.default_rng(4)
    displacement, velocity = sine_functions(25.0, frequency_hz)
    x = displacement(t) + rng.normal(0.0, 1.5e-3, t.size)
    v = velocity(t) + rng.normal(0.0, 2.0, t.size)
    assert prepare_input(t, x, v).steps_per_sample == steps
    assert prepare_input(t, x).steps_per_sample == steps
    # without the noise the sample-scale x'' is the sine's own: the same counts
    assert prepare_input(t, displacement(t), velocity(t)).steps_per_sample == steps


def test_a_decimated_hold_gives_the_same_forces_at_the_samples_it_keeps():
    params = paper_parameters("table5")
    t = sample_times(3.0, 1000.0)
    x, v = Step(2.0, 0.4, 3.0).signals(t)
    full = prepare_input(t, x)
    decimated = prepare_input(t, x, decimate_holds=True)
    assert decimated.sample_index.size < 0.25 * t.size
    from identification.forward.simulate import simulate_driven
    from identification.forward.population import parameter_matrix
    matrix = parameter_matrix([params])
    every = simulate_driven(matrix, full)[0]
    kept = simulate_driven(matrix, decimated)[0]
    assert np.max(np.abs(kept - every[decimated.sample_index])) < 1e-6 * np.max(np.abs(every))


def test_a_strided_sine_follows_the_same_path_and_gives_its_kept_samples_forces():
    # a rig's slow sine at 1024 Hz (2048 samples a cycle at 0.5 Hz), forces asked for every 8th
    # sample: against scipy's Radau on the paper's equations with the exact sine, within the
    # models' own substep accuracy (integration.THETA: 5e-4 of the peak force), at an eighth of the
    # communication steps (measured: 1.1e-4 of the peak, every sample's 1.4e-6)
    params = paper_parameters("table5")
    t = np.arange(0.0, 4.0, 1.0 / 1024.0)
    displacement, velocity = sine_functions(2.0, 0.5)
    reference = paper_force(params, t, displacement, velocity)
    from identification.forward.simulate import simulate_driven
    from identification.forward.population import parameter_matrix
    matrix = parameter_matrix([params])
    every = prepare_input(t, displacement(t))
    strided = prepare_input(t, displacement(t), stride=8)
    assert strided.stride == 8 and np.array_equal(strided.sample_index, np.arange(0, t.size, 8))
    assert strided.time_s.size < every.time_s.size / 7
    kept = simulate_driven(matrix, strided)[0]
    scale = np.max(np.abs(reference))
    error_every = np.max(np.abs(simulate_driven(matrix, every)[0] - reference)) / scale
    error_kept = np.max(np.abs(kept - reference[strided.sample_index])) / scale
    assert error_every < 1e-5 and error_kept < 5e-4, (error_kept, error_every)


def test_stride_one_is_the_input_as_it_was():
    t = sample_times(3.0, 1000.0)
    x, v = Step(2.0, 0.4, 3.0).signals(t)
    a, b = prepare_input(t, x, decimate_holds=True), prepare_input(t, x, decimate_holds=True, stride=1)
    for name in ("time_s", "displacement_mm", "velocity_mm_s", "output_index", "sample_index"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    with pytest.raises(ValueError, match="stride = 0"):
        prepare_input(t, x, stride=0)


@pytest.mark.parametrize("model", list(MODELS))
def test_every_model_simulates_from_a_mapping_or_a_parameter_set(model):
    from fmu_src.parameter_files import read_parameter_set
    from conftest import DATA
    parameter_set = read_parameter_set(DATA / MODELS[model].default_file)
    t = sample_times(0.3, 1000.0)
    x, v = Random(2.0, 0.3, seed=3).signals(t)
    via_set = simulate(parameter_set, t, x, v)
    via_mapping = simulate(parameter_set.parameters, t, x, v, model=model)
    np.testing.assert_array_equal(via_set, via_mapping)
    held = simulate_model_held(model, parameter_set.parameters, t, x, v)
    # the two input conventions agree to the held velocity's first-order error
    assert np.sqrt(np.mean((via_set - held) ** 2)) < 0.02 * np.sqrt(np.mean(held ** 2))


def test_bad_arrays_are_refused_with_the_reason():
    params = paper_parameters("table5")
    with pytest.raises(ValueError, match="time must increase"):
        simulate(params, np.array([0.0, 0.002, 0.001, 0.003]), np.zeros(4))
    with pytest.raises(ValueError, match="equal length"):
        simulate(params, np.arange(5) / 1000, np.zeros(4))
    with pytest.raises(TypeError, match="mapping"):
        simulate([1.0, 2.0], np.arange(5) / 1000, np.zeros(5))
