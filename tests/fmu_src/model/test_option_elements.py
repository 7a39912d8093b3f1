"""The option elements' table (fmu_src.model.options): discovered from their modules, named in one
order, refused clearly; and a new element, defined here as a module would define it, composes
with the others without touching them: a Jenkins element (a spring in series with a Coulomb
slider) beside the Maxwell element on a Kelvin-Voigt base, two elements with states, against the
three written out with numpy."""
from __future__ import annotations

import sys

import numpy as np
import pytest

from fmu_src.model import derived, options as option_table
from fmu_src.model.definition import SearchCoordinate
from fmu_src.model.derived import split_name
from fmu_src.model.options import Options
from fmu_src.model.options.element import ElementState, OptionElement, Step
from fmu_src.model.parameter_specs import ParameterError, ParameterSpec
from fmu_src.model.registry import get_model
from fmu_src.model.search_coordinates import KIND
from python_core import simulate_python_core


def test_the_table_holds_the_options_in_their_order():
    assert list(option_table.ELEMENTS) == ["backbone", "limits", "maxwell", "iwan", "band", "series", "rig", "wlf", "arrhenius", "heating"]
    assert Options.parse(["Rig", "maxwell", "backbone5", "LIMITS"]).tokens == ("backbone5", "limits", "maxwell", "rig")


def test_every_option_round_trips_through_a_name_and_an_identifier():
    for token in ("backbone3", "limits", "maxwell", "iwan2", "band", "series", "rig"):
        model = get_model(f"berg+{token}")
        assert get_model(model.identifier) is model
        assert split_name(model.identifier) == (get_model("berg").identifier, Options.parse([token]))


def test_bad_options_are_refused_with_what_is_allowed():
    with pytest.raises(ParameterError, match=r"unknown model option 'stops'; the options are backbone<K> .*, "
                                             r"limits, maxwell, iwan<N> .*, band, series, rig, wlf, arrhenius and heating"):
        Options.parse(["stops"])
    with pytest.raises(ParameterError, match="backbone40: the count must be 2 to 32"):
        Options.parse(["backbone40"])
    with pytest.raises(ParameterError, match="takes no count"):
        Options((("rig", 3),))
    with pytest.raises(ParameterError, match="backbone5 and backbone7: give one backbone"):
        Options.parse(["backbone5"]).union(Options.parse(["backbone7", "rig"]))
    assert Options.parse(["backbone5"]).union(Options.parse(["backbone5", "rig"])).tokens == ("backbone5", "rig")
    assert Options.parse(["maxwell", "rig"]).without("rig").tokens == ("maxwell",)


JENKINS_SOURCE = '''def jenkins_step(f, k, level, du):
    """The Jenkins element's force [N] after a travel du [mm]: its spring k [N/mm] takes it until
    the slider's level [N]."""
    g = f + k * du
    if g > level:
        return level
    if g < -level:
        return -level
    return g


def jenkins_rate(f, k, level, v):
    """df/dt [N/s] at v [mm/s]: 0 where the slider slides."""
    if (f >= level and v > 0.0) or (f <= -level and v < 0.0):
        return 0.0
    return k * v
'''

JENKINS = OptionElement(
    token="jenkins", word="a Jenkins element", usage="jenkins", order=25,
    specs=lambda count: (ParameterSpec("jenkins_k", "N/mm", "the Jenkins element's spring", minimum=0.0),
                         ParameterSpec("jenkins_level", "N", "the Jenkins element's slip force", minimum=0.0)),
    coordinates=lambda count: (SearchCoordinate("jenkins_k", KIND.stiffness, -4.0, 1.0),),
    helpers=lambda count: JENKINS_SOURCE,
    force=lambda slot: slot.states[0],
    states=lambda count: (ElementState("jenkins_f", "N", "the Jenkins element's force"),),
    jump=lambda slot: (f"jenkins_step({slot.states[0]}, {slot.m}[0], {slot.m}[1], jump_mm)",),
    step=lambda slot: Step((f"g = jenkins_step({slot.states[0]}, {slot.m}[0], {slot.m}[1], v * h)",), ("g",)),
    derivatives=lambda slot: (f"jenkins_rate({slot.states[0]}, {slot.m}[0], {slot.m}[1], v)",),
    neutral=(("jenkins_k", 0.0), ("jenkins_level", 0.0)))


@pytest.fixture
def with_jenkins(monkeypatch):
    monkeypatch.setitem(option_table.ELEMENTS, "jenkins", JENKINS)
    monkeypatch.setattr(derived, "_DERIVED", {})
    yield
    for name in [name for name in sys.modules if "__" in name and "jenkins" in name]:
        del sys.modules[name]


def test_a_new_element_with_a_state_composes_with_the_maxwell_element_as_numpy_says(with_jenkins):
    model = get_model("kelvin_voigt+maxwell+jenkins")
    assert model.name == "kelvin_voigt+jenkins+maxwell"
    assert [s.name for s in model.states][-2:] == ["jenkins_f", "maxwell_f"]
    params = dict(k=120.0, c=0.8, preload=5.0, jenkins_k=300.0, jenkins_level=90.0, maxwell_k=60.0, maxwell_c=3.0)
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 4.0, 1e-3)
    v = np.repeat(rng.normal(0.0, 6.0, t.size // 200), 200)[:t.size]
    x = np.empty_like(t)
    x[0] = 0.0
    for k in range(t.size - 1):         # exactly the path the walk takes: no jumps
        x[k + 1] = x[k] + v[k] * (t[k + 1] - t[k])
    got = simulate_python_core(params, t, x, v, model=model.name)
    # the reference: each element stepped exactly over each interval at its constant velocity
    fj, fm, want = 0.0, 0.0, np.empty_like(t)
    rate = params["maxwell_k"] / params["maxwell_c"]
    want[0] = params["k"] * x[0] + params["c"] * v[0] + params["preload"]
    for k in range(t.size - 1):
        h = t[k + 1] - t[k]
        fj = np.clip(fj + params["jenkins_k"] * v[k] * h, -params["jenkins_level"], params["jenkins_level"])
        fm = fm * np.exp(-rate * h) + params["maxwell_k"] * v[k] * (1.0 - np.exp(-rate * h)) / rate
        want[k + 1] = params["k"] * x[k + 1] + params["c"] * v[k] + params["preload"] + fj + fm
    assert np.max(np.abs(np.diff(np.sign(np.diff(x))))) > 0 and np.max(np.abs(got - params["k"] * x)) > 90.0
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.max(np.abs(want)))
    # its rate (model exchange) is the spring's until the slider slides
    m = model.constants(model.check(params))
    state = model.initial_state(m, 0.0)
    assert model.derivatives(m, state, 0.0, 2.0)[-2:] == pytest.approx((600.0, 120.0))
    sliding = tuple(state[:-2]) + (90.0, 0.0)
    assert model.derivatives(m, sliding, 0.0, 2.0)[-2] == 0.0 and model.derivatives(m, sliding, 0.0, -2.0)[-2] == -600.0
