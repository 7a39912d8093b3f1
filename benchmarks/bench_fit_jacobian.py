"""The fit's exact Jacobian against forward differences, side by side in one run.

    python benchmarks/bench_fit_jacobian.py [--workers N] [--seed S] [--repeats R] [--no-ensemble]
                                            [--sine FILE --step FILE --rise-time S]

On the paper's two tests (default: the synthetic Table 2 sine 2 mm/10 Hz and step 2 mm/0.4 s with
1 % force noise, ``data/synthetic_table2_noise1pct_*``), the default fit (``identification.fit``,
preset ``default``, with its ensemble unless ``--no-ensemble``) runs with ``jacobian="difference"``
(forward differences, what the fit did before) and ``jacobian="exact"`` (the forces'
sensitivities, ``identification.forward.parameter_jacobian``), alternating, ``--repeats`` times each, in this
process (the compiled modules loaded before the first timing; each fit starts its own worker
processes, which load them from the disk cache, as a fit does). Printed per run: wall time, CPU
time (this process and the fit's workers: less sensitive than the wall time to other load on a
shared machine; Unix), chi^2/n, each test's NRMSE over its noise level (the floor: <= 1.25), the
simulations counted (a sensitivity simulation counts as one), the agreeing final starts.

Then the Jacobian itself at the exact fit's best point: the time of one Jacobian each way, the
largest relative difference of the exact columns from the reference (central differences, each
column at the step among 1e-4 ... 1e-8 where successive steps agree best) and of the
forward-difference columns from it, and the identifiability's singular values from the exact
Jacobian, from forward differences and from the reference, with their relative differences:
"accurate" where forward differences agree with the reference to 1e-4.
"""
from __future__ import annotations

import argparse
import resource
import time
from pathlib import Path

import numpy as np
import harness

REPO = Path(__file__).resolve().parents[1]

REFERENCE_STEPS = 10.0 ** -np.arange(4.0, 8.5, 0.5)
ACCURATE = 1e-4


def central_jacobian(problem, theta, step):
    """Central differences of the residuals, step ``step``*max(1, |theta_j|) (inside the box)."""
    bounds = problem.space.bounds()
    steps = step * np.maximum(1.0, np.abs(theta))
    up = np.minimum(theta + steps, bounds[:, 1])
    down = np.maximum(theta - steps, bounds[:, 0])
    rows = problem.residuals(np.vstack([theta + np.diag(up - theta), theta + np.diag(down - theta)]))
    d = len(theta)
    return ((rows[:d] - rows[d:]) / (up - down)[:, None]).T


def reference_jacobian(problem, theta):
    """The reference: for each column, central differences at the steps REFERENCE_STEPS (times
    max(1, |theta_j|)), the smaller of the two successive steps whose differences agree best. No
    one step suits every column: at this benchmark's best fit (seed 0) the residual of one sample
    of the sine curves so sharply in c0 and n2 that their 1e-6 central differences are 9e-6 and
    6e-5 off (falling as the step squared), while k2's column is so small that rounding takes its
    1e-7 central difference 1e-4 off."""
    estimates = np.array([central_jacobian(problem, theta, step) for step in REFERENCE_STEPS])   # (s, n, d)
    change = np.linalg.norm(estimates[1:] - estimates[:-1], axis=1) / np.linalg.norm(estimates[1:], axis=1)
    best = np.argmin(change, axis=0) + 1
    return estimates[best, :, np.arange(len(theta))].T


def cpu_seconds() -> float:
    """User and system time of this process and of its finished children (a fit's workers)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def describe(result, label, wall, cpu):
    ratios = " ".join(f"{t.nrmse / t.noise.relative:.3f}" for t in result.tests)
    floor = all(t.nrmse <= 1.25 * t.noise.relative for t in result.tests)
    agree = result.summary().splitlines()
    agreement = next((line.split(";")[0] for line in agree if line.startswith("starts:")), "")
    return (f"{label:11s} {wall:8.1f} {cpu:8.1f} {result.misfit:9.4f}   {ratios:14s} {'yes' if floor else 'NO':5s} "
            f"{result.evaluations:12d}   {agreement}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--no-ensemble", action="store_true")
    parser.add_argument("--sine", default=str(REPO / "data" / "synthetic_table2_noise1pct_sine_2mm_10Hz.csv"))
    parser.add_argument("--step", default=str(REPO / "data" / "synthetic_table2_noise1pct_step_2mm_rise0.4s.csv"))
    parser.add_argument("--rise-time", type=float, default=0.4)
    args = parser.parse_args()

    import warnings
    from identification import fit, training_tests
    from fmu_src.model.registry import get_model
    from identification.forward.parameter_jacobian import sensitivity_module
    from identification.fitting.result import FitNotConvergedWarning
    from identification.fitting.multistart import Problem, difference_jacobian, jacobian
    from identification.fitting.objectives import Objective

    warnings.simplefilter("ignore", FitNotConvergedWarning)
    tests = training_tests(sine=[args.sine], step=[args.step], rise_times_s=[args.rise_time])
    print(harness.provenance())
    print(f"tests: {Path(args.sine).name}, {Path(args.step).name} (rise {args.rise_time} s); default preset, "
          f"seed {args.seed}, {args.workers} workers, ensemble {'off' if args.no_ensemble else 'on'}")
    started = time.perf_counter()
    sensitivity_module(get_model("proposed"), 14)
    print(f"sensitivity module compiled or loaded in this process: {time.perf_counter() - started:.1f} s")

    print(f"{'jacobian':11s} {'wall s':>8s} {'CPU s':>8s} {'chi2/n':>9s}   {'NRMSE/noise':14s} {'floor':5s} "
          f"{'simulations':>12s}")
    walls = {"difference": [], "exact": []}
    cpus = {"difference": [], "exact": []}
    results = {}
    for _ in range(args.repeats):
        for mode in ("difference", "exact"):
            started, cpu = time.perf_counter(), cpu_seconds()
            result = fit(tests, seed=args.seed, workers=args.workers, progress=False, jacobian=mode,
                         ensemble=not args.no_ensemble)
            walls[mode].append(time.perf_counter() - started)
            cpus[mode].append(cpu_seconds() - cpu)
            results[mode] = result
            print(describe(result, mode, walls[mode][-1], cpus[mode][-1]), flush=True)
    difference, exact = (float(np.median(walls[m])) for m in ("difference", "exact"))
    print(f"median wall time: difference {difference:.1f} s, exact {exact:.1f} s: exact/difference = "
          f"{exact / difference:.2f} (target <= 0.60)")
    difference, exact = (float(np.median(cpus[m])) for m in ("difference", "exact"))
    print(f"median CPU time (this process and its workers): difference {difference:.1f} s, exact {exact:.1f} s: "
          f"exact/difference = {exact / difference:.2f}")

    # the Jacobian at the exact fit's best point
    result = results["exact"]
    space = result.space
    theta = space.to_coordinates(result.parameters.parameters)
    theta = np.clip(theta, space.bounds()[:, 0], space.bounds()[:, 1])
    objective = Objective(tests, [t.noise for t in result.tests], steps=result.steps_per_sample, model=space.bushing)
    problem = Problem(objective, space, "exact")
    n = objective.size
    exact_j, _ = jacobian(problem, theta)
    # one numba thread, as in a fit's worker (a worker takes a start's Jacobians): the forward
    # differences' 15 simulations would otherwise run on every core of this process
    from fmu_src.kernels.jit import numba
    numba.set_num_threads(1)
    timings = {}
    for label, function in (("exact", lambda: jacobian(problem, theta)),
                            ("difference", lambda: difference_jacobian(problem, theta))):
        started = time.perf_counter()
        for _ in range(5):
            function()
        timings[label] = (time.perf_counter() - started) / 5
    forward_j, _ = difference_jacobian(problem, theta)
    central_j = reference_jacobian(problem, theta)
    norms = np.linalg.norm(central_j, axis=0)
    exact_error = np.linalg.norm(exact_j - central_j, axis=0) / norms
    forward_error = np.linalg.norm(forward_j - central_j, axis=0) / norms
    print(f"one Jacobian at the best fit (one numba thread, as in a worker): "
          f"exact {timings['exact'] * 1e3:.1f} ms, forward differences {timings['difference'] * 1e3:.1f} ms "
          f"({len(theta) + 1} simulations)")
    print(f"columns against the reference (central differences, each column's step chosen among 1e-4 ... 1e-8), "
          f"largest relative difference: exact "
          f"{exact_error.max():.1e} ({space.names[int(np.argmax(exact_error))]}), forward differences "
          f"{forward_error.max():.1e} ({space.names[int(np.argmax(forward_error))]})")
    values = {label: np.linalg.svd(j * np.sqrt(n), compute_uv=False)
              for label, j in (("exact", exact_j), ("forward", forward_j), ("central", central_j))}
    accurate = np.abs(values["forward"] / values["central"] - 1.0) <= ACCURATE
    print("identifiability's singular values (relative to the largest) and relative differences:")
    print(f"{'#':>3s} {'exact':>9s} {'exact/forward-1':>16s} {'exact/reference-1':>18s} {'forward accurate':>17s}")
    for i in range(len(theta)):
        value = values["exact"][i]
        print(f"{i + 1:3d} {value / values['exact'][0]:9.2e} "
              f"{value / values['forward'][i] - 1:16.1e} {value / values['central'][i] - 1:18.1e} "
              f"{'yes' if accurate[i] else 'no':>17s}")
    where = np.abs(values["exact"][accurate] / values["forward"][accurate] - 1.0)
    print(f"largest relative change where forward differences were accurate: {where.max() if where.size else 0:.1e} "
          f"(target <= 1e-3)")


if __name__ == "__main__":
    main()
