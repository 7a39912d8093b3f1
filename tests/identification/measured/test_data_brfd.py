"""The real friction-damper measurements shipped in data/brfd/ (CC BY-SA 4.0, see its README.md):
present, unchanged, in the documented layout and units, and with their licence beside them."""
import gzip
import hashlib
import re
import warnings

import numpy as np
import pytest

from conftest import DATA
from identification.measured.measurements import MeasurementError, MeasurementWarning, load_measurement

BRFD = DATA / "brfd"
MM_PER_IN = 25.4
RATE_HZ = 1024

# name -> (samples, sha256 of the uncompressed CSV text). The digests are those of the uncompressed
# files the documentation's friction-damper figures were measured on, which data/brfd/convert.py
# reproduces byte for byte from the original dataset: a change to any value changes them.
FILES = {
    "sine_0.25Hz30lbtension0.5amplitude": (28673, "8e2ab12c29ec47fcb84e93066f0a86cdd589f3d94c2d158cd1c5fecd3d1bea58"),
    "sine_0.25Hz30lbtension1amplitude": (28673, "6afa3ec3529dfc4f6bc5ded4eee82f1d40901a4bc910de24ebd7117ac6af8f69"),
    "sine_0.25Hz30lbtension1.5amplitude": (28673, "ab5860e8d8b3675f093ab96e80d2c3c523dc5fa24caa269e57ddcd4bf75b1953"),
    "sine_0.5Hz30lbtension0.5amplitude": (14337, "c197703545ffb4e3212c26afbd5fed1b86829cdedf6e5d0cc179149557e6eff3"),
    "sine_0.5Hz30lbtension1amplitude": (14337, "41740983079202b0edeac57071bfb4775354d6942522deeabff15c6fbc2a372c"),
    "sine_0.5Hz30lbtension1.5amplitude": (14337, "b870159b31e32c4eeb14974d2901884f3252628e54ed136481d984015ac92077"),
    "sine_1Hz30lbtension0.5amplitude": (7169, "568c91a17a9e0f7f70054299c103d163bfb0c7ee02179d00093fafa0f8e00463"),
    "sine_1Hz30lbtension1amplitude": (7169, "ecadaf3399f4818e1c8d3a26aad4830548d24fecff6a3fb7608033f885d42bee"),
    "sine_1Hz30lbtension1.5amplitude": (7169, "9a7da8a13acf15eb79fe883e5f7e823aad21f1af6fbab9faf49082c71e4119ae"),
    "sine_2Hz30lbtension0.5amplitude": (3585, "d955fb0096a7d83385ee8d6821464a1c9914908b32231faf4d804f8235050548"),
    "earthquake_ImperialValleyDBE": (28698, "fc07774a07f1a440409446fce00942bdca90ba45093fba0d4e54d25492ae338b"),
    "earthquake_ImperialValleyMCE": (28698, "cdcbdfd49e4adcaab419a44fe793fd6d7070991b813e71df53064cbf6a1aa411"),
    "earthquake_KocaeliDBE": (27342, "e743f7fb4efef00848fd3627f992fd9b54bf5405fef5a2e2323bf372b2338c8c"),
    "earthquake_KocaeliMCE": (27342, "cded2766c62fbdc8c34ac336a167228d77a78af8d5c14a0daf405594ad2f8a96"),
}
SINE_NAME = re.compile(r"sine_(?P<frequency>[0-9.]+)Hz30lbtension(?P<amplitude>[0-9.]+)amplitude")


def test_exactly_the_documented_files_are_shipped():
    assert sorted(path.name for path in BRFD.glob("*.csv*")) == sorted(f"{name}.csv.gz" for name in FILES)


@pytest.mark.parametrize("name", FILES)
def test_each_file_holds_the_values_the_docs_were_measured_on(name):
    text = gzip.decompress((BRFD / f"{name}.csv.gz").read_bytes())
    assert hashlib.sha256(text).hexdigest() == FILES[name][1]
    assert text.split(b"\n", 1)[0] == b"time_s,displacement_mm,force_N,velocity_mm_s"


@pytest.mark.parametrize("name", FILES)
def test_each_file_loads_in_the_documented_units_and_sample_rate(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeasurementWarning)      # real data look plausible
        m = load_measurement(BRFD / f"{name}.csv.gz")
    assert len(m) == FILES[name][0]
    assert not m.velocity_derived and m.has_force and m.comments == []
    # 1024 Hz from t = 0, the times printed to 1 us
    assert m.time_s[0] == 0.0
    assert np.max(np.abs(m.time_s - np.arange(len(m)) / RATE_HZ)) <= 5e-7 + 1e-12
    # newtons: peak forces of 10-25 kN (kN or kip would be 1000 or 4.4 times smaller)
    assert 8e3 < np.max(np.abs(m.force_N)) < 3e4
    # mm/s: the rig's velocity has the size of the displacement's derivative (in/s would be 25 x smaller)
    derivative = np.gradient(m.displacement_mm, m.time_s)
    assert 0.8 < np.sqrt(np.mean(m.velocity_mm_s ** 2) / np.mean(derivative ** 2)) < 1.25
    sine = SINE_NAME.fullmatch(name)
    if sine:    # mm: the peak displacement is the amplitude in the name, in inches times 25.4
        amplitude_mm = float(sine["amplitude"]) * MM_PER_IN
        assert np.max(np.abs(m.displacement_mm)) == pytest.approx(amplitude_mm, rel=0.05)
        assert 0.3 * amplitude_mm < np.sqrt(2) * np.std(m.displacement_mm) < 1.05 * amplitude_mm
    else:       # earthquakes: a few mm to a few cm
        assert 4 < np.max(np.abs(m.displacement_mm)) < 40


def test_the_readme_gives_the_licence_the_attribution_and_the_changes():
    readme = (BRFD / "README.md").read_text(encoding="utf-8")
    for required in ("CC BY-SA 4.0", "Creative Commons Attribution-ShareAlike 4.0 International",
                     "https://creativecommons.org/licenses/by-sa/4.0/", "legalcode",
                     "Daniel Coble", "Parker Huggins", "Liang Cao", "James Ricles", "Austin Downey",
                     "Dataset-Friction-Damper-with-Backlash", "2022",
                     "https://github.com/ARTS-Laboratory/Dataset-Friction-Damper-with-Backlash",
                     "0e09aa9d950760277e31c08cd93fd01f39a5af09", "Changes made", "25.4", "4448.2216152605",
                     "gzip", "convert.py", "not under the MIT licence"):
        assert required in readme, required
    for name in FILES:
        assert f"`{name}.csv.gz`" in readme, name
    licence = (BRFD / "LICENSE").read_text(encoding="utf-8")
    assert "Attribution-ShareAlike 4.0 International" in licence
    assert "https://creativecommons.org/licenses/by-sa/4.0/legalcode" in licence
    assert "Section 3 -- License Conditions." in licence
    assert (BRFD / "convert.py").is_file()


def test_a_gzip_compressed_csv_loads_as_the_same_csv(tmp_path):
    text = "# provenance\ntime_s,displacement_in,force_kip\n" + "".join(
        f"{k / 100:.2f},{np.sin(k / 5):.4f},{np.cos(k / 5):.4f}\n" for k in range(40))
    plain, packed = tmp_path / "test.csv", tmp_path / "test.csv.gz"
    plain.write_text(text, encoding="utf-8")
    packed.write_bytes(gzip.compress(text.encode("utf-8")))
    a, b = load_measurement(plain), load_measurement(packed)
    for column in ("time_s", "displacement_mm", "force_N", "velocity_mm_s"):
        assert np.array_equal(getattr(a, column), getattr(b, column))
    assert b.comments == ["provenance"] and b.velocity_derived and b.source == str(packed)


def test_a_file_that_is_not_what_its_name_says_is_refused_with_its_name(tmp_path):
    not_gzip = tmp_path / "plain.csv.gz"
    not_gzip.write_text("time_s,displacement_mm,force_N\n", encoding="utf-8")
    with pytest.raises(MeasurementError, match=r"plain\.csv\.gz: not a readable gzip file"):
        load_measurement(not_gzip)
    compressed = tmp_path / "packed.csv"
    compressed.write_bytes(gzip.compress(b"time_s,displacement_mm,force_N\n"))
    with pytest.raises(MeasurementError, match=r"packed\.csv: not UTF-8 text .*must end in \.gz"):
        load_measurement(compressed)
    with pytest.raises(MeasurementError, match="does not exist"):
        load_measurement(tmp_path / "absent.csv.gz")


def test_measurement_name_drops_the_csv_and_gz_suffixes():
    from identification.measured.measurements import measurement_name
    assert measurement_name("data/brfd/sine_1Hz30lbtension1amplitude.csv.gz") == "sine_1Hz30lbtension1amplitude"
    assert measurement_name("x/run_2.CSV") == "run_2"
    assert measurement_name("rig.txt") == "rig.txt"
