"""The rounding variants CI runs the optimizer tests under do what they say (tests/suite_options.py)."""
import numpy as np

from conftest import DATA
from identification.fitting import search
from identification.measured.measurements import load_measurement
from identification.measured.rig_tests import RigTest
from suite_options import rounding_variant


class Options:
    """A pytest config that answers the suite's options."""

    def __init__(self, perturb=0.0, seed_offset=0):
        self.values = {"--perturb-force": perturb, "--seed-offset": seed_offset}

    def getoption(self, name):
        return self.values[name]


def test_forces_are_perturbed_at_the_level_asked_and_only_inside_the_variant():
    m = load_measurement(DATA / "synthetic_table5_sine_2mm_10Hz.csv")
    with rounding_variant(Options(perturb=1e-12)):
        perturbed = RigTest(m, "sine").measurement.force_N
    plain = RigTest(m, "sine").measurement.force_N
    assert np.array_equal(plain, m.force_N)
    relative = perturbed[m.force_N != 0] / m.force_N[m.force_N != 0] - 1.0
    assert 3e-13 < np.std(relative) < 3e-12 and np.count_nonzero(relative) > 0.9 * relative.size


def test_every_fit_seed_is_offset_inside_the_variant_only(monkeypatch):
    seeds = []
    monkeypatch.setattr(search, "begin", lambda request, engine, progress, started: seeds.append(request.seed))

    def request(seed):
        return search.SearchRequest([], [], None, "default", None, seed)
    with rounding_variant(Options(seed_offset=2)):
        search.begin(request(5), None, True, 0.0)
        search.begin(request=request(0), engine=None, progress=True, started=0.0)
    search.begin(request(5), None, True, 0.0)
    assert seeds == [7, 2, 5]


def test_without_options_nothing_changes():
    m = load_measurement(DATA / "synthetic_table5_sine_2mm_10Hz.csv")
    begin = search.begin
    with rounding_variant(Options()):
        assert search.begin is begin and np.array_equal(RigTest(m, "sine").measurement.force_N, m.force_N)
