"""The free-plate hydraulic mount (fmu_src/models/hydraulic_free_decoupler_model.py) against its
independent references: the linear closed form without free travel
(tests/references/hydraulic_closed_form.py), the plate's balance solved by scipy's brentq and the
whole mount solved by scipy's Radau (tests/references/free_decoupler_mount.py, numpy and scipy
only), and the physics a free plate must show: inside its gap the fluid path lets go.
"""
import importlib.util
import json
import re
from pathlib import Path

import numpy as np
import pytest

from fmu_src.model.registry import MODELS

REFERENCES = Path(__file__).resolve().parents[2] / "references"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, REFERENCES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)         # numpy and scipy only; nothing of the project
    return module


closed_form = _load("hydraulic_closed_form")
mount = _load("free_decoupler_mount")

MODEL = "hydraulic_free_decoupler"
DEFAULTS = {name: float(value) for name, value in json.loads(
    (Path(__file__).resolve().parents[3] / "data" / "params_hydraulic_free_decoupler.json").read_text())
    ["parameters"].items()}
"""data/params_hydraulic_free_decoupler.json as plain JSON: the track tuned to 9.98 Hz, a plate free
within +-0.12 mm, its 2000 N/mm cage engaging over 0.005 mm, centred by 5 N/mm."""
LINEAR = dict(DEFAULTS, gap=0.0, ct=0.0, k3=0.0)
HARD = dict(DEFAULTS, width=0.0)


def plate_equations_in_the_frequency_domain(p, frequency_hz):
    """K* [N/mm] of the linear mount (gap = 0, ct = 0, k3 = 0) by solving its equations with the
    plate's balance as an unknown of its own, typed apart from the closed form: unknowns
    (Y, W, F1, U) with i*omega*Y = W, i*omega*mf*W = kb*(X - Y) - kc*Y - (kb + kc)*U - cf*W,
    (i*omega + k1/c1)*F1 = i*omega*k1*X and 0 = kb*(X - Y) - kc*Y - (kb + kc + kd + kcage)*U,
    at X = 1; F = k0 + i*omega*c0 + F1 + kb*(1 - Y - U)."""
    kb, kc, kd, kcage = p["kb"], p["kc"], p["kd"], p["kcage"]
    result = []
    for f in np.atleast_1d(frequency_hz):
        s = 2j * np.pi * f
        A = np.array([[s, -1.0, 0.0, 0.0],
                      [kb + kc, s * p["mf"] + p["cf"], 0.0, kb + kc],
                      [0.0, 0.0, s + p["k1"] / p["c1"], 0.0],
                      [kb + kc, 0.0, 0.0, kb + kc + kd + kcage]])
        b = np.array([0.0, kb, s * p["k1"], kb])
        Y, W, F1, U = np.linalg.solve(A, b)
        result.append(p["k0"] + s * p["c0"] + F1 + kb * (1.0 - Y - U))
    return np.array(result)


def test_closed_form_is_the_plate_equations_solved_in_the_frequency_domain():
    frequencies = np.logspace(-3.0, 3.0, 241)
    rng = np.random.default_rng(12)
    sets = [LINEAR] + [{name: value * rng.uniform(0.2, 5.0) for name, value in LINEAR.items()} for _ in range(20)]
    worst = max(np.max(np.abs(closed_form.free_decoupler_complex_stiffness(p, frequencies)
                              / plate_equations_in_the_frequency_domain(p, frequencies) - 1.0)) for p in sets)
    assert worst <= 1e-12                                   # observed 2026-11-27: 7e-15
    # an ever stiffer cage is the mount without decoupler
    rigid = closed_form.free_decoupler_complex_stiffness(dict(LINEAR, kcage=1e12), frequencies)
    np.testing.assert_allclose(rigid, closed_form.complex_stiffness(LINEAR, frequencies), rtol=1e-8)


def test_characterise_equals_the_closed_form_without_free_travel():
    # as the membrane mount's issue-43 target: within 1e-4 in |K*| and 0.01 deg from 0.5 to 100 Hz
    from identification.forward.dynamic_stiffness import characterise
    frequencies = np.array([0.5, 1.0, 3.0, 5.0, 8.0, 10.0, 12.0, 20.0, 50.0, 100.0])
    sheet = characterise(LINEAR, amplitudes_mm=(1.0,), frequencies_hz=frequencies, model=MODEL)
    expected = closed_form.free_decoupler_complex_stiffness(LINEAR, frequencies)
    assert sheet.converged.all()
    np.testing.assert_allclose(sheet.kdyn_N_per_mm, np.abs(expected), rtol=1e-4)
    np.testing.assert_allclose(sheet.loss_angle_deg, np.degrees(np.angle(expected)), rtol=0, atol=0.01)


def test_the_rounded_cage_tends_to_the_hard_cage_solved_by_brentq():
    # the model's plate travel (its fluid-path force, read back) against the hard cage's balance
    # solved by brentq, over pressures inside and far beyond the free travel: the rounding moves the
    # plate by at most log(2)*kcage/(K + kcage)*width (where the softplus is log 2 off its corner)
    from fmu_src.model.elements import track_force
    pressures = np.linspace(-400.0, 400.0, 801)
    hard = np.array([mount.plate_travel(HARD, pressure) for pressure in pressures])
    K = HARD["kb"] + HARD["kc"] + HARD["kd"]
    for width in (1e-2, 1e-3, 1e-5, 0.0):
        constants = MODELS[MODEL].constants(dict(HARD, width=width))
        kb, kc, decoupler = constants[5], constants[6], constants[10]
        x = pressures / kb                                    # y = 0: P = kb*x
        travel = np.array([x_i - track_force(kb, kc, decoupler, 0.0, x_i)[0] / kb for x_i in x])
        bound = np.log(2.0) * HARD["kcage"] / (K + HARD["kcage"]) * width
        assert np.max(np.abs(travel - hard)) <= bound * (1.0 + 1e-6) + 1e-13, width


@pytest.mark.parametrize("params, amplitude_mm, frequency_hz", [
    (HARD, 0.05, 8.0),          # inside the free travel: the plate takes the volume
    # on and off the cage each cycle, below the resonance; the rounded cage, on it for most of the
    # cycle, at the resonance: 10-13 s each, in the slow tier (the README's command stays short)
    pytest.param(HARD, 0.3, 7.0, marks=pytest.mark.slow),
    pytest.param(DEFAULTS, 1.0, 9.0, marks=pytest.mark.slow),
])
def test_the_data_sheet_follows_the_mount_solved_by_scipy(params, amplitude_mm, frequency_hz):
    # the model's steady first harmonic (characterise: the compiled path, 256 steps a cycle,
    # settling 2 s) against Radau's (rtol 1e-10) on the continuous sine, settled 4 s
    from identification.forward.dynamic_stiffness import characterise
    expected = mount.steady_stiffness(params, amplitude_mm, frequency_hz)
    sheet = characterise(params, amplitudes_mm=(amplitude_mm,), frequencies_hz=[frequency_hz], model=MODEL)
    assert sheet.kdyn_N_per_mm[0] == pytest.approx(abs(expected), rel=2e-4)        # observed <= 3.1e-5
    assert sheet.loss_angle_deg[0] == pytest.approx(np.degrees(np.angle(expected)), abs=0.01)   # observed 0.003


def test_inside_its_gap_the_fluid_path_lets_go():
    # 0.05 mm at 8 Hz moves the plate (P ~ 12 N against K*gap = 33.6 N) and hardly the fluid: the
    # mount is the rubber with the bulge in series with the bellows and the plate's centring
    # spring side by side (u = P/K), the loss angle the rubber's;
    # at 1 mm the plate rests on its cage and the column pumps near its resonance
    from identification.forward.dynamic_stiffness import characterise
    p, omega = DEFAULTS, 2.0 * np.pi * 8.0
    decoupled = (p["k0"] + 1j * omega * p["c0"] + p["k1"] * 1j * omega * p["c1"] / (p["k1"] + 1j * omega * p["c1"])
                 + p["kb"] * (p["kc"] + p["kd"]) / (p["kb"] + p["kc"] + p["kd"]))
    sheet = characterise(p, amplitudes_mm=(0.05, 1.0), frequencies_hz=[8.0], model=MODEL)
    small, large = sheet.amplitude_mm == 0.05, sheet.amplitude_mm == 1.0
    assert sheet.kdyn_N_per_mm[small][0] == pytest.approx(abs(decoupled), rel=0.002)    # observed 235.73 / 235.59
    assert sheet.loss_angle_deg[small][0] == pytest.approx(np.degrees(np.angle(decoupled)), abs=0.1)      # observed 4.53 / 4.52
    assert sheet.loss_angle_deg[large][0] >= 40.0                                         # observed 58.2


def test_switches_are_where_the_plate_meets_its_cage():
    bushing = MODELS[MODEL]
    constants = bushing.constants(HARD)
    free = (HARD["kb"] + HARD["kc"] + HARD["kd"]) * HARD["gap"]
    state, x = (0.2, -3.0, 4.0), 0.5
    pressure = HARD["kb"] * (x - 0.2) - HARD["kc"] * 0.2
    assert bushing.switches(constants, state, x, 1.0) == pytest.approx((pressure - free, pressure + free), rel=1e-14)
    assert bushing.update is None and len(bushing.switch_specs) == 2


@pytest.mark.parametrize("name, value, says", [("gap", -0.12, "gap = -0.12 [mm] must be >= 0"),
                                               ("width", -0.005, "width = -0.005 [mm] must be >= 0"),
                                               ("kcage", -1.0, "kcage = -1.0 [N/mm] must be >= 0")])
def test_a_parameter_file_with_a_negative_travel_width_or_cage_is_refused(tmp_path, name, value, says):
    # the parameter files' reader (the FMUs' refusals are in tests/fmu_src/fmi/test_fmu_baselines.py)
    from fmu_src.parameter_files import load_parameters
    from fmu_src.model.parameter_specs import ParameterError
    document = json.loads((Path(__file__).resolve().parents[3] / "data"
                           / "params_hydraulic_free_decoupler.json").read_text())
    document["parameters"][name] = value
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document))
    with pytest.raises(ParameterError, match=re.escape(says)):
        load_parameters(path, MODEL)
