"""A backbone read off a quasi-static test (identification.measured.static_curve), on made-up
tests whose static curve and hysteresis are known by construction."""
import numpy as np
import pytest

from identification.errors import MeasurementError
from identification.measured.measurements import Measurement
from identification.measured.static_curve import default_knots, read_static_curve


def measured(t, x, force, source):
    return Measurement(t, x, force, np.gradient(x, t), velocity_derived=True, source=source)


def static(x):
    """A voided bushing's curve: soft below 0, stiffer above, with a cubic."""
    return np.where(x < 0.0, 150.0 * x, 400.0 * x) + 10.0 * x ** 3


def triangle_test(amplitude=4.0, cycles=2, friction=60.0, noise=0.0, seed=0):
    """A slow triangle: the static curve plus a friction of +-``friction`` N by direction."""
    t = np.linspace(0.0, 20.0 * cycles, 4000 * cycles + 1)
    phase = np.mod(t / 20.0 + 0.25, 1.0)
    x = np.where(phase < 0.5, -1.0 + 4.0 * phase, 3.0 - 4.0 * phase) * amplitude
    force = static(x) + friction * np.sign(np.gradient(x, t)) + np.random.default_rng(seed).normal(0.0, noise, t.size)
    return measured(t, x, force, "triangle.csv")


def test_the_backbone_is_the_mean_of_the_branches_and_the_half_difference_the_friction():
    curve = read_static_curve(triangle_test(), knots_mm=[-3.0, -1.0, 0.0, 1.0, 3.0])
    # each knot's window averages the curve over +-0.05 of the knot spacing: at the corner at 0
    # (250 N/mm more above than below) that reads 250*0.05/4 = 3.1 N high, elsewhere the cubic's 0.1 N
    np.testing.assert_allclose(curve.forces_N, static(curve.knots_mm), atol=3.5)
    np.testing.assert_allclose(curve.half_width_N, 60.0, atol=0.5)
    assert not curve.adjusted and curve.force_at_zero == pytest.approx(250.0 * 0.05 / 4.0, abs=0.3)
    assert curve.parameters()["backbone_x3"] == 0.0 and len(curve.parameters()) == 10


def test_noise_that_makes_the_forces_decrease_is_made_monotone():
    # a flat stretch of the curve read with noise: the isotonic regression keeps it monotone
    test = triangle_test(noise=40.0, seed=3)
    test = measured(test.time_s, test.displacement_mm, test.force_N - static(test.displacement_mm)
                    + 1e-3 * test.displacement_mm, "flat.csv")
    curve = read_static_curve(test, count=15)
    assert np.all(np.diff(curve.forces_N) >= 0.0)
    assert curve.adjusted and "made monotone" in curve.describe()


def test_pinned_at_zero_the_forces_are_relative_to_the_knot_at_zero():
    offset = triangle_test()
    offset = measured(offset.time_s, offset.displacement_mm, offset.force_N + 40.0, "offset.csv")
    curve = read_static_curve(offset)
    pinned = curve.parameters(pinned_at_zero=True)
    zero = next(i for i, x in enumerate(curve.knots_mm) if x == 0.0)
    assert pinned[f"backbone_F{zero + 1}"] == 0.0
    # 9 knots over +-4 mm, 2 % in from its ends, are 0.96 mm apart: the corner at 0 reads 250*0.05*0.96/4 N high
    assert curve.force_at_zero == pytest.approx(40.0 + 250.0 * 0.05 * 0.96 / 4.0, abs=0.3)


def test_the_default_knots_spread_over_the_range_one_at_zero():
    knots = default_knots(-4.0, 4.0, 9)
    assert knots.size == 9 and 0.0 in knots and np.all(np.diff(knots) > 0.0)
    assert knots[0] == pytest.approx(-3.84) and knots[-1] == pytest.approx(3.84)


def test_a_test_that_moves_one_way_or_knots_outside_it_are_refused_with_the_reason():
    t = np.linspace(0.0, 10.0, 1001)
    with pytest.raises(MeasurementError, match="load and unload"):
        read_static_curve(measured(t, t, 100.0 * t, "ramp.csv"))
    with pytest.raises(MeasurementError, match=r"knot at 6 mm.*covers -4 to 4 mm both ways"):
        read_static_curve(triangle_test(), knots_mm=[-2.0, 0.0, 6.0])
    with pytest.raises(MeasurementError, match="increasing"):
        read_static_curve(triangle_test(), knots_mm=[1.0, 0.0])
