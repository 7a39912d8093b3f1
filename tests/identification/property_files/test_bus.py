"""Adams' nonlinear bushing files (identification/property_files/bus.py) on a file hand-written
after the layout the issue describes (tests/fixtures/bus; checked against that description only):
the curves and damping in the project's units (typed here from the file's kN, m and degrees),
the two namings of the damping's keys, refusals."""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import pytest

from identification.errors import IdentificationError
from identification.property_files.bus import read_bus
from identification.property_files.chrono_json import PropertyFileWarning

BUSHING = Path(__file__).resolve().parents[2] / "fixtures" / "bus" / "bushing_after_the_described_layout.bus"


def quiet_read(path=BUSHING):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PropertyFileWarning)
        return read_bus(path)


def test_curves_and_damping_in_the_projects_units():
    axes = quiet_read().axes
    x = axes["x"][1]
    # the file: m, kN; 2 kN.s/m = 2 N.s/mm
    assert axes["x"][0] == "kelvin_voigt+backbone5" and x["c"] == 2.0
    assert [x[f"backbone_x{i}"] for i in range(1, 6)] == pytest.approx([-4.0, -2.0, 0.0, 2.0, 4.0], rel=1e-15)
    assert [x[f"backbone_F{i}"] for i in range(1, 6)] == pytest.approx([-2400.0, -900.0, 0.0, 900.0, 2400.0],
                                                                       rel=1e-15)
    rz = axes["rz"][1]
    # 20 deg, 0.2 kN.m = 2e5 N.mm; 0.02 kN.m.s/deg = 2e4 N.mm.s/deg
    assert rz["backbone_x3"] == pytest.approx(20.0 * math.pi / 180.0, rel=1e-15)
    assert rz["backbone_F3"] == pytest.approx(2e5, rel=1e-15)
    assert rz["c"] == pytest.approx(2e4 * 180.0 / math.pi, rel=1e-15)
    assert axes["z"][1]["c"] == 3.0


def test_the_curves_naming_of_the_damping_and_a_missing_curve(tmp_path):
    text = BUSHING.read_text()
    named = (text.replace("TX = 2.0     $ kN.s/m", "FX_DAMPING = 2.0").replace("TY = 2.0", "FY_DAMPING = 2.0")
             .replace("TZ = 3.0", "FZ_DAMPING = 3.0").replace("RX = 0.01    $ kN.m.s/deg", "TX_DAMPING = 0.01")
             .replace("RY = 0.01", "TY_DAMPING = 0.01").replace("RZ = 0.02", "TZ_DAMPING = 0.02"))
    (tmp_path / "named.bus").write_text(named)
    assert quiet_read(tmp_path / "named.bus").axes == quiet_read().axes
    start, end = text.index("\n[TY_CURVE]"), text.index("\n[TZ_CURVE]")
    (tmp_path / "free.bus").write_text(text[:start] + text[end:])
    with pytest.warns(PropertyFileWarning, match=r"no \[TY_CURVE\]: a free axis ry"):
        free = read_bus(tmp_path / "free.bus")
    assert free.axes["ry"] == ("kelvin_voigt", {"k": 0.0, "c": pytest.approx(0.01e6 * 180 / math.pi), "preload": 0.0})


@pytest.mark.parametrize("change, message", [
    (("TZ = 3.0", "FZ = 3.0"), r"\[DAMPING\] FZ names no direction"),
    (("TZ = 3.0", "TZ = -3.0"), r"TZ = -3.0 must be a number >= 0"),
    ((" -0.004  -2.4\n -0.002  -0.9", " -0.004  -2.4 1\n -0.002  -0.9"), r"3 values for the 2 columns"),
    ((" -0.002  -0.9", " -0.005  -0.9"), r"the deflections must increase"),
    (("FORCE = 'kilonewton'", "FORCE = 'ton'"), r"FORCE = 'ton' is not a unit this reader knows"),
    (("\n[FX_CURVE]", "\n[FX_CURVES]"), r"block\(s\) \[FX_CURVES\] .* not in the .bus layout"),
])
def test_bad_files_are_refused_with_the_line(tmp_path, change, message):
    text = BUSHING.read_text()
    assert change[0] in text
    (tmp_path / "bad.bus").write_text(text.replace(change[0], change[1], 1))
    with pytest.raises(IdentificationError, match=message):
        quiet_read(tmp_path / "bad.bus")


def test_the_command_line_imports_a_bus(tmp_path):
    import json
    from identification.cli.arguments import main
    assert main(["import", str(BUSHING), "--out", str(tmp_path / "bus.json")]) == 0
    written = json.loads((tmp_path / "bus.json").read_text())
    assert written["axes"]["z"]["model"] == "KelvinVoigtBushing_Backbone5" and written["fit"]["format"] == "bus"
