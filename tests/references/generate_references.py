"""Reference results of the one-axis bushing models on the paper's Table 5 tests.

    python tests/references/generate_references.py [--check-convergence] [--model NAME]

Writes, next to this file, ``<model>_sine_2mm_10Hz.csv`` and ``<model>_step_2mm_rise0.4s.csv``
(columns time_s, displacement_mm, force_N; 1 ms samples) and ``<model>.png`` (hysteresis loop
and step response) for the proposed model (the paper's Table 5), Spencer's, the single Bouc-Wen
and Kelvin-Voigt (the project's fitted sets), the filled-rubber models Berg and fractional
(illustrative sets typed in data/), and the two hydraulic mounts (rubber path, inertia track,
a membrane or a free-plate decoupler; illustrative sets typed in data/). Running it again rewrites the same bytes on the
same numpy/scipy/matplotlib.

Independent of the code under test: the equations are typed here from the paper (eqs. 1-5),
Spencer et al. (1997) and the hydraulic mount's lumped-parameter equations (Flower 1985; Singh,
Kim and Ravindra 1992) as the model modules' docstrings state them, the parameter files are read
as plain JSON, and scipy's Radau integrates the continuous-time inputs (no sampling, no
interpolation, no communication steps). The filled-rubber models are typed in
``filled_rubber.py`` beside this file and solved exactly on a path of straight pieces, 10 us long
for the sine (Berg's friction from its definition, Maxwell elements by scipy's lsim, the
fractional derivative by the L1 sum). Nothing of ``fmu_src`` or ``identification`` is imported.

The tests (paper §4.1-4.3, ``identification.measured.signals``): x = 2 mm * sin(2*pi*10 Hz*t) over 1 s,
and a ramp from 0 to 2 mm over 0.4 s held to 10 s. The bushing starts in relaxed equilibrium at
x(0) = 0, with the velocity of the input at t = 0 (the sine starts moving at once). At t = 0.4 s
the step's velocity jumps from 5 mm/s to 0; the sample there is the right limit (dx/dt = 0, as
``Step.signals`` gives it), which is lower than the left limit by the viscous feedthrough
(8.4 N for the proposed model).

``--check-convergence`` solves every ODE case again with 10x tighter tolerances (the filled-rubber
sines on 10x shorter pieces) and prints the largest difference relative to the peak |F| (the
README quotes it); the files are not rewritten. ``--model NAME`` restricts either to one model
(the other models' files are left as they are).

Units: time s, displacement mm, velocity mm/s, force N, parameters in the paper's N-mm-s.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import scipy
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))
import filled_rubber  # noqa: E402  (numpy and scipy only)
import free_decoupler_mount  # noqa: E402  (numpy and scipy only)

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
DATA = REPO / "data"

SAMPLE_S = 1e-3
SINE = {"name": "sine_2mm_10Hz", "amplitude_mm": 2.0, "frequency_hz": 10.0, "duration_s": 1.0}
STEP = {"name": "step_2mm_rise0.4s", "amplitude_mm": 2.0, "rise_time_s": 0.4, "duration_s": 10.0}

RTOL = 1e-10
ATOL_MM = 1e-12      # on the states in mm (y, w)
ATOL_N = 1e-9        # on the hysteretic forces in N (z, up to ~1e3 N): the same 1e-12 relative to their scale
ATOL_MM_S = 1e-10    # on velocities in mm/s (the hydraulic mount's fluid column w, up to ~1e2 mm/s): the same 1e-12
MAX_STEP_S = 1e-3    # 1/100 of the sine's period
TIGHTER = 10.0       # the convergence check divides rtol and atol by this

MODELS = {
    # name: (parameter file in data/, description)
    "proposed": ("params_table5_combined.json", "the paper's proposed model, eqs. 1-5, with its Table 5"),
    "spencer": ("params_spencer_fit_synthetic_table5.json",
                "Spencer et al. 1997, the paper's Fig. 7, as the project fitted it to the synthetic Table 5 tests"),
    "single_bouc_wen": ("params_single_bouc_wen_fit_synthetic_table5.json",
                        "single Bouc-Wen element, the paper's Fig. 6, as the project fitted it to the synthetic "
                        "Table 5 tests"),
    "asymmetric_bouc_wen": ("params_asymmetric_bouc_wen_illustrative.json",
                            "a spring with free play +-gap (corners rounded over width) in series with a slider "
                            "whose yield is zp one way and zn the other, sharpness n, breakaway eps over delta; "
                            "k0 and c0 in parallel; an illustrative bushing"),
    "kelvin_voigt": ("params_kelvin_voigt_fit_synthetic_table5.json",
                     "Kelvin-Voigt F = k*x + c*dx/dt + preload, as the project fitted it to the synthetic "
                     "Table 5 tests"),
    "berg": ("params_berg_filled_rubber.json",
             "Berg 1998: spring k0*x + k3*x^3, Berg's friction, two Maxwell elements; an illustrative filled rubber"),
    "fractional": ("params_fractional_filled_rubber.json",
                   "spring k0*x + k3*x^3, Berg's friction, b*D^alpha x (the exact fractional derivative); an "
                   "illustrative filled rubber"),
    "hydraulic": ("params_hydraulic_mount.json",
                  "hydraulic mount: rubber k0, c0 and a Maxwell element in parallel with bulge kb, inertia track "
                  "mf, cf, ct, bellows kc and a tanh decoupler of travel gap; an illustrative engine mount"),
    "hydraulic_free_decoupler": ("params_hydraulic_free_decoupler.json",
                                 "hydraulic mount with a free decoupler plate: rubber k0, k3, c0 and a Maxwell "
                                 "element in parallel with bulge kb, inertia track mf, cf, ct, bellows kc and a plate "
                                 "free within +-gap, then caged (kcage, engagement width, centring kd); an "
                                 "illustrative engine mount (free_decoupler_mount.py)"),
}
PATH_MODELS = ("berg", "fractional")
"""Solved on a fine straight-piece path (filled_rubber.py), not by an ODE solver."""
FINE_SINE_S = 1e-5
"""The straight pieces that stand for the continuous sine of the path models: the friction's
reversal and the fractional derivative of this path differ from the sine's by < 1e-7 of the peak."""


# ------------------------------------------------------------------------------ inputs
def sine_input(t):
    """(x [mm], dx/dt [mm/s]) of the 2 mm / 10 Hz sine."""
    omega = 2.0 * np.pi * SINE["frequency_hz"]
    return SINE["amplitude_mm"] * np.sin(omega * t), SINE["amplitude_mm"] * omega * np.cos(omega * t)


def step_input(t):
    """(x [mm], dx/dt [mm/s]) of the 2 mm step with 0.4 s rise: dx/dt = 0 from t = 0.4 s on."""
    t = np.asarray(t, dtype=float)
    rate = STEP["amplitude_mm"] / STEP["rise_time_s"]
    rising = t < STEP["rise_time_s"]
    return np.where(rising, rate * t, STEP["amplitude_mm"]), np.where(rising, rate, 0.0)


# ------------------------------------------------------------------------------ equations
def bouc_wen_rate(u, z, A, beta, gamma, n):
    """dz/dt of eqs. 1-2: u*[A - (gamma + beta*sgn(u)*sgn(z))*|z|^n], u the element's relative velocity."""
    return u * (A - (gamma + beta * np.sign(u) * np.sign(z)) * abs(z) ** n)


def proposed_rhs(t, state, p, signal):
    """d/dt (y, z1, w, z2) of the proposed model, eqs. 1-4."""
    y, z1, w, z2 = state
    x, xd = signal(t)
    yd = (p["c1"] * xd + p["k1"] * (x - y) - p["k0"] * y + p["alpha1"] * z1) / p["c1"]        # eq. 3
    wd = (p["c2"] * xd + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])         # eq. 4
    return [yd, bouc_wen_rate(xd - yd, z1, p["A1"], p["beta1"], p["gamma1"], p["n1"]),     # eq. 1
            wd, bouc_wen_rate(xd - wd, z2, p["A2"], p["beta2"], p["gamma2"], p["n2"])]     # eq. 2


def proposed_force(p, states, x, xd):
    """Eq. 5 with eq. 4: F = k0*y + c0*dw/dt."""
    y, _, w, z2 = states
    return p["k0"] * y + p["c0"] * (p["c2"] * xd + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])


def proposed_start(p, x0):
    """Relaxed equilibrium at x0: z1 = z2 = 0, w = x0, and k1*(x0 - y) = k0*y."""
    return [p["k1"] * x0 / (p["k0"] + p["k1"]), 0.0, x0, 0.0]


def spencer_rhs(t, state, p, signal):
    """d/dt (y, z) of Spencer's model: dy/dt = [alpha*z + c0*dx/dt + k0*(x - y)]/(c0 + c1),
    dz/dt = -gamma*|u|*z*|z|^(n-1) - beta*u*|z|^n + A*u, u = dx/dt - dy/dt (Spencer's beta,
    gamma; written out, not through bouc_wen_rate, which names them the paper's way)."""
    y, z = state
    x, xd = signal(t)
    yd = (p["alpha"] * z + p["c0"] * xd + p["k0"] * (x - y)) / (p["c0"] + p["c1"])
    u = xd - yd
    zd = -p["gamma"] * abs(u) * z * abs(z) ** (p["n"] - 1.0) - p["beta"] * u * abs(z) ** p["n"] + p["A"] * u
    return [yd, zd]


def spencer_force(p, states, x, xd):
    """F = c1*dy/dt + k1*(x - x0)."""
    y, z = states
    yd = (p["alpha"] * z + p["c0"] * xd + p["k0"] * (x - y)) / (p["c0"] + p["c1"])
    return p["c1"] * yd + p["k1"] * (x - p["x0"])


def spencer_start(p, x0):
    """At rest at x0: y = x0, z = 0."""
    return [x0, 0.0]


def single_bouc_wen_rhs(t, state, p, signal):
    """dz/dt = dx/dt*[A - (gamma + beta*sgn(dx/dt)*sgn(z))*|z|^n] (eq. 1's form)."""
    _, xd = signal(t)
    return [bouc_wen_rate(xd, state[0], p["A"], p["beta"], p["gamma"], p["n"])]


def single_bouc_wen_force(p, states, x, xd):
    """F = c0*dx/dt + k0*x + alpha*z."""
    return p["c0"] * xd + p["k0"] * x + p["alpha"] * states[0]


def single_bouc_wen_start(p, x0):
    return [0.0]


def softplus(z):
    """log(1 + exp(z)) without overflow (numpy's logaddexp)."""
    return np.logaddexp(0.0, z)


def asymmetric_play(p, e):
    """The play: width*(softplus((e - gap)/width) - softplus((-e - gap)/width)) [mm]."""
    w, g = p["width"], p["gap"]
    return w * (softplus((e - g) / w) - softplus((-e - g) / w))


def asymmetric_rhs(t, state, p, signal):
    """d/dt (e, q): de/dt = dx/dt*(1 - s), dq/dt = ((1 - q)*(1 - s) - q*s)*|dx/dt|/delta with the
    sliding share s = (|z|/Z)^n where z*dx/dt > 0 (else 0), z = A*play(e), and the yield
    Z = (zp if z > 0 else zn)*(1 + eps*q)."""
    e, q = state
    _, xd = signal(t)
    z = p["A"] * asymmetric_play(p, e)
    s = 0.0
    if z * xd > 0.0:
        level = (p["zp"] if z > 0.0 else p["zn"]) * (1.0 + p["eps"] * q)
        s = (abs(z) / level) ** p["n"]
    return [xd * (1.0 - s), ((1.0 - q) * (1.0 - s) - q * s) * abs(xd) / p["delta"]]


def asymmetric_force(p, states, x, xd):
    """F = c0*dx/dt + k0*x + A*play(e)."""
    return p["c0"] * xd + p["k0"] * x + p["A"] * asymmetric_play(p, states[0])


def asymmetric_start(p, x0):
    """At rest: e = 0 (the play's centre), q = 1 (stuck)."""
    return [0.0, 1.0]


def hydraulic_track(p, x, y):
    """(kb*(x - y - u), dp) of the hydraulic mount: the fluid path's force on the mount [N] and
    the pressure difference that drives the inertia track [N], with the chambers' pressure
    difference (decoupler closed) P = kb*(x - y) - kc*y and the decoupler's travel
    u = gap*tanh(P/((kb + kc + kd)*gap)), u = 0 where gap = 0."""
    kb, kc, gap = p["kb"], p["kc"], p["gap"]
    pressure = kb * (x - y) - kc * y
    u = gap * np.tanh(pressure / ((kb + kc + p["kd"]) * gap)) if gap > 0.0 else 0.0 * pressure
    return kb * (x - y - u), pressure - (kb + kc) * u


def hydraulic_rhs(t, state, p, signal):
    """d/dt (y, w, f1) of the hydraulic mount: dy/dt = w, mf*dw/dt = dp - cf*w - ct*|w|*w (the
    fluid column in the inertia track), df1/dt = k1*dx/dt - (k1/c1)*f1 (the rubber's Maxwell element)."""
    y, w, f1 = state
    x, xd = signal(t)
    _, drive = hydraulic_track(p, x, y)
    return [w, (drive - p["cf"] * w - p["ct"] * abs(w) * w) / p["mf"], p["k1"] * xd - p["k1"] / p["c1"] * f1]


def hydraulic_force(p, states, x, xd):
    """F = k0*x + c0*dx/dt + f1 + kb*(x - y - u)."""
    y, _, f1 = states
    bulge, _ = hydraulic_track(p, x, y)
    return p["k0"] * x + p["c0"] * xd + f1 + bulge


def hydraulic_start(p, x0):
    """Relaxed at x0: the chambers' pressures equal (P = 0: y = kb*x0/(kb + kc), u = 0), the
    fluid still, the Maxwell element relaxed."""
    return [p["kb"] * x0 / (p["kb"] + p["kc"]), 0.0, 0.0]


EQUATIONS = {
    "proposed": (proposed_rhs, proposed_force, proposed_start, [ATOL_MM, ATOL_N, ATOL_MM, ATOL_N]),
    "spencer": (spencer_rhs, spencer_force, spencer_start, [ATOL_MM, ATOL_N]),
    "single_bouc_wen": (single_bouc_wen_rhs, single_bouc_wen_force, single_bouc_wen_start, [ATOL_N]),
    "asymmetric_bouc_wen": (asymmetric_rhs, asymmetric_force, asymmetric_start, [ATOL_MM, ATOL_MM]),
    "hydraulic": (hydraulic_rhs, hydraulic_force, hydraulic_start, [ATOL_MM, ATOL_MM_S, ATOL_N]),
    "hydraulic_free_decoupler": (free_decoupler_mount.rhs, free_decoupler_mount.force, free_decoupler_mount.start,
                                 [ATOL_MM, ATOL_MM_S, ATOL_N]),
}


# ------------------------------------------------------------------------------ solving
def read_parameters(model: str) -> dict[str, float]:
    """The ``parameters`` of the model's JSON file, as plain JSON (not the project's reader)."""
    return {name: float(value) for name, value in
            json.loads((DATA / MODELS[model][0]).read_text())["parameters"].items()}


def sample_times(duration_s: float) -> np.ndarray:
    """0, 1 ms, ..., duration (inclusive), as ``identification.measured.signals.sample_times``."""
    return np.arange(round(duration_s / SAMPLE_S) + 1) / round(1.0 / SAMPLE_S)


def solve(model: str, p: dict, test: dict, tighter: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(time_s, displacement_mm, force_N) of ``model`` on ``test`` at the 1 ms samples."""
    signal = sine_input if test is SINE else step_input
    t = sample_times(test["duration_s"])
    x, xd = signal(t)
    if model == "kelvin_voigt":
        return t, x, p["k"] * x + p["c"] * xd + p["preload"]
    if model in PATH_MODELS:
        return t, x, solve_path(model, p, test, tighter)
    rhs, force, start, atol = EQUATIONS[model]
    if test is SINE:
        pieces = [(0.0, test["duration_s"], sine_input)]
    else:
        # The step's velocity jumps at the rise time: each smooth piece is integrated on its own,
        # the ramp with its own velocity up to and including its end.
        rate, rise = STEP["amplitude_mm"] / STEP["rise_time_s"], STEP["rise_time_s"]
        pieces = [(0.0, rise, lambda s: (rate * s, rate + 0.0 * s)),
                  (rise, test["duration_s"], lambda s: (STEP["amplitude_mm"] + 0.0 * s, 0.0 * s))]
    state = np.array(start(p, float(x[0])), dtype=float)
    states = np.empty((state.size, t.size))
    for begin, end, piece in pieces:
        inside = (t >= begin) & (t <= end)
        solution = solve_ivp(rhs, (begin, end), state, method="Radau", t_eval=t[inside], args=(p, piece),
                             rtol=RTOL / tighter, atol=np.array(atol) / tighter, max_step=MAX_STEP_S)
        if not solution.success:
            raise RuntimeError(f"{model}, {test['name']}: {solution.message}")
        states[:, inside] = solution.y    # the state is continuous: a break point's sample from either piece
        state = solution.y[:, -1]
    # eq. 5 etc. with the test's velocity at each sample (at the rise time: dx/dt = 0, the right limit)
    return t, x, force(p, states, x, xd)


def solve_path(model: str, p: dict, test: dict, tighter: float = 1.0) -> np.ndarray:
    """The force [N] at the 1 ms samples of a filled-rubber model (filled_rubber.py): the step is
    straight pieces between the samples already (its corners are samples); the sine runs on
    pieces of FINE_SINE_S / ``tighter``, then is read at every 1 ms."""
    if test is STEP:
        t = sample_times(test["duration_s"])
        return filled_rubber.FORCES[model](p, t, step_input(t)[0])
    per_sample = round(SAMPLE_S / (FINE_SINE_S / tighter))
    fine = np.arange(round(test["duration_s"] / SAMPLE_S) * per_sample + 1) * (SAMPLE_S / per_sample)
    return filled_rubber.FORCES[model](p, fine, sine_input(fine)[0])[::per_sample]


def header(model: str, test: dict) -> str:
    if test is SINE:
        signal = "x = 2 mm * sin(2*pi*10 Hz*t), t = 0..1 s"
    else:
        signal = "x = ramp 0 -> 2 mm over 0.4 s, held to 10 s (dx/dt = 0 from t = 0.4 s: the right limit there)"
    if model == "kelvin_voigt":
        solver = "closed form F = k*x + c*dx/dt + preload (no state, nothing to integrate)"
    elif model in PATH_MODELS:
        solver = (f"exact on straight pieces (tests/references/filled_rubber.py: Berg's friction, lsim, the L1 sum), "
                  f"pieces of {'1 ms' if test is STEP else f'{FINE_SINE_S:g} s'}, from rest at x(0)")
    else:
        velocity = f" / {ATOL_MM_S:g} mm/s" if ATOL_MM_S in EQUATIONS[model][3] else ""
        solver = (f"scipy {scipy.__version__} solve_ivp Radau, rtol = {RTOL:g}, atol = {ATOL_MM:g} mm{velocity} "
                  f"/ {ATOL_N:g} N, max_step = {MAX_STEP_S:g} s, from relaxed equilibrium at x(0)")
    return (f"# model: {model} ({MODELS[model][1]}); parameters: data/{MODELS[model][0]}; signal: {signal}, "
            f"sampled every 1 ms; solver: {solver}; generator: tests/references/generate_references.py")


def write_csv(path: Path, model: str, test: dict, t, x, force) -> None:
    lines = [header(model, test), "time_s,displacement_mm,force_N"]
    lines += [f"{ti:.3f},{xi:.12g},{fi:.6f}" for ti, xi, fi in zip(t, x, force)]
    path.write_text("\n".join(lines) + "\n")


def read_csv(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(time_s, displacement_mm, force_N) of a reference CSV."""
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=2)
    return data[:, 0], data[:, 1], data[:, 2]


def plot(path: Path, model: str, sine, step) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t_sine, x_sine, f_sine = sine
    t_step, x_step, f_step = step
    figure, (loops, response) = plt.subplots(1, 2, figsize=(11, 4.2))
    period = 1.0 / SINE["frequency_hz"]
    first, last = t_sine <= period + 1e-9, t_sine >= SINE["duration_s"] - period - 1e-9
    loops.plot(x_sine[first], f_sine[first] / 1e3, color="0.6", lw=1, label="first cycle (from rest)")
    loops.plot(x_sine[last], f_sine[last] / 1e3, color="C0", lw=2, label="10th cycle")
    loops.set(xlabel="displacement x [mm]", ylabel="force F [kN]", title="Sine 2 mm, 10 Hz: hysteresis loop")
    loops.legend(loc="upper left")
    loops.grid(alpha=0.3)
    response.plot(t_step, f_step / 1e3, color="C3", lw=2)
    response.set(xlabel="time [s]", ylabel="force F [kN]", title="Step 2 mm, rise time 0.4 s")
    twin = response.twinx()
    twin.plot(t_step, x_step, color="0.5", ls="--", lw=1)
    twin.set_ylabel("displacement x [mm] (dashed)")
    response.grid(alpha=0.3)
    method = {"kelvin_voigt": "closed form", "berg": "straight pieces", "fractional": "straight pieces"}
    figure.suptitle(f"{model}: reference (data/{MODELS[model][0]}; {method.get(model, 'scipy Radau')}, 1 ms samples)")
    figure.tight_layout()
    figure.savefig(path, dpi=80, metadata={"Software": None})   # no version stamp: same bytes on a rerun
    plt.close(figure)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check-convergence", action="store_true",
                        help="solve again with 10x tighter tolerances and print the differences; write nothing")
    parser.add_argument("--model", choices=list(MODELS), metavar="NAME",
                        help=f"only this model ({', '.join(MODELS)}); the other models' files are left as they are")
    args = parser.parse_args(argv)
    for model in ([args.model] if args.model else MODELS):
        p = read_parameters(model)
        results = {}
        for test in (SINE, STEP):
            t, x, force = solve(model, p, test)
            results[test["name"]] = (t, x, force)
            peak = np.max(np.abs(force))
            if args.check_convergence:
                if model == "kelvin_voigt":
                    continue
                _, _, finer = solve(model, p, test, tighter=TIGHTER)
                print(f"{model:16s} {test['name']:18s} peak |F| {peak:9.3f} N, max |F - F_tighter| "
                      f"{np.max(np.abs(force - finer)):.2e} N = {np.max(np.abs(force - finer)) / peak:.1e} of the peak")
            else:
                write_csv(HERE / f"{model}_{test['name']}.csv", model, test, t, x, force)
                print(f"{model:16s} {test['name']:18s} peak |F| {peak:9.3f} N")
        if not args.check_convergence:
            plot(HERE / f"{model}.png", model, results[SINE["name"]], results[STEP["name"]])
    return 0


if __name__ == "__main__":
    sys.exit(main())
