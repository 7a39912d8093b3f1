"""The band element (``band``, fmu_src/model/options/band.py): a band brake's self-energizing
friction through a play with a progressive contact, against what it is by its definition: a ramp
and its reversal against the contact and level laws typed here; Coulomb's limit against the Iwan
element's one spring-slider; the classical band brake's two levels; a random path against a
reference of the definition stepped with numpy and scipy's root finder; refusals; the compiled
path, both FMUs and model exchange with CVode equal to its Python kernels."""
from __future__ import annotations

import math
import shutil

import numpy as np
import pytest
from scipy.optimize import brentq

from fmu_src.model.parameter_specs import ParameterError
from fmu_src.model.registry import get_model
from fmu_src.parameter_files import save_parameters
from element_checks import assert_fmu_is_the_forward_model, assert_six_axis_z_is_the_forward_model
from example_parameter_files import defaults
from python_core import simulate_python_core

PURE = dict(k=0.0, c=0.0, preload=0.0)          # a Kelvin-Voigt base of nothing: the band alone
BAND = dict(band_gap=0.5, band_k=1000.0, band_depth=0.2, band_f=100.0, band_ratio_pos=4.0, band_ratio_neg=2.0,
            band_travel=2.0)


def contact(e, p=BAND):
    """The contact force [N] at engagement e [mm]: the stiffness rises linearly over the depth."""
    a = np.maximum(np.abs(e) - p["band_gap"], 0.0)
    k, d = p["band_k"], p["band_depth"]
    g = np.where(a < d, k * a ** 2 / (2 * d) if d > 0 else 0.0, k * (a - d / 2))
    return np.sign(e) * g


def level(s, ratio, p=BAND):
    """The level [N] a travel s [mm] into a side: band_f * ratio**(s/travel), then band_f * ratio."""
    return p["band_f"] * ratio ** (np.minimum(s, p["band_travel"]) / p["band_travel"])


def path(x, dt=1e-3):
    """(t [s], x [mm], v [mm/s]) with x walked exactly as the walk does (no jumps)."""
    t = np.arange(x.size) * dt
    v = np.append(np.diff(x) / dt, 0.0)
    walked = np.empty_like(x)
    walked[0] = x[0]
    for k in range(x.size - 1):
        walked[k + 1] = walked[k] + v[k] * (t[k + 1] - t[k])
    return t, walked, v


def test_a_ramp_and_its_reversal_follow_the_contact_and_the_growing_level():
    # up to 3 mm: the contact engages past the gap (0.5 mm), meets the level about 0.23 mm in and
    # slides on it as it grows (ratio 4 over 2 mm of travel into the contact), then at 400 N; back
    # to -2 mm: the contact unloads, crosses the play and slides the negative way at a level
    # growing from 100 N again (ratio 2)
    gap = BAND["band_gap"]
    up = np.linspace(0.0, 3.0, 3001)
    down = np.linspace(3.0, -2.0, 5001)[1:]
    t, x, v = path(np.concatenate([up, down]))
    force = simulate_python_core(dict(PURE, **BAND), t, x, v, model="kelvin_voigt+band")
    rising = np.minimum(contact(x[:up.size]), level(np.maximum(x[:up.size] - gap, 0.0), 4.0))
    peak_engagement = brentq(lambda e: contact(e) - 400.0, 0.5, 3.0)
    back = 3.0 - x[up.size:]
    into_negative = np.maximum(back - (peak_engagement + gap), 0.0)     # travel past the negative edge
    falling = np.maximum(contact(peak_engagement - back), -level(into_negative, 2.0))
    want = np.concatenate([rising, falling])
    growing = (x[:up.size] - gap > 0.25) & (x[:up.size] - gap < 1.9)      # slid on the level as it grew
    assert np.all(np.isclose(force[:up.size][growing], level(x[:up.size][growing] - gap, 4.0), rtol=1e-9))
    assert rising[-1] == pytest.approx(400.0)
    assert falling[-1] == pytest.approx(-200.0) and np.any(-falling == level(into_negative, 2.0))
    np.testing.assert_allclose(force, want, rtol=0, atol=1e-9 * 400.0)


def test_coulombs_limit_is_one_spring_slider_of_the_iwan_element():
    rng = np.random.default_rng(3)
    t, x, v = path(np.cumsum(np.repeat(rng.normal(0.0, 0.03, 200), 15)))
    coulomb = dict(PURE, band_gap=0.0, band_k=800.0, band_depth=0.0, band_f=250.0, band_ratio_pos=1.0,
                   band_ratio_neg=1.0, band_travel=1.0)
    band = simulate_python_core(coulomb, t, x, v, model="kelvin_voigt+band")
    jenkins = simulate_python_core(dict(PURE, iwan_k=800.0, iwan_f=250.0), t, x, v, model="kelvin_voigt+iwan1")
    assert np.ptp(jenkins) > 400.0                  # it slid both ways
    np.testing.assert_allclose(band, jenkins, rtol=0, atol=1e-9 * 250.0)


def test_with_no_wrap_travel_it_is_the_classical_band_brake_of_two_levels():
    t = np.arange(0.0, 2.0, 1e-3)
    t, x, v = path(4.0 * np.sin(2 * np.pi * t))
    brake = dict(BAND, band_travel=0.0, band_ratio_pos=3.5, band_ratio_neg=1.0)
    force = simulate_python_core(dict(PURE, **brake), t, x, v, model="kelvin_voigt+band")
    assert force.max() == pytest.approx(350.0, rel=1e-12)      # energized: f * exp(mu theta)
    assert force.min() == pytest.approx(-100.0, rel=1e-12)     # released: f


def reference_band(x, p):
    """The band's force [N] along x [mm], stepped sample to sample from its definition by
    tests/references/band_brake.py (the engagement's trial; the travel into the engaged side;
    a slide back to where the contact force meets that side's level, found with scipy's brentq)."""
    import sys
    from conftest import REPO
    sys.path.insert(0, str(REPO / "tests" / "references"))
    import band_brake
    laws = dict(gap=p["band_gap"], kc=p["band_k"], d=p["band_depth"], f=p["band_f"], r_pos=p["band_ratio_pos"],
                r_neg=p["band_ratio_neg"], S=p["band_travel"])
    return band_brake.band_force(laws, x)


def test_a_random_path_is_its_definition_stepped_with_numpy_and_scipys_roots():
    rng = np.random.default_rng(8)
    t, x, v = path(np.cumsum(np.repeat(rng.normal(0.0, 0.04, 300), 12)))
    params = dict(defaults("single_bouc_wen"), **BAND)
    got = simulate_python_core(params, t, x, v, model="single_bouc_wen+band")
    base = simulate_python_core(defaults("single_bouc_wen"), t, x, v, model="single_bouc_wen")
    want = reference_band(x, BAND)
    assert np.ptp(x) > 4 * BAND["band_gap"] and np.ptp(want) > 2 * BAND["band_f"]   # engaged and slid both ways
    np.testing.assert_allclose(got - base, want, rtol=0, atol=1e-8 * 400.0)


@pytest.mark.parametrize("name, value, fragment", [
    ("band_ratio_pos", 0.5, "band_ratio_pos = 0.5 [1] must be >= 1"),
    ("band_k", -1.0, "band_k = -1.0 [N/mm] must be >= 0"),
    ("band_gap", -0.1, "band_gap = -0.1 [mm] must be >= 0"),
])
def test_values_outside_their_range_are_refused_with_unit_and_range(name, value, fragment):
    with pytest.raises(ParameterError, match=fragment.replace("[", r"\[").replace("]", r"\]")):
        get_model("kelvin_voigt+band").check({**PURE, **BAND, name: value})


def test_the_compiled_band_element_equals_its_python_kernels_bitwise():
    from identification.forward.population import simulate_population_held
    rng = np.random.default_rng(5)
    t, x, v = path(np.cumsum(np.repeat(rng.normal(0.0, 0.05, 100), 25)))
    model = get_model("asymmetric_bouc_wen+maxwell+iwan2+band+rig")
    params = dict(defaults("asymmetric_bouc_wen"), **BAND, iwan_k=300.0, iwan_f=200.0, maxwell_k=50.0,
                  maxwell_c=1.0, rig_displacement_zero=0.1, rig_force_zero=20.0)
    compiled = simulate_population_held([model.check(params)], t, x, v, model=model)[0]
    np.testing.assert_array_equal(compiled, simulate_python_core(params, t, x, v, model=model.name))


@pytest.mark.parametrize("kind", ["pythonfmu", "native2"])
def test_both_fmus_of_a_model_with_a_band_equal_its_forward_model(kind, tmp_path):
    want = assert_fmu_is_the_forward_model(kind, get_model("single_bouc_wen+band"),
                                           dict(defaults("single_bouc_wen"), **BAND), tmp_path)
    assert np.ptp(want) > 2 * BAND["band_f"]


@pytest.mark.parametrize("version", [2, 3])
def test_model_exchange_reverses_the_band_at_events_and_follows_a_fine_walk(version, tmp_path):
    # the host integrates the states (CVode); where the engagement crosses the play's edge the
    # FMU's event update releases the band. Reference: the co-simulation walk at 1 us (first order
    # in its step where the level grows as the band slides)
    import build_fmu
    from identification.forward.population import simulate_population_held
    from model_exchange import simulate_model_exchange
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    model = get_model("kelvin_voigt+band")
    params = dict(PURE, **BAND)
    file = save_parameters(tmp_path / "band.json", params, model.name)
    fmu = build_fmu.build_native_fmu(file, tmp_path, model=model.name, fmi_version=version).path
    w, amplitude = 2 * np.pi * 3.0, 2.5
    t = np.linspace(0.0, 0.6, 61)
    run = simulate_model_exchange(fmu, t, lambda s: amplitude * math.sin(w * s) * 1e-3,
                                  lambda s: amplitude * w * math.cos(w * s) * 1e-3)
    fine = np.arange(0.0, 0.6 + 5e-7, 1e-6)
    walk = simulate_population_held([model.check(params)], fine, amplitude * np.sin(w * fine),
                                    amplitude * w * np.cos(w * fine), model=model)[0][::10000]
    assert run.events >= 6          # each side engaged, slid and released
    # measured 2026-12-02: 1.4e-5 of the peak, 19 events
    np.testing.assert_allclose(run.force_N, walk, rtol=0, atol=1e-4 * np.max(np.abs(walk)))


def test_the_band_brake_truth_of_data_is_the_model_with_its_values():
    # data/generate_band_brake.py's truth (tests/references/band_brake.py, typed from the laws with
    # scipy's brentq) walked on the samples is kelvin_voigt+band+rig with the same values
    import sys
    from conftest import REPO
    sys.path.insert(0, str(REPO / "tests" / "references"))
    import band_brake
    p = band_brake.PARAMETERS
    t = np.arange(0.0, 3.0, 2e-3)
    t, x, v = path(3.5 * np.sin(2 * np.pi * 1.0 * t) * np.minimum(t, 1.0), dt=2e-3)
    arriving = np.concatenate([v[:1], v[:-1]])      # the walk reports each sample's force at the step's v
    truth = band_brake.force(p, t, lambda s: (np.interp(s, t, x), np.interp(s, t, arriving)), substeps=1)
    params = dict(k=p["k0"], c=p["c"], preload=0.0, band_gap=p["gap"], band_k=p["kc"], band_depth=p["d"],
                  band_f=p["f"], band_ratio_pos=p["r_pos"], band_ratio_neg=p["r_neg"], band_travel=p["S"],
                  rig_displacement_zero=0.0, rig_force_zero=p["b"])
    model = simulate_python_core(params, t, x, v, model="kelvin_voigt+band+rig")
    assert np.max(truth - p["b"]) > p["f"] * p["r_pos"] and np.min(truth - p["b"]) < -p["f"]   # slid both ways
    np.testing.assert_allclose(model, truth, rtol=0, atol=1e-8 * np.max(np.abs(truth)))


@pytest.mark.slow
def test_a_six_axis_fmus_axis_takes_a_band_in_both_fmus(tmp_path):
    # z a Kelvin-Voigt axis with a band
    assert_six_axis_z_is_the_forward_model(get_model("kelvin_voigt+band"), dict(k=300.0, c=1.0, preload=0.0, **BAND),
                                           tmp_path)


FAST = dict(PURE, band_gap=0.0, band_k=1000.0, band_depth=0.0, band_f=1.0, band_ratio_pos=100.0,
            band_ratio_neg=100.0, band_travel=0.1)
"""A level that outgrows the contact: at 100 N it grows at 100 ln(100)/0.1 = 4600 N/mm, the contact 1000 N/mm."""


def ramp_in_continuous_time(s, p):
    """The force [N] of a ramp into the contact (gap 0) at the travels s [mm], exactly: the slider
    slides only where the contact meets the level, so F(s) = min(k s, min over s' <= s of
    L(s') + k (s - s')) (the slip is the largest s' - L(s')/k so far)."""
    k = p["band_k"]
    levels = p["band_f"] * p["band_ratio_pos"] ** (np.minimum(s, p["band_travel"]) / p["band_travel"])
    return np.minimum(k * s, np.minimum.accumulate(levels - k * s) + k * s)


def test_where_the_level_outgrows_the_contact_the_band_sticks_until_the_wrap_is_full():
    t = np.linspace(0.0, 0.3, 30001)                  # 1e-5 mm a step
    t, x, v = path(t, dt=1e-5)
    force = simulate_python_core(FAST, t, x, v, model="kelvin_voigt+band")
    want = ramp_in_continuous_time(x, FAST)
    assert want[-1] == pytest.approx(100.0) and np.any((want < 99.0) & (x > 0.1))   # it stuck below the wrap's level
    np.testing.assert_allclose(force, want, rtol=0, atol=0.05)


def test_model_exchange_where_the_level_outgrows_the_contact(tmp_path):
    # the slide ends at an event where the level outgrows the contact, and the contact catches the
    # level once the wrap is full: as the ramp in continuous time
    import build_fmu
    from model_exchange import simulate_model_exchange
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    model = get_model("kelvin_voigt+band")
    fmu = build_fmu.build_native_fmu(save_parameters(tmp_path / "fast.json", FAST, model.name), tmp_path,
                                     model=model.name).path
    t = np.linspace(0.0, 0.3, 31)
    run = simulate_model_exchange(fmu, t, lambda s: s * 1e-3, lambda s: 1e-3)
    fine = np.linspace(0.0, 0.3, 300001)              # the minimum over the path on a 1e-6 mm grid
    want = np.interp(t, fine, ramp_in_continuous_time(fine, FAST))
    np.testing.assert_allclose(run.force_N, want, rtol=0, atol=1e-3 * 100.0)
