"""A parameter file written as Altair's .gbs (identification/property_files/export.py) and read
back (gbs.py): the round trips exact (the curve to the bit, export -> import -> export the same
blocks), the damping of a Kelvin-Voigt axis its own c (K''/omega = c for a dashpot), the paper's
Table 5 static force at rest over the range."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import DATA
from fmu_src.model.registry import get_model
from identification.errors import IdentificationError
from identification.property_files.chrono_json import PropertyFileWarning
from identification.property_files.export import OperatingPoint, export_gbs, gbs_text
from identification.property_files.gbs import read_gbs

SIX = DATA / "params_six_axis_illustrative.json"


def imported(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PropertyFileWarning)
        return read_gbs(path)


def test_export_import_export_writes_the_same_blocks(tmp_path):
    from fmu_src.parameter_files import save_six_axis
    point = OperatingPoint(points=17)
    first = export_gbs(SIX, tmp_path / "first.gbs", point)
    back = imported(first)
    again = export_gbs(save_six_axis(tmp_path / "back.json", back.axes, back.provenance), tmp_path / "again.gbs", point)
    blocks = [path.read_text().split("[HEADER]", 1)[1] for path in (first, again)]
    assert blocks[0] == blocks[1]
    assert all(model == "kelvin_voigt+backbone17" for model, _ in back.axes.values())


def test_the_damping_of_a_kelvin_voigt_axis_is_its_own_and_the_curve_reads_back_to_the_bit(tmp_path):
    import json
    document = json.loads(SIX.read_text())
    c_rx = document["axes"]["rx"]["parameters"]["c"]                 # N.mm.s/rad
    k_rx = document["axes"]["rx"]["parameters"]["k"]
    back = imported(export_gbs(SIX, tmp_path / "six.gbs", OperatingPoint(points=9, range_rad=0.05)))
    rx = back.axes["rx"][1]
    assert rx["c"] == pytest.approx(c_rx, rel=1e-9)
    knots = np.linspace(-0.05, 0.05, 9)
    np.testing.assert_array_equal([rx[f"backbone_x{i}"] for i in range(1, 10)], knots)
    np.testing.assert_allclose([rx[f"backbone_F{i}"] for i in range(1, 10)], k_rx * knots, rtol=1e-14, atol=1e-9)


def test_the_paper_table5_fit_exported_on_fz_is_its_static_force_at_rest(tmp_path):
    from fmu_src.parameter_files import read_parameter_set, save_six_axis
    from fmu_src.fmi.axes import SIX_AXES
    table5 = read_parameter_set(DATA / "params_table5_combined.json")
    with pytest.raises(IdentificationError, match="a one-axis parameter file: say which direction"):
        gbs_text(DATA / "params_table5_combined.json")
    back = imported(export_gbs(DATA / "params_table5_combined.json", tmp_path / "fz.gbs", OperatingPoint(points=11),
                               direction="FZ"))
    assert set(back.axes) == set(a.name for a in SIX_AXES) and back.axes["x"][1]["k"] == 0.0
    z_model, z_values = back.axes["z"]
    model = get_model(z_model)
    proposed = table5.model
    constants = proposed.constants(table5.parameters)
    imported_constants = model.constants(model.check(z_values))
    # the imported backbone against the paper's model's force at rest, at the points and between them
    for x in np.linspace(-5.0, 5.0, 41):
        want = proposed.relaxed_force(constants, float(x))
        got = model.relaxed_force(imported_constants, float(x))
        assert abs(got - want) <= 1e-3 * max(abs(want), 1.0) + 1e-9, x
    six = save_six_axis(tmp_path / "fz.json", back.axes, back.provenance)
    assert six.exists()


def test_an_axis_without_damping_exports_none_and_reads_back(tmp_path):
    """A spring alone: its loss stiffness is rounding (about -1e-13), written as 0, not refused."""
    from fmu_src.parameter_files import save_parameters
    spring = save_parameters(tmp_path / "spring.json", dict(k=500.0, c=0.0, preload=0.0), "kelvin_voigt")
    back = imported(export_gbs(spring, tmp_path / "spring.gbs", direction="FX"))
    assert back.axes["x"][1]["c"] == 0.0
    with pytest.raises(IdentificationError, match="is a six-axis file: every direction is written"):
        gbs_text(SIX, direction="FX")


def test_bad_operating_points_are_refused_with_their_unit():
    with pytest.raises(IdentificationError, match=r"frequency_hz = 0.0 \[Hz\] must be a finite number > 0"):
        OperatingPoint(frequency_hz=0.0)
    with pytest.raises(IdentificationError, match="points = 40: 2 to 32"):
        OperatingPoint(points=40)


def test_the_command_line_exports(tmp_path):
    from identification.cli.arguments import main
    assert main(["export", str(SIX), "--points", "5", "--out", str(tmp_path / "six.gbs")]) == 0
    assert "[SPLINE_STIFFNESS_TZ]" in (tmp_path / "six.gbs").read_text()
