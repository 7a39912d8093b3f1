"""How often does a fit reach the noise floor, how fast, and how good are its predictions?

    python benchmarks/bench_fit_reliability.py [--truths 12] [--seeds 0 1 2] [--methods default]
                                               [--workers N] [--json results.json]

Truths: the paper's Tables 2, 4 and 5, then sets drawn uniformly in the search box of the
documented bounds (``identification/fitting/search_space.py``, scaled as for Table 5's tests) and kept
only if they are plausible bushings (peak force 0.5-20 kN on the 2 mm/10 Hz sine, 2-30 %
relaxation from the end of the step's ramp to 10 s) and lie inside the box scaled by their
own tests (what a fit searches). Data: the paper's two training tests (sine 2 mm/10 Hz for 1 s;
step 2 mm with a 0.4 s rise, held to 10 s) from the continuous-time truth at 1 kHz, with
white force noise of 1 % of each test's rms force (seeded per truth).

Per fit: at the floor (every training test's NRMSE <= 1.25 x its actual noise level: the rms
of the noise drawn, over the rms force), converged (the fit's own verdict, with its own noise
estimate), the wall time, the worst NRMSE against the noise-free truth over the paper's §5
grid less the two training cases (16 sines, 9 steps, the random input), and the ensemble's
band: on every grid case the best fit misses by more than 1 % NRMSE, the fraction of samples
where the truth lies within the ensemble's envelope widened by the training noise level; and
(default method) the factor by which the stages after the first lowered the misfit, which bounds
compare's race (``identification.analysis.race.RACE_CLOSING``).

``--methods default,de,cma`` adds the previous default (scipy's differential evolution,
rand1bin, 15 x 14 x 100, then a trust-region polish from its best) and CMA-ES with BIPOP
restarts (the ``cma`` package, 40,000 evaluations, no polish), each on the same objective
and box, for the comparison of methods.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.models.proposed_model import PARAMETER_NAMES  # noqa: E402
from fmu_src.parameter_files import load_parameters  # noqa: E402
from identification.measured.measurements import Measurement  # noqa: E402
from identification.measured.signals import Sine, Step, sample_times  # noqa: E402
from identification.measured.rig_tests import RigTest  # noqa: E402
from identification.fitting.search_space import SearchSpace  # noqa: E402
from identification.forward.simulate import simulate  # noqa: E402
import harness  # noqa: E402

NOISE = 0.01
FLOOR = 1.25
TRAINING = (("sine", Sine(2.0, 10.0, 1.0), None), ("step", Step(2.0, 0.4, 10.0), 0.4))


def truth_forces(params, protocol):
    t = sample_times(protocol.duration_s, 1000.0)
    x, v = protocol.signals(t)
    return t, x, v, simulate(params, t, x, v, steps_per_sample=16)


def plausible(params):
    """(sine peak force, step relaxation) if the set is a plausible bushing, else None."""
    with np.errstate(all="ignore"):
        _, _, _, sine = truth_forces(params, TRAINING[0][1])
        if not np.all(np.isfinite(sine)) or not 500.0 <= np.max(np.abs(sine)) <= 20e3:
            return None
        t, _, _, step = truth_forces(params, TRAINING[1][1])
    if not np.all(np.isfinite(step)):
        return None
    at_rise = step[np.argmin(np.abs(t - 0.4))]
    relaxation = (at_rise - step[-1]) / at_rise
    return (float(np.max(np.abs(sine))), float(relaxation)) if 0.02 <= relaxation <= 0.30 else None


def own_space(params):
    measurements = []
    for kind, protocol, _ in TRAINING:
        t, x, v, force = truth_forces(params, protocol)
        measurements.append(Measurement(t, x, force, v))
    return SearchSpace.from_measurements(measurements, steps=[False, True])


def truths(count: int, seed: int = 1) -> list[tuple[str, dict]]:
    tables = [(name, load_parameters(REPO / "data" / f"params_{file}.json")) for name, file in
              (("Table 2", "table2_sine"), ("Table 4", "table4_step"), ("Table 5", "table5_combined"))]
    out = tables[:count]
    nominal = own_space(tables[2][1])
    bounds = nominal.bounds()
    rng = np.random.default_rng(seed)
    tried = 0
    while len(out) < count:
        tried += 1
        theta = bounds[:, 0] + rng.random(len(bounds)) * (bounds[:, 1] - bounds[:, 0])
        params = dict(zip(PARAMETER_NAMES, map(float, nominal.to_parameters(theta)[0])))
        if plausible(params) is None:
            continue
        space = own_space(params)
        if not space.inside(space.to_coordinates(params))[0]:
            continue
        out.append((f"random {len(out) - 2}", params))
    print(f"truths: {len(out)} ({max(0, len(out) - 3)} random ones kept of {tried} drawn)", file=sys.stderr)
    return out


def load_or_draw_truths(count: int, path: Path | None = None) -> list[tuple[str, dict]]:
    """The first ``count`` truths of the JSON file ``path`` if it exists, else :func:`truths`
    (then written to ``path``, if given, so that later runs use the same ones)."""
    if path and path.exists():
        return [tuple(pair) for pair in json.loads(path.read_text())][:count]
    drawn = truths(count)
    if path:
        path.write_text(json.dumps(drawn, indent=1))
    return drawn


def training_data(params, noise_seed: int):
    rng = np.random.default_rng(noise_seed)
    tests, noise_levels = [], []
    for kind, protocol, rise in TRAINING:
        t, x, v, force = truth_forces(params, protocol)
        noise = rng.normal(0.0, NOISE * np.sqrt(np.mean(force ** 2)), t.size)
        measured = force + noise
        tests.append(RigTest(Measurement(t, x, measured, np.gradient(x, t), velocity_derived=True,
                                         source=f"{kind}.csv"), kind, rise))
        noise_levels.append(float(np.sqrt(np.mean(noise ** 2)) / np.sqrt(np.mean(measured ** 2))))
    return tests, noise_levels


def grid_cases():
    from identification.analysis.paper_verification import grid_protocols
    for name, protocol in grid_protocols():
        if name not in ("sine 2 mm 10 Hz", "step 2 mm rise 0.4 s"):
            yield name, protocol


def judge(members, truth, sigma_N):
    """Worst grid NRMSE of the best member, and the band coverage where it misses > 1 %."""
    from identification.fitting.objectives import nrmse
    from identification.analysis.predict import predict
    worst, coverages = 0.0, []
    for name, protocol in grid_cases():
        t = sample_times(protocol.duration_s, 1000.0)
        x, v = protocol.signals(t)
        expected = simulate(truth, t, x, v)
        prediction = predict(members, t, x, v)
        error = nrmse(prediction.force_N, expected)
        worst = max(worst, error)
        if error > 0.01:
            inside = (expected >= prediction.lower_N - sigma_N) & (expected <= prediction.upper_N + sigma_N)
            coverages.append((name, float(np.mean(inside)), error))
    return worst, coverages


def run_default(tests, seed, workers):
    from identification.fitting.fit import fit
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = fit(tests, seed=seed, workers=workers, progress=False)
    # how far the stages after the first lowered the misfit (compare's race: identification.analysis.race)
    closing = result.first_stage_misfit / result.misfit
    return result.ensemble, result.converged, [t.nrmse for t in result.tests], result.warning or "", closing


def _problem(tests):
    from identification.fitting.multistart import Problem
    from identification.fitting.objectives import Objective
    space = SearchSpace.from_measurements([t.measurement for t in tests], steps=[t.kind == "step" for t in tests])
    return Problem(Objective(tests), space)


def _finish(problem, theta, tests):
    from identification.fitting.search import test_fits
    from fmu_src.parameter_files import ParameterSet
    from identification.measured.noise import estimate_noise
    params = dict(zip(PARAMETER_NAMES, map(float, problem.space.to_parameters(theta)[0])))
    fits = test_fits(tests, [estimate_noise(t.measurement.force_N) for t in tests],
                      ParameterSet(problem.space.bushing, params))
    return [params], all(f.at_floor for f in fits), [f.nrmse for f in fits], "", None


def run_de(tests, seed, workers):
    """The previous default: differential evolution (rand1bin, 15 x 14 x 100), then a polish."""
    from scipy.optimize import differential_evolution
    from identification.fitting.engine import SerialEngine
    from identification.fitting.multistart import _least_squares_task
    problem = _problem(tests)
    bounds = problem.space.bounds()
    search = differential_evolution(lambda columns: problem.misfit(columns.T), bounds, vectorized=True,
                                    updating="deferred", popsize=15, maxiter=100, strategy="rand1bin",
                                    mutation=(0.5, 1.0), recombination=0.9, seed=seed, polish=False, init="sobol")
    theta = SerialEngine().map(_least_squares_task, [(search.x, 300)], problem)[0][0]
    return _finish(problem, theta[None, :], tests)


def run_cma(tests, seed, workers):
    """CMA-ES with BIPOP restarts on the box scaled to [0, 1]."""
    import cma
    problem = _problem(tests)
    bounds = problem.space.bounds()
    low, span = bounds[:, 0], bounds[:, 1] - bounds[:, 0]
    objective = lambda unit: float(problem.misfit((low + np.asarray(unit) * span)[None, :])[0])  # noqa: E731
    batch = lambda units: list(problem.misfit(low + np.asarray(units) * span))  # noqa: E731
    options = {"bounds": [0.0, 1.0], "maxfevals": 40000, "seed": seed + 1, "verbose": -9}
    best, _ = cma.fmin2(objective, 0.5 * np.ones(len(bounds)), 0.3, options, restarts=9, bipop=True,
                        parallel_objective=batch)
    return _finish(problem, (low + best * span)[None, :], tests)


METHODS = {"default": run_default, "de": run_de, "cma": run_cma}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truths", type=int, default=12)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--methods", default="default")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--first-truth", type=int, default=0, help="skip the truths before this index")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--truths-file", type=Path,
                        help="read the truths from this JSON file if it exists, else draw them and write it")
    args = parser.parse_args()

    print(harness.provenance(), file=sys.stderr)
    rows = []
    drawn = load_or_draw_truths(args.truths, args.truths_file)
    for index, (name, truth) in enumerate(drawn):
        if index < args.first_truth:
            continue
        tests, noise_levels = training_data(truth, 100 + index)
        sigma_N = max(level * np.sqrt(np.mean(t.measurement.force_N ** 2)) for level, t in zip(noise_levels, tests))
        for method in args.methods.split(","):
            for seed in args.seeds:
                started = time.perf_counter()
                members, converged, nrmses, note, closing = METHODS[method](tests, seed, args.workers)
                seconds = time.perf_counter() - started
                at_floor = all(n <= FLOOR * level for n, level in zip(nrmses, noise_levels))
                worst, coverages = judge(members, truth, sigma_N)
                row = {"truth": name, "method": method, "seed": seed, "at_floor": at_floor, "converged": converged,
                       "seconds": seconds, "nrmse_over_noise": [n / level for n, level in zip(nrmses, noise_levels)],
                       "worst_grid_nrmse": worst, "members": len(members), "note": note, "closing": closing,
                       "band": [{"case": c, "coverage": cov, "nrmse": e} for c, cov, e in coverages]}
                rows.append(row)
                band = min((c["coverage"] for c in row["band"]), default=float("nan"))
                print(f"{name:10s} {method:8s} seed {seed}: {'FLOOR' if at_floor else 'miss '} "
                      f"{'converged' if converged else 'NOT conv.'} "
                      f"NRMSE/noise {' '.join(f'{r:.3f}' for r in row['nrmse_over_noise'])} "
                      f"{seconds:6.1f} s  worst grid {worst:6.2%}  members {len(members):3d}  "
                      f"cases > 1 %: {len(row['band'])}, least band coverage {band:.3f}"
                      + (f", later stages closed {closing:.3g}x" if closing else "")
                      + (f"\n           ({note})" if note else ""), flush=True)
                if args.json:
                    args.json.write_text(json.dumps(rows, indent=1))
    print()
    print(f"{'method':8s} {'runs':>5s} {'at floor':>9s} {'converged':>10s} {'median s':>9s} {'worst s':>8s} "
          f"{'worst grid':>11s} {'band >= 95 %':>13s}")
    for method in args.methods.split(","):
        mine = [r for r in rows if r["method"] == method]
        if not mine:
            continue
        bands = [c["coverage"] for r in mine for c in r["band"]]
        print(f"{method:8s} {len(mine):5d} {sum(r['at_floor'] for r in mine):4d} of {len(mine):<3d}"
              f"{sum(r['converged'] for r in mine):5d} of {len(mine):<3d} "
              f"{np.median([r['seconds'] for r in mine]):9.1f} {max(r['seconds'] for r in mine):8.1f} "
              f"{max(r['worst_grid_nrmse'] for r in mine):11.2%} "
              f"{sum(b >= 0.95 for b in bands):5d} of {len(bands):<5d}")
    closings = [r["closing"] for r in rows if r["closing"]]
    if closings:
        print(f"the stages after the first lowered the misfit by at most {max(closings):.3g}x (median "
              f"{np.median(closings):.3g}x)")


if __name__ == "__main__":
    main()
