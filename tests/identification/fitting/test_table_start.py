"""A fluid track's starts read off a data sheet (identification/fitting/table_start.py): near the truth on
the hydraulic model's own synthetic sheet, and a clear note where a sheet cannot give them."""
import json
import math

import numpy as np
import pytest

from conftest import REPO
from identification.measured.kdyn_table import KdynTable, load_kdyn_table
from identification.fitting.loop_start import anchored_coordinates
from identification.fitting.search_space import SearchSpace
from identification.fitting.table_start import TableStart, table_start

TRAIN = REPO / "data" / "kdyn_synthetic_hydraulic_train.csv"
TRUTH = {name: float(value) for name, value in
         json.loads((REPO / "data" / "params_hydraulic_mount.json").read_text())["parameters"].items()}


def resonance_hz(p):
    """The track's resonance with the decoupler on its cage, typed: sqrt((kb + kc)/mf)/(2*pi)."""
    return math.sqrt((p["kb"] + p["kc"]) / p["mf"]) / (2.0 * math.pi)


def test_the_synthetic_sheet_gives_the_track_near_its_truth():
    # data/generate_hydraulic.py's training sheet (0.1, 0.5, 2 mm x 1-50 Hz, 1 % and 0.2 deg noise):
    # the starts need only land in the truth's basin; measured: resonance 9.6 Hz (truth 9.98),
    # kb 260 (250), k0 199 (200), gap 0.091 mm (0.1)
    table = load_kdyn_table(TRAIN)
    start = table_start(table, SearchSpace.from_table(table, "hydraulic"))
    assert isinstance(start, TableStart) and not start.missing
    p = start.parameters
    assert resonance_hz(p) == pytest.approx(resonance_hz(TRUTH), rel=0.1)
    assert p["kb"] == pytest.approx(TRUTH["kb"], rel=0.2)
    assert p["k0"] == pytest.approx(TRUTH["k0"], rel=0.2)
    assert 0.5 * TRUTH["gap"] <= p["gap"] <= 2.0 * TRUTH["gap"]
    assert "fluid track from the data sheet" in start.describe()


def test_a_free_plates_sheet_gives_its_gap_and_starts_for_its_cage():
    # data/generate_hydraulic_free_decoupler.py's training sheet, made by scipy from a hard-caged
    # plate free within +-0.12 mm (truth typed there: kb 280, kc 30, mf 0.09, a 9.34 Hz track);
    # measured: resonance 8.4 Hz, kb 268, gap 0.20 mm, then the stated proportions of the cage
    table = load_kdyn_table(REPO / "data" / "kdyn_synthetic_free_decoupler_train.csv")
    start = table_start(table, SearchSpace.from_table(table, "hydraulic_free_decoupler"))
    assert isinstance(start, TableStart) and not start.missing
    p = start.parameters
    assert resonance_hz(p) == pytest.approx(9.34, rel=0.15)
    assert 0.5 * 0.12 <= p["gap"] <= 2.0 * 0.12
    assert p["width"] == pytest.approx(0.05 * p["gap"], rel=1e-12)
    assert p["kcage"] == pytest.approx(10.0 * (p["kb"] + p["kc"]), rel=1e-12)
    assert p["kd"] == pytest.approx(0.02 * (p["kb"] + p["kc"]), rel=1e-12)
    space = SearchSpace.from_table(table, "hydraulic_free_decoupler")
    assert {space.names[i] for i in anchored_coordinates(start, space)} == set(p)


def test_the_anchored_coordinates_are_the_starts_in_the_box():
    table = load_kdyn_table(TRAIN)
    space = SearchSpace.from_table(table, "hydraulic")
    start = table_start(table, space)
    anchored = anchored_coordinates(start, space)
    assert {space.names[i] for i in anchored} == set(start.parameters)
    full = space.to_coordinates({**TRUTH, **start.parameters})
    for i, value in anchored.items():
        assert value == pytest.approx(full[i], abs=1e-12)


def _table(amplitudes, frequencies, kdyn, angle):
    amplitudes, frequencies = np.asarray(amplitudes, float), np.asarray(frequencies, float)
    return KdynTable(amplitudes, frequencies, np.zeros(amplitudes.size), np.asarray(kdyn, float),
                     np.asarray(angle, float), np.ones(amplitudes.size), "sheet.csv")


def test_a_sheet_without_a_peak_or_with_too_few_frequencies_says_so():
    space = SearchSpace(300.0, 1.0, 600.0, 1e-3, "hydraulic", 2.0)
    rising = _table([2.0] * 4, [1.0, 5.0, 10.0, 50.0], [200.0, 250.0, 300.0, 350.0], [3.0, 5.0, 8.0, 12.0])
    note = table_start(rising, space)
    assert isinstance(note, str) and "no peak inside its frequencies (1-50 Hz)" in note and "default box" in note
    two = _table([2.0, 2.0], [5.0, 10.0], [200.0, 300.0], [10.0, 40.0])
    note = table_start(two, space)
    assert isinstance(note, str) and "2 frequencies at its largest amplitude (2 mm)" in note


def test_a_sheet_at_two_preloads_is_read_at_one():
    # the synthetic sheet again at a 1.5 mm preload, stiffer by half: the starts are the ones of
    # the sheet at preload 0 alone (the more common preload at the largest amplitude, then the
    # nearest 0)
    table = load_kdyn_table(TRAIN)
    space = SearchSpace.from_table(table, "hydraulic")
    both = KdynTable(*(np.concatenate([column, column]) for column in (
        table.amplitude_mm, table.frequency_hz)), np.concatenate([table.preload_mm, table.preload_mm + 1.5]),
        np.concatenate([table.kdyn_N_per_mm, 1.5 * table.kdyn_N_per_mm]),
        np.concatenate([table.loss_angle_deg, table.loss_angle_deg]), np.concatenate([table.weight, table.weight]),
        "two.csv")
    assert table_start(both, space).parameters == table_start(table, space).parameters


def test_one_amplitude_leaves_the_travel_to_the_box():
    space = SearchSpace(300.0, 1.0, 600.0, 1e-3, "hydraulic", 2.0)
    one = _table([1.0] * 5, [2.0, 5.0, 8.0, 12.0, 30.0], [220.0, 200.0, 500.0, 700.0, 480.0],
                 [5.0, 20.0, 60.0, 30.0, 4.0])
    start = table_start(one, space)
    assert "gap" not in start.parameters and "single amplitude (1 mm)" in start.missing


def test_a_model_without_a_track_and_no_table_give_no_start():
    table = load_kdyn_table(TRAIN)
    assert table_start(table, SearchSpace.from_table(table, "berg")) is None
    assert table_start(None, SearchSpace.from_table(table, "hydraulic")) is None


def _sine_tests(params, amplitude_mm, frequencies_hz, model="hydraulic"):
    """2 s sines from rest at 1 kHz, the model's force (no noise), as rig tests."""
    from identification.forward.simulate import simulate
    from identification.measured.measurements import Measurement
    from identification.measured.rig_tests import RigTest
    t = np.arange(2001) / 1000.0
    tests = []
    for f in frequencies_hz:
        x = amplitude_mm * np.sin(2.0 * np.pi * f * t)
        v = amplitude_mm * 2.0 * np.pi * f * np.cos(2.0 * np.pi * f * t)
        force = simulate(params, t, x, v, model=model)
        tests.append(RigTest(Measurement(t, x, force, v, source=f"sine_{f:g}Hz.csv"), kind="sine"))
    return tests


def test_a_sines_first_harmonic_is_the_closed_forms_stiffness():
    # the linear mount (no decoupler, no turbulence): each sine's reading against the closed form
    # typed in tests/references/hydraulic_closed_form.py; its later half is settled (the column's
    # transient decays as exp(-9.3/s*t)), the secant sine's harmonic is within (pi/(1000/f))^2/3
    import importlib.util
    from identification.fitting.table_start import sines_as_table
    spec = importlib.util.spec_from_file_location("closed_form", REPO / "tests" / "references" / "hydraulic_closed_form.py")
    closed_form = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(closed_form)
    linear = dict(TRUTH, gap=0.0, ct=0.0)
    frequencies = (3.0, 8.0, 12.0)
    table = sines_as_table(_sine_tests(linear, 1.0, frequencies))
    expected = closed_form.complex_stiffness(linear, np.array(frequencies))
    np.testing.assert_allclose(table.frequency_hz, frequencies, rtol=1e-6)   # interpolated crossings: observed 4e-8
    np.testing.assert_allclose(table.kdyn_N_per_mm, np.abs(expected), rtol=1e-3)       # observed <= 2.0e-4
    np.testing.assert_allclose(table.loss_angle_deg, np.degrees(np.angle(expected)), atol=0.05)   # observed 0.019
    assert table.amplitude_mm.tolist() == [1.0, 1.0, 1.0]


def test_sines_alone_give_the_track_a_start_and_one_sine_says_why_not():
    # time series alone: sines of 1 mm at five frequencies around the membrane mount's track
    # (truth 9.98 Hz) give its resonance; one sine cannot, and the note says what would
    from identification.fitting.table_start import sines_as_table
    tests = _sine_tests(TRUTH, 1.0, (5.0, 7.0, 9.0, 11.0, 14.0))
    table = sines_as_table(tests)
    space = SearchSpace(300.0, 1.0, 600.0, 1.0, "hydraulic", 2.0)
    start = table_start(table, space)
    assert isinstance(start, TableStart)
    assert resonance_hz(start.parameters) == pytest.approx(resonance_hz(TRUTH), rel=0.15)     # observed 9.08 Hz
    assert "single amplitude" in start.missing and "sine_9Hz.csv" in start.describe()
    note = table_start(sines_as_table(tests[2:3]), space)
    assert isinstance(note, str) and "a single frequency" in note and "sines at 3 or more frequencies" in note
