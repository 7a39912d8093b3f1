"""Make data/brfd/*.csv.gz from the original friction-damper dataset (see README.md here).

    python data/brfd/convert.py --source DATASET [--out DIR] [--compare-with DIR]

DATASET is the dataset repository ARTS-Laboratory/Dataset-Friction-Damper-with-Backlash at commit
0e09aa9d950760277e31c08cd93fd01f39a5af09: a checkout (a folder holding ``data/dataset-3``) or a
bare git directory (then the files are read with ``git show COMMIT:path``). Each source file is
checked against its git blob id before it is converted, so a different version of the dataset is
refused rather than silently converted.

What the conversion does, and nothing else:

- takes dataset 3 (tests of April 2023, band tension 30 lb), the ten sine ("characterization")
  tests and the four earthquake tests listed in FILES below;
- keeps the first four columns of each test's ``data`` matrix (time [s], displacement [in],
  friction force [kip], velocity [in/s]) and drops the two actuator forces [lb];
- converts inch to mm (x 25.4) and kip to N (x 4448.2216152605, i.e. 1000 lbf of
  4.4482216152605 N, the factor identification.measured.measurements uses for ``force_kip``);
- writes ``time_s,displacement_mm,force_N,velocity_mm_s`` with fixed decimals: time 6
  (1 us; samples are 1/1024 s apart), displacement 5 (10 nm), force 2 (0.01 N), velocity 4
  (0.1 um/s), all far below the rig's resolution (displacement steps of about 1.5 um, force
  steps of about 3.6 N);
- compresses each CSV with gzip (level 9, no file name and time stamp 0 in the header, so the
  same input gives the same bytes).

``--compare-with DIR`` also checks that the CSV text made for each file is byte for byte the
``DIR/<name>.csv`` (an uncompressed copy made earlier, such as ../shared/data/brfd), and every
run reads each written .gz back and checks it decompresses to the text that was made.
"""
from __future__ import annotations

import argparse
import gzip
import hashlib
import io
import json
import subprocess
import sys
from pathlib import Path

COMMIT = "0e09aa9d950760277e31c08cd93fd01f39a5af09"
SINES = "data/dataset-3/characterization tests"
EARTHQUAKES = "data/dataset-3/earthquake profiles"

# shipped name -> (source path in the dataset repository, its git blob id at COMMIT)
FILES = {
    "sine_0.25Hz30lbtension0.5amplitude": (f"{SINES}/0.25Hz30lbtension0.5amplitude.json",
                                           "500bae97c152cf32b2d66c54965fbeca6614fdc5"),
    "sine_0.25Hz30lbtension1amplitude": (f"{SINES}/0.25Hz30lbtension1amplitude.json",
                                         "bf58d67ca2b37207246cc5b393711b04df0e9488"),
    "sine_0.25Hz30lbtension1.5amplitude": (f"{SINES}/0.25Hz30lbtension1.5amplitude.json",
                                           "98517346f408b2d71768a29fb180001ccd1d8f12"),
    "sine_0.5Hz30lbtension0.5amplitude": (f"{SINES}/0.5Hz30lbtension0.5amplitude.json",
                                          "15f799f606171d6067620df6a26696bb9ec28423"),
    "sine_0.5Hz30lbtension1amplitude": (f"{SINES}/0.5Hz30lbtension1amplitude.json",
                                        "2192cd3be885132456a1805fd9794e48e7913ada"),
    "sine_0.5Hz30lbtension1.5amplitude": (f"{SINES}/0.5Hz30lbtension1.5amplitude.json",
                                          "fc03c185795c629a7008bab42ecb2a4635ac09b0"),
    "sine_1Hz30lbtension0.5amplitude": (f"{SINES}/1Hz30lbtension0.5amplitude.json",
                                        "66670a0ebdea5bc165bed9cd57668a582e669a35"),
    "sine_1Hz30lbtension1amplitude": (f"{SINES}/1Hz30lbtension1amplitude.json",
                                      "2cc29bb16fa30db31204857ade395c09a93fb681"),
    "sine_1Hz30lbtension1.5amplitude": (f"{SINES}/1Hz30lbtension1.5amplitude.json",
                                        "852561f8388fb82bc138374cf6c2dfbcbf5b2c09"),
    "sine_2Hz30lbtension0.5amplitude": (f"{SINES}/2Hz30lbtension0.5amplitude.json",
                                        "45e2955fbb0fe41cc01d2ba1f4a620f060e9c0d1"),
    "earthquake_ImperialValleyDBE": (f"{EARTHQUAKES}/ImperialValleyDBE.json",
                                     "c609091906b6234972cd7720d91e628ccf2cb43b"),
    "earthquake_ImperialValleyMCE": (f"{EARTHQUAKES}/ImperialValleyMCE.json",
                                     "861b7c854f34e58fcae831726fb9b7d985956c4e"),
    "earthquake_KocaeliDBE": (f"{EARTHQUAKES}/KocaeliDBE.json",
                              "77124c38a7272dff8edc0107e24ae1c695519289"),
    "earthquake_KocaeliMCE": (f"{EARTHQUAKES}/KocaeliMCE.json",
                              "2508385252c40812a33abf2bfbce89d10829e9f4"),
}

MM_PER_IN = 25.4
N_PER_KIP = 4448.2216152605
HEADER = "time_s,displacement_mm,force_N,velocity_mm_s"
SOURCE_UNITS = {"time units": "s", "displacement units": "in", "friction force units": "kip"}
SAMPLE_RATE_HZ = 1024


def git_blob_id(content: bytes) -> str:
    """The id git gives a file with these bytes (so a checkout can be checked too)."""
    return hashlib.sha1(b"blob %d\0" % len(content) + content).hexdigest()


def read_source(source: Path, path: str) -> bytes:
    if (source / "data").is_dir():
        return (source / path).read_bytes()
    return subprocess.run(["git", "--git-dir", str(source), "show", f"{COMMIT}:{path}"],
                          capture_output=True, check=True).stdout


def convert(document: dict, name: str) -> str:
    """One test's JSON document as the CSV text shipped here."""
    for key, unit in SOURCE_UNITS.items():
        if document[key] != unit:
            raise SystemExit(f"{name}: {key} is {document[key]!r}, expected {unit!r}")
    if document["sampling freq"] != SAMPLE_RATE_HZ or document["dt"] != 1.0 / SAMPLE_RATE_HZ:
        raise SystemExit(f"{name}: sampled at {document['sampling freq']} Hz, expected {SAMPLE_RATE_HZ} Hz")
    lines = [HEADER]
    for row in document["data"]:
        time_s, displacement_in, force_kip, velocity_in_s = row[:4]
        lines.append(f"{time_s:.6f},{displacement_in * MM_PER_IN:.5f},"
                     f"{force_kip * N_PER_KIP:.2f},{velocity_in_s * MM_PER_IN:.4f}")
    return "\n".join(lines) + "\n"


def compress(text: str) -> bytes:
    buffer = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=buffer, compresslevel=9, mtime=0) as stream:
        stream.write(text.encode("utf-8"))
    return buffer.getvalue()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", type=Path, required=True,
                        help="the dataset repository: a checkout, or a bare git directory")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent,
                        help="where to write <name>.csv.gz (default: this folder)")
    parser.add_argument("--compare-with", type=Path, metavar="DIR",
                        help="check the CSV text against DIR/<name>.csv, byte for byte")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    total = 0
    for name, (path, blob) in FILES.items():
        content = read_source(args.source, path)
        if git_blob_id(content) != blob:
            sys.exit(f"{path}: git blob {git_blob_id(content)}, expected {blob} (commit {COMMIT[:7]})")
        text = convert(json.loads(content), name)
        if args.compare_with is not None:
            reference = (args.compare_with / f"{name}.csv").read_bytes()
            if reference != text.encode("utf-8"):
                sys.exit(f"{name}: the CSV made differs from {args.compare_with / (name + '.csv')}")
        packed = compress(text)
        if gzip.decompress(packed).decode("utf-8") != text:
            sys.exit(f"{name}: the compressed file does not read back as the text made")
        (args.out / f"{name}.csv.gz").write_bytes(packed)
        total += len(packed)
        same = ", identical to the reference" if args.compare_with is not None else ""
        print(f"{name}.csv.gz: {text.count(chr(10)) - 1} samples, {len(packed)} bytes{same}")
    print(f"{len(FILES)} files, {total} bytes in {args.out}")


if __name__ == "__main__":
    main()
