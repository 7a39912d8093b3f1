"""A record without steady cycles (an earthquake, a random road) has no repeatability of its own:
its floor is its noise, and the report sets its NRMSE beside what the device repeats on its sines."""
import numpy as np
import pytest

from identification.analysis.compare import general_excitation_lines
from identification.fitting.result import RigTestFit, general_excitation_notes, sines_repeatability
from identification.measured.measurements import Measurement
from identification.measured.noise import NoiseEstimate
from identification.measured.repeatability import Repeatability


def _fit(name, kind, nrmse, repeat=None):
    repeatability = Repeatability(repeat * 1000.0, 1000.0, 1.0, 3) if repeat is not None else None
    return RigTestFit(name, kind, NoiseEstimate(2.0, 1000.0), nrmse, repeatability)


def test_a_record_without_cycles_is_set_beside_what_the_sines_repeat():
    tests = [_fit("a.csv", "sine", 0.08, 0.05), _fit("b.csv", "sine", 0.09, 0.07), _fit("quake.csv", "random", 0.30)]
    assert sines_repeatability(tests) == pytest.approx(0.06, rel=1e-12)
    notes = general_excitation_notes(tests)
    assert notes == ["note: quake.csv has no steady cycles to repeat: its floor is its noise (0.20%); 5x what the "
                     "device repeats on its sines (6.00%)"]


def test_without_sines_the_note_says_the_noise_alone():
    (note,) = general_excitation_notes([_fit("quake.csv", "random", 0.30)])
    assert note.endswith("its floor is its noise (0.20%)")


def test_compare_sets_each_models_held_out_earthquake_beside_the_sines():
    t = np.arange(2000) * 1e-3
    rng = np.random.default_rng(0)
    quake = Measurement(t, np.cumsum(rng.normal(0.0, 0.01, t.size)), rng.normal(0.0, 1.0, t.size), np.zeros(t.size),
                        source="quake.csv")
    sine = Measurement(t, np.sin(2 * np.pi * 5 * t), np.sin(2 * np.pi * 5 * t), np.zeros(t.size), source="sine.csv")
    errors = {("quake.csv", "a"): (0.3, 0.0), ("quake.csv", "b"): (0.12, 0.0)}
    lines = general_excitation_lines([sine, quake], errors, ["a", "b"], 0.06)
    assert lines == ["quake.csv has no steady cycles (its floor is its noise); against what the device repeats on the "
                     "training sines (6.00%): a 5x, b 2x"]
