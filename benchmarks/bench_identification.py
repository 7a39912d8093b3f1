"""Cost of evaluating fitting candidates: compiled population vs Python core vs solve_ivp.

    python benchmarks/bench_identification.py [--candidates N] [--ivp-candidates M]

All three simulate the paper's identification sine (2 mm, 10 Hz, 1 s at 1 kHz) for random
candidates of the normalised search space (around the synthetic Table 5 data), in one run:
- the numba-compiled core over the whole population at once (what the fit uses),
- the same core as plain Python, one candidate after the other (what the FMU runs),
- scipy's solve_ivp (Radau, rtol 1e-6) on eqs. 1-4, restarted at every sample, on a few
  candidates (it is slow): the per-candidate loop the issue compares against.
Then the cost of one candidate of the fit's objective on the paper's two training tests
(sine and step, through the forward model: spline input, decimated hold).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import harness

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))   # the Python core loop (tests/python_core.py)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--candidates", type=int, default=210)
    parser.add_argument("--ivp-candidates", type=int, default=3)
    args = parser.parse_args()

    from scipy.integrate import solve_ivp
    from fmu_src.model.integration import StepError
    from fmu_src.models.proposed_model import MODEL, PARAMETER_NAMES
    from fmu_src.parameter_files import load_parameters
    from identification.forward.population import simulate_population_held
    from identification.measured.measurements import load_measurement
    from identification.fitting.objectives import Objective
    from identification.measured.rig_tests import RigTest
    from identification.measured.signals import Sine, sample_times
    from identification.fitting.search_space import SearchSpace
    from python_core import simulate_python_core

    sine = load_measurement(REPO / "data" / "synthetic_table5_sine_2mm_10Hz.csv")
    step = load_measurement(REPO / "data" / "synthetic_table5_step_2mm_rise0.4s.csv")
    space = SearchSpace.from_measurements([sine, step], steps=[False, True])
    bounds = space.bounds()
    # Candidates near the data's optimum region (a late generation), not uniform over the
    # bounds, where many candidates fail at once and would flatter every method.
    centre = space.to_coordinates(load_parameters(REPO / "data" / "params_table5_combined.json"))
    rng = np.random.default_rng(0)
    theta = np.clip(centre + 0.05 * (bounds[:, 1] - bounds[:, 0]) * rng.standard_normal((args.candidates, 14)),
                    bounds[:, 0], bounds[:, 1])
    matrix = space.to_parameters(theta)
    t = sample_times(1.0, 1000.0)
    x, v = Sine(2.0, 10.0).signals(t)

    simulate_population_held(matrix[:2], t, x, v)  # compile outside the timing
    started = time.perf_counter()
    compiled = simulate_population_held(matrix, t, x, v)
    compiled_cost = (time.perf_counter() - started) / len(matrix)

    python_sample = matrix[:20]
    started = time.perf_counter()
    for row in python_sample:
        try:
            simulate_python_core(dict(zip(PARAMETER_NAMES, row)), t, x, v)
        except StepError:
            pass
    python_cost = (time.perf_counter() - started) / len(python_sample)

    ivp_sample = matrix[:args.ivp_candidates]
    started = time.perf_counter()
    for row in ivp_sample:
        constants = MODEL.constants(dict(zip(PARAMETER_NAMES, row)))
        state = np.array(MODEL.initial_state(constants, x[0]))
        for k in range(t.size - 1):
            # eqs. 1-4 (the model's derivatives) with the input held as the FMU holds it
            state = solve_ivp(lambda s, y, xk, vk: MODEL.derivatives(constants, tuple(y), xk + vk * s, vk),
                              (0.0, t[k + 1] - t[k]), state, method="Radau", args=(x[k], v[k]),
                              rtol=1e-6, atol=1e-6).y[:, -1]
    ivp_cost = (time.perf_counter() - started) / len(ivp_sample)

    objective = Objective([RigTest(sine, "sine"), RigTest(step, "step", 0.4)])
    objective(matrix[:2])
    started = time.perf_counter()
    objective(matrix)
    objective_cost = (time.perf_counter() - started) / len(matrix)

    print(f"{harness.provenance()}\nsine 2 mm / 10 Hz, 1 s at 1 kHz; {len(matrix)} candidates near the optimum, "
          f"{np.isnan(compiled[:, -1]).sum()} of them failed")
    print(f"{'per candidate':45s} {'ms':>10s} {'speed-up':>9s}")
    print(f"{'solve_ivp Radau loop (' + str(len(ivp_sample)) + ' candidates)':45s} {ivp_cost * 1e3:10.1f} {1.0:9.0f}")
    print(f"{'Python core (20 candidates)':45s} {python_cost * 1e3:10.2f} {ivp_cost / python_cost:9.0f}")
    print(f"{'compiled core, population at once':45s} {compiled_cost * 1e3:10.3f} {ivp_cost / compiled_cost:9.0f}")
    print(f"the fit's objective on the sine and step tests: {objective_cost * 1e3:.2f} ms per candidate "
          f"(the paper's GA preset's 60,000: {60000 * objective_cost:.0f} s)")


if __name__ == "__main__":
    main()
