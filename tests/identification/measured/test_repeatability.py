"""What a sine test repeats from cycle to cycle (identification.measured.repeatability), and the
floor a fit reports with it (identification.fitting.result): on made-up forces whose
non-repeating part is known by construction, and on the real friction damper."""
from pathlib import Path

import numpy as np
import pytest

from identification import load_measurement
from identification.fitting.result import RigTestFit
from identification.measured.noise import NoiseEstimate
from identification.measured.repeatability import Repeatability, cycle_starts, estimate_repeatability

DATA = Path(__file__).resolve().parents[3] / "data"
RATE_HZ = 1000.0


def sine_test(cycles: float, frequency_hz: float = 2.0, ramp_cycles: int = 0, seed: int = 0):
    """(t, x, the force that repeats): a 2 mm sine with ``ramp_cycles`` of linear ramp-in and as
    many of ramp-out, and a force that is a fixed nonlinear function of the phase and the
    displacement (a loop with harmonics)."""
    t = np.arange(0.0, cycles / frequency_hz, 1.0 / RATE_HZ)
    phase = 2 * np.pi * frequency_hz * t
    envelope = np.ones_like(t)
    if ramp_cycles:
        ramp = ramp_cycles / frequency_hz
        envelope = np.clip(np.minimum(t / ramp, (t[-1] - t) / ramp), 0.0, 1.0)
    x = 2.0 * envelope * np.sin(phase)
    force = 800.0 * x + 300.0 * np.cos(phase) * envelope + 120.0 * np.sin(3 * phase) * envelope
    return t, x, force


def test_white_noise_reads_as_its_own_level():
    t, x, force = sine_test(40)
    sigma = 7.0
    measured = force + np.random.default_rng(1).normal(0.0, sigma, t.size)
    r = estimate_repeatability(t, x, measured)
    assert r.differences == 2 and r.groups >= 35
    # linear interpolation of the shifted cycle reads white noise up to 13 % low (here the cycles
    # fall on whole samples, so not at all); 35 x 500 samples scatter by about 1.5 %
    assert 0.95 * sigma < r.sigma_N < 1.05 * sigma, r.sigma_N
    assert r.relative == pytest.approx(r.sigma_N / np.sqrt(np.mean(measured ** 2)))


def test_a_slow_drift_of_the_cycles_is_not_counted_but_chatter_that_changes_every_cycle_is():
    t, x, force = sine_test(20)
    drift = 40.0 * t           # a slow relaxation a model follows: 20 N a cycle
    assert estimate_repeatability(t, x, force + drift).sigma_N < 0.5
    # a 50 Hz chatter whose amplitude changes from cycle to cycle (rms over cycles of a) doesn't repeat
    rng = np.random.default_rng(3)
    cycle = np.floor(t * 2.0).astype(int)
    amplitude = rng.normal(0.0, 60.0, cycle.max() + 1)
    chatter = amplitude[cycle] * np.sin(2 * np.pi * 50.0 * t)
    r = estimate_repeatability(t, x, force + drift + chatter)
    # its rms is 60/sqrt(2) = 42.4 N; second differences of independent cycles read it whole
    assert 0.7 * 42.4 < r.sigma_N < 1.3 * 42.4, r.sigma_N


def test_a_rig_sine_with_ramps_is_read_on_its_cycles_at_full_range_after_the_first():
    # 2 ramp cycles in, 3 at full range, 2 out (as the real damper's sines): one pair, (4th, 5th)
    t, x, force = sine_test(7, ramp_cycles=2)
    sigma = 5.0
    measured = force + np.random.default_rng(2).normal(0.0, sigma, t.size)
    r = estimate_repeatability(t, x, measured)
    assert r.groups == 1 and r.differences == 1 and r.period_s == pytest.approx(0.5, rel=1e-3)
    assert 0.8 * sigma < r.sigma_N < 1.2 * sigma      # 500 samples: about 3 % scatter


def test_noise_on_the_displacement_at_a_crossing_starts_no_second_cycle():
    t, x, _ = sine_test(10)
    noisy = x + np.random.default_rng(4).normal(0.0, 0.02, t.size)     # 1 % of the amplitude
    # the upward crossings after the first trough: at 0.5, 1.0, ... 4.5 s
    assert cycle_starts(t, noisy).size == cycle_starts(t, x).size == 9


@pytest.mark.parametrize("cycles, why", [(2.2, "full cycle(s) in the record"), (3.5, "two consecutive ones")])
def test_too_few_steady_cycles_give_no_repeatability_and_say_why(cycles, why):
    t, x, force = sine_test(cycles)
    r = estimate_repeatability(t, x, force)
    assert not r.known and np.isnan(r.relative) and why in r.reason
    assert "repeatability unknown" in r.describe()


def test_a_displacement_that_does_not_move_has_no_repeatability():
    r = estimate_repeatability(np.arange(100.0), np.zeros(100), np.ones(100))
    assert not r.known and "does not move" in r.reason


def test_the_real_damper_repeats_to_about_five_percent_at_half_a_hertz():
    # the issue's own reading (consecutive steady cycles, rms difference / sqrt(2) over the steady
    # cycles' rms force): 4-6 % at 0.25-0.5 Hz; here over the whole record's rms force
    m = load_measurement(DATA / "brfd" / "sine_0.5Hz30lbtension1amplitude.csv.gz")
    r = estimate_repeatability(m.time_s, m.displacement_mm, m.force_N)
    assert r.groups == 1 and r.period_s == pytest.approx(2.0, rel=2e-3)
    assert 0.045 < r.relative < 0.065, r.relative


def fitted(nrmse: float, repeat_N: float | None, kind: str = "sine") -> RigTestFit:
    noise = NoiseEstimate(10.0, 1000.0)          # 1 %
    repeats = Repeatability(repeat_N, 1000.0, 0.5, 1, differences=1) if repeat_N is not None else None
    return RigTestFit("t.csv", kind, noise, nrmse, repeats)


def test_the_floor_is_what_the_device_repeats_where_that_is_more_than_the_noise():
    fit = fitted(0.065, 50.0)
    assert fit.floor_source == "repeatability" and fit.floor_fraction == pytest.approx(0.05)
    assert fit.ratio == pytest.approx(1.3) and fit.noise_ratio == pytest.approx(6.5) and not fit.at_floor
    d = fit.as_dict()
    assert d["floor"] == "repeatability" and d["nrmse_over_floor"] == pytest.approx(1.3)
    assert d["nrmse_over_noise"] == pytest.approx(6.5) and d["repeatability_fraction"] == pytest.approx(0.05)
    assert fit.floor_words == "what the device repeats"


def test_the_floor_is_the_noise_where_the_device_repeats_better_or_cannot_tell():
    for fit in (fitted(0.012, 8.0), fitted(0.012, float("nan")), fitted(0.012, None, kind="random")):
        assert fit.floor_source == "noise" and fit.floor_fraction == pytest.approx(0.01)
        assert fit.ratio == pytest.approx(1.2) and fit.at_floor and fit.as_dict()["floor"] == "noise"
    assert fitted(0.012, 8.0).as_dict()["repeatability_fraction"] == pytest.approx(0.008)
    assert "repeatability_fraction" not in fitted(0.012, float("nan")).as_dict()
