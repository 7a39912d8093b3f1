"""What the compiled core costs a new process: its first call with an empty numba cache (the
models' kernels compiled) and with a filled one (the machine code loaded).

    python benchmarks/bench_compile_cache.py [--model proposed]

Runs, in fresh Python processes sharing a new, empty cache directory ($BUSHING_CACHE_DIR), one
``identification.simulate`` of 1 s of the 10 Hz sine at 1 kHz: first with the directory empty,
then twice with it filled; prints each process's time for that first call.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path
import harness

REPO = Path(__file__).resolve().parents[1]

FIRST_CALL = """
import sys, time
sys.path.insert(0, {repo!r})
import numpy as np
from build_fmu import default_parameter_file
from fmu_src.parameter_files import load_parameters
from identification.forward.simulate import simulate
params = load_parameters(default_parameter_file({model!r}))
t = np.arange(1000) * 1e-3
x = 2.0 * np.sin(2 * np.pi * 10.0 * t)
started = time.perf_counter()
simulate(params, t, x, model={model!r})
print(time.perf_counter() - started)
"""


def first_call(model: str, cache: Path) -> float:
    environment = dict(os.environ, BUSHING_CACHE_DIR=str(cache))
    output = subprocess.run([sys.executable, "-c", FIRST_CALL.format(repo=str(REPO), model=model)], env=environment,
                            capture_output=True, text=True, check=True).stdout
    return float(output.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="proposed")
    args = parser.parse_args()
    print(harness.provenance())
    with tempfile.TemporaryDirectory() as folder:
        cache = Path(folder)
        print(f"first call, empty cache (compiling):   {first_call(args.model, cache):6.2f} s")
        for run in (1, 2):
            print(f"first call, filled cache (loading) #{run}: {first_call(args.model, cache):6.2f} s")


if __name__ == "__main__":
    main()
