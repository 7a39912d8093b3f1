"""A new device's first contact (identification.analysis.first_contact, measured.offsets): what
the records show before any fit, the options compare assumes from it, and compare weighing the
recommended model without each of them.

The records are made here with a known centre, rest force and mean force (analytic), or are the
shipped synthetic files shifted by a known stroke and load-cell zero."""
import csv
import math

import numpy as np
import pytest

from conftest import DATA
from identification.__main__ import main
from identification.analysis.first_contact import first_contact
from identification.measured.measurements import Measurement, load_measurement, write_measurement
from identification.measured.offsets import record_offsets, rig_zeros
from identification.measured.rig_tests import RigTest

TABLE5_SINE = DATA / "synthetic_table5_sine_2mm_10Hz.csv"
TABLE5_STEP = DATA / "synthetic_table5_step_2mm_rise0.4s.csv"
VOIDED = {name: DATA / f"synthetic_voided_{name}.csv" for name in ("sine_2mm_5Hz", "sine_3.5mm_1Hz",
                                                                   "triangle_4.2mm_0.05Hz")}
STROKE_MM, LOAD_CELL_N = 2.0, 100.0


def shifted(path, folder):
    """The file read through a one-sided stroke (+2 mm) and a load cell off by +100 N."""
    m = load_measurement(path)
    out = folder / f"{path.stem}_shifted.csv"
    write_measurement(out, m.time_s, m.displacement_mm + STROKE_MM, m.force_N + LOAD_CELL_N)
    return out


def resting_sine(rest_s=0.5, centre=3.0, amplitude=2.0, rest_force=-250.0, mean_force=40.0):
    """A 5 Hz sine about ``centre`` [mm] after ``rest_s`` at rest at its start value, its force
    ``rest_force`` [N] at rest and a sine about ``mean_force`` after: every offset known."""
    t = np.arange(0.0, rest_s + 2.0, 1e-3)
    moving = t >= rest_s
    phase = 2 * np.pi * 5.0 * (t - rest_s)
    x = np.where(moving, centre - amplitude * np.cos(phase), centre - amplitude)
    force = np.where(moving, mean_force - 500.0 * np.cos(phase), rest_force)
    return Measurement(t, x, force, np.gradient(x, t), source="resting_sine.csv")


def test_a_record_shows_its_stroke_centre_rest_force_and_mean_force():
    offsets = record_offsets(resting_sine())
    assert offsets.centre_mm == pytest.approx(3.0, abs=1e-9)
    assert offsets.half_range_mm == pytest.approx(2.0, abs=1e-9)
    assert offsets.one_sided == pytest.approx(1.5, abs=1e-9)
    assert offsets.rest_force_N == pytest.approx(-250.0) and offsets.rest_s == pytest.approx(0.5, abs=5e-3)
    assert offsets.cycle_mean_force_N == pytest.approx(40.0, abs=0.5)   # whole cycles only
    assert offsets.frequency_hz == pytest.approx(5.0, rel=1e-3) and not offsets.quasi_static


def test_a_record_that_starts_moving_has_no_rest_force():
    assert math.isnan(record_offsets(resting_sine(rest_s=0.0)).rest_force_N)


def test_a_rest_too_short_to_count_is_named_in_the_fits_notes_and_a_long_one_is_held():
    from fmu_src.model.registry import get_model
    from identification.fitting.search import resting_notes
    from identification.measured.offsets import held_force, short_rest
    brief, long = resting_sine(rest_s=0.01), resting_sine(rest_s=0.5)      # 11 samples at rest, and 501
    force, rest_s = short_rest(brief)
    assert math.isnan(held_force(brief)) and force == pytest.approx(-250.0) and rest_s == pytest.approx(0.01, abs=5e-3)
    assert held_force(long) == pytest.approx(-250.0) and short_rest(long) is None
    assert short_rest(resting_sine(rest_s=0.0)) is None
    model = get_model("asymmetric_bouc_wen")
    notes = resting_notes([RigTest(brief), RigTest(long)], [held_force(brief), held_force(long)], model)
    assert "resting_sine.csv starts at -250 N but rests only" in notes[0] and "starts it relaxed" in notes[0]
    assert "holds -250 N at rest before it moves" in notes[1]
    # a slow sine from its turning point lingers there for 28 ms at 0.5 Hz: not a rest
    t = np.arange(0.0, 4.0, 1e-3)
    turning = Measurement(t, 2.0 * np.cos(np.pi * t), 100.0 * np.cos(np.pi * t), -2.0 * np.pi * np.sin(np.pi * t))
    assert resting_notes([RigTest(turning, "sine")], [held_force(turning)], model) == []


def test_the_rig_zeros_are_the_periodic_records_centres_else_the_rests():
    sine = record_offsets(resting_sine())
    assert rig_zeros([sine]) == pytest.approx((3.0, 40.0), abs=0.5)
    step = record_offsets(resting_sine(rest_s=1.0, rest_force=75.0))
    assert rig_zeros([step], steps=[True]) == pytest.approx((1.0, 75.0))
    assert rig_zeros([]) == (0.0, 0.0)


def test_centred_tests_assume_nothing():
    tests = [RigTest(load_measurement(TABLE5_SINE), "sine"), RigTest(load_measurement(TABLE5_STEP), "step", 0.4)]
    assert first_contact(tests).assumptions == ()


def test_a_one_sided_stroke_and_a_load_cell_zero_assume_the_rig(tmp_path):
    tests = [RigTest(load_measurement(shifted(TABLE5_SINE, tmp_path)), "sine"),
             RigTest(load_measurement(shifted(TABLE5_STEP, tmp_path)), "step", 0.4)]
    contact = first_contact(tests)
    assert contact.tokens == ("rig",)
    assert "one-sided" in contact.assumptions[0].reason and "+2 mm" in contact.assumptions[0].reason
    assert "--options none" in contact.format()


def test_a_force_at_rest_assumes_the_rig():
    contact = first_contact([RigTest(resting_sine(centre=0.0, amplitude=2.0, mean_force=0.0), "sine")])
    assert contact.tokens == ("rig",) and "holds -250 N at rest" in contact.assumptions[0].reason


def test_the_voided_bushing_with_its_slow_triangle_assumes_a_backbone_a_maxwell_element_and_the_rig():
    # the options its benchmark named by hand (docs/benchmarks.md, voided bushing): the 9-knot cubic
    # misses its void's corner and stop, and its 5 Hz sine is stiffer than the static curve
    tests = [RigTest(load_measurement(VOIDED[name]), "sine") for name in ("sine_2mm_5Hz", "sine_3.5mm_1Hz")]
    triangle = RigTest(load_measurement(VOIDED["triangle_4.2mm_0.05Hz"]))
    assert sorted(first_contact(tests, triangle).tokens) == ["backbone17", "maxwell", "rig"]
    # the same when the triangle is a training test: it is recognised as quasi-static
    contact = first_contact([*tests, triangle])
    assert sorted(contact.tokens) == ["backbone17", "maxwell", "rig"] and contact.static_test.name == triangle.name


def test_compare_says_what_it_assumed_and_weighs_the_model_without_it(tmp_path, capsys):
    sine = shifted(TABLE5_SINE, tmp_path)
    out = tmp_path / "compare"
    assert main(["compare", "--sine", str(sine), "--models", "single_bouc_wen", "--screening", "32", "--starts", "2",
                 "--no-ensemble", "--quiet", "--workers", "1", "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert "assumed: rig: the stroke of" in printed.out and "assumed: rig" in printed.err
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    assert set(rows) == {"single_bouc_wen+rig", "single_bouc_wen"}
    assert (out / "params_single_bouc_wen+rig.json").is_file() and (out / "params_single_bouc_wen.json").is_file()
    assert sum(row["recommended"] == "True" for row in rows.values()) == 1


def test_compare_with_options_none_assumes_nothing(tmp_path, capsys):
    sine = shifted(TABLE5_SINE, tmp_path)
    out = tmp_path / "compare"
    assert main(["compare", "--sine", str(sine), "--models", "kelvin_voigt", "--options", "none", "--no-ensemble",
                 "--quiet", "--out", str(out)]) == 0
    assert "assumed" not in capsys.readouterr().out
    with open(out / "comparison.csv") as handle:
        assert [row["model"] for row in csv.DictReader(handle)] == ["kelvin_voigt"]


def test_the_rig_zeros_are_searched_about_the_records_centre_on_the_centred_scales(tmp_path):
    # the box of proposed+rig on the shifted files is the box of the proposed model on the
    # original ones, its rig's zeros searched about (+2 mm, +100 N)
    from fmu_src.model.registry import get_model
    from identification.fitting.search_space import SearchSpace
    original = [load_measurement(TABLE5_SINE), load_measurement(TABLE5_STEP)]
    moved = [load_measurement(shifted(path, tmp_path)) for path in (TABLE5_SINE, TABLE5_STEP)]
    plain = SearchSpace.from_measurements(original, "proposed", steps=[False, True])
    rig = SearchSpace.from_measurements(moved, get_model("proposed+rig"), steps=[False, True])
    assert rig.x_zero == pytest.approx(STROKE_MM, abs=1e-3)
    # the centred sine's whole cycles average -18 N (its long relaxation from rest): an estimate, a box's centre
    assert rig.F_zero == pytest.approx(LOAD_CELL_N, abs=0.01 * rig.F_ref)
    for scale in ("k_ref", "c_ref", "F_ref", "x_ref"):
        assert getattr(rig, scale) == pytest.approx(getattr(plain, scale), rel=0.02), scale
    names = list(rig.names)
    centre = np.zeros((1, len(names)))
    values = rig.to_model_parameters(centre)[0]
    parameters = dict(zip(rig.bushing.parameter_names, values))
    assert parameters["rig_displacement_zero"] == pytest.approx(rig.x_zero)
    assert parameters["rig_force_zero"] == pytest.approx(rig.F_zero)
    assert SearchSpace.from_measurements(original, "proposed", steps=[False, True]).x_zero == 0.0


def test_compare_scores_the_recommended_model_leaving_each_test_out(tmp_path, capsys):
    # two sines of the filled rubber: each predicted by the model fitted to the other
    filled = DATA / "synthetic_filled_rubber"
    out = tmp_path / "compare"
    assert main(["compare", "--sine", f"{filled}_sine_2mm_10Hz.csv", "--sine", f"{filled}_sine_0.5mm_3Hz.csv",
                 "--models", "kelvin_voigt", "--leave-one-out", "--no-ensemble", "--quiet", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "leave-one-out: kelvin_voigt fitted to the training tests but one" in printed
    with open(out / "leave_one_out.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert [row["test"] for row in rows] == ["synthetic_filled_rubber_sine_2mm_10Hz.csv",
                                             "synthetic_filled_rubber_sine_0.5mm_3Hz.csv"]
    # a linear fit to one amplitude misses the other more than the fit to both does
    assert all(float(row["left_out_nrmse"]) > float(row["training_nrmse"]) for row in rows)


def test_several_records_offsets_are_said_once_with_their_range(tmp_path):
    sine = load_measurement(shifted(TABLE5_SINE, tmp_path))
    other = Measurement(sine.time_s, sine.displacement_mm + 1.0, sine.force_N, sine.velocity_mm_s, source="b.csv")
    (rig,) = first_contact([RigTest(sine, "sine"), RigTest(other, "sine")]).assumptions
    assert rig.reason.startswith("the strokes of 2 sines are one-sided (centred at +2 to +3 mm)")


def test_a_loops_dissipation_is_one_for_coulombs_friction_and_pi_over_4_sin_delta_for_a_linear_element():
    from identification.analysis.first_contact import loop_dissipation
    t = np.arange(0.0, 3.0, 1e-4)
    x, v = 2.0 * np.sin(2 * np.pi * 2.0 * t), 4.0 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * t)
    coulomb = Measurement(t, x, 300.0 * np.sign(v), v)
    assert loop_dissipation(coulomb) == pytest.approx(1.0, abs=2e-3)
    k, c = 100.0, 3.0                                   # tan(delta) = c*omega/k
    delta = math.atan(c * 4.0 * np.pi / k)
    assert loop_dissipation(Measurement(t, x, k * x + c * v, v)) == pytest.approx(math.pi / 4 * math.sin(delta),
                                                                                   rel=2e-3)


def test_the_first_contact_tries_the_band_where_the_loops_dissipate_as_friction_does():
    band = [RigTest(load_measurement(DATA / f"synthetic_band_sine_{n}.csv"), "sine") for n in ("2.5mm_0.5Hz", "4mm_2Hz")]
    contact = first_contact(band)
    assert contact.tried == ("band",) and "dissipate 0.54" in contact.format()
    assert first_contact([RigTest(load_measurement(TABLE5_SINE), "sine")]).tried == ()


def test_compare_weighs_each_tried_option_on_the_recommended_model(tmp_path, capsys):
    # the synthetic band brake (a play, a self-energizing friction, a load-cell zero of +60 N):
    # Kelvin-Voigt with the rig assumed, then with the band tried; the band earns its parameters
    sines = [DATA / f"synthetic_band_sine_{name}.csv" for name in ("2.5mm_0.5Hz", "4mm_2Hz")]
    out = tmp_path / "compare"
    assert main(["compare", *[a for s in sines for a in ("--sine", str(s))], "--models", "kelvin_voigt",
                 "--try-options", "band", "--screening", "64", "--starts", "2", "--no-ensemble", "--quiet",
                 "--workers", "1", "--out", str(out)]) == 0
    assert "option tried added" in capsys.readouterr().err
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    assert {"kelvin_voigt+rig", "kelvin_voigt+band+rig"} <= set(rows)
    assert rows["kelvin_voigt+band+rig"]["recommended"] == "True"


def test_a_tried_option_that_is_not_one_is_refused_before_any_work(tmp_path, capsys):
    assert main(["compare", "--sine", str(TABLE5_SINE), "--models", "kelvin_voigt", "--try-options", "iwan0",
                 "--out", str(tmp_path / "c")]) == 2
    printed = capsys.readouterr().err
    assert "--try-options iwan0: iwan0: the count must be 1 to 16" in printed and "assumed" not in printed
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("extra", [[], ["--try-options", "none"]])
def test_compare_tries_what_the_first_contact_tries_unless_told(tmp_path, capsys, extra):
    sines = [DATA / f"synthetic_band_sine_{name}.csv" for name in ("2.5mm_0.5Hz", "4mm_2Hz")]
    out = tmp_path / "compare"
    assert main(["compare", *[a for s in sines for a in ("--sine", str(s))], "--models", "kelvin_voigt", *extra,
                 "--screening", "64", "--starts", "2", "--no-ensemble", "--quiet", "--workers", "1",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr()
    with open(out / "comparison.csv") as handle:
        rows = {row["model"]: row for row in csv.DictReader(handle)}
    assert {"kelvin_voigt+rig", "kelvin_voigt"} <= set(rows)        # the rig assumed, weighed without it
    if extra:
        assert "kelvin_voigt+band+rig" not in rows
        assert "tried: band" not in printed.out + printed.err      # what is named is what is said
    else:
        assert "tried: band" in printed.out + printed.err
        assert rows["kelvin_voigt+band+rig"]["recommended"] == "True"


def test_a_static_curve_gives_every_model_its_backbone_held_at_the_curve():
    from fmu_src.model.options import Options
    from identification.cli.model_options import build_model_options
    triangle = load_measurement(VOIDED["triangle_4.2mm_0.05Hz"])
    options = build_model_options(Options.parse(["backbone9", "rig"]), {}, triangle)
    assert options.options.tokens == ("backbone9", "rig")
    knots = [options.fixed[f"backbone_x{i}"] for i in range(1, 10)]
    assert all(b > a for a, b in zip(knots, knots[1:])) and {f"backbone_F{i}" for i in range(1, 10)} <= set(options.fixed)
    assert options.fixed["rig_displacement_zero"] == 0.0
    # knots given, no backbone named: the backbone takes their count
    given = build_model_options(Options.parse(["maxwell"]), {}, triangle, knots=[-3.0, 0.0, 3.0])
    assert given.options.tokens == ("backbone3", "maxwell")
    assert [given.fixed[f"backbone_x{i}"] for i in (1, 2, 3)] == [-3.0, 0.0, 3.0]


@pytest.mark.slow
def test_compare_on_a_slow_triangle_assumes_its_backbone_and_fits(tmp_path, capsys):
    out = tmp_path / "compare"
    assert main(["compare", "--sine", str(VOIDED["triangle_4.2mm_0.05Hz"]), "--sine", str(VOIDED["sine_2mm_5Hz"]),
                 "--models", "kelvin_voigt", "--screening", "32", "--starts", "2", "--no-ensemble", "--quiet",
                 "--workers", "1", "--out", str(out)]) == 0
    assert "assumed: backbone" in capsys.readouterr().out
    with open(out / "comparison.csv") as handle:
        assert any(row["model"].startswith("kelvin_voigt+backbone") for row in csv.DictReader(handle))


def test_the_band_is_not_tried_where_the_dissipation_depends_on_the_rate():
    # a dashpot's loops dissipate much of 4 F x, but twice the share at twice the frequency: not friction
    def viscous(hz):
        t = np.arange(0.0, 4.0 / hz, 1e-3)
        x, v = 2.0 * np.sin(2 * np.pi * hz * t), 4.0 * np.pi * hz * np.cos(2 * np.pi * hz * t)
        return RigTest(Measurement(t, x, 100.0 * x + 5.0 * v, v, source=f"viscous_{hz}Hz.csv"), "sine")
    one, two = viscous(1.0), viscous(2.0)
    assert first_contact([two]).tried == ("band",)            # one sine alone does not tell
    assert first_contact([one, two]).tried == ()
    from identification.measured.kdyn_table import load_kdyn_table
    sheet = load_kdyn_table(DATA / "kdyn_synthetic_hydraulic_train.csv")        # its loss angle peaks over frequency
    hydraulic = RigTest(load_measurement(DATA / "synthetic_hydraulic_sine_1mm_8Hz.csv"), "sine")
    assert first_contact([hydraulic]).tried == ("band",) and first_contact([hydraulic], None, sheet).tried == ()
