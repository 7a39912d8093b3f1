"""Reference results of the coupled (plane) bushing models on paths in the plane.

    python tests/references/generate_coupled_references.py [--check-convergence]

Writes, next to this file, ``coupled_<model>_<path>.csv`` (columns time_s, dx_mm, dy_mm, Fx_N,
Fy_N; 1 ms samples) for the proposed model (the paper's Table 5), Spencer's and the single
Bouc-Wen (the project's fitted sets), and Berg's and the fractional model (the illustrative
filled-rubber sets), on four paths: circles of 0.5 mm at 9.7 Hz and 4 mm at 4.7 Hz, an ellipse of
2 mm x 0.8 mm at 9.7 Hz and a random path in the plane (peak 3 mm, 0.5-20 Hz), each 0.5 s from rest.

The input is the co-simulation's: the displacement runs straight between the 1 ms samples with the
secant velocity, so the references measure the kernels' integration, not the sampling of a curve.

Independent of the code under test: the coupled equations are typed here as the issue and the
docs state them (every linear element on each component; each Bouc-Wen element
dz/dt = A*u - |z|^(n-2)*(gamma*(z.u) + beta*|z.u|)*z; Berg's friction in the plane
F = F_s + R*|d|*F_max/(x2*|R| + |d|*F_max), R = F_max*d/|d| - F_s, reversing where d.v < 0; the
progressive spring (k0 + k3*|x|^2)*x; the fractional element as its 20 Maxwell modes and upper
dashpot, from the model's docstring), parameter files are read as plain JSON, and scipy's Radau
(rtol 1e-10) integrates every straight piece. Nothing of ``fmu_src`` or ``identification`` is
imported.

``--check-convergence`` solves every case again with 10x tighter tolerances and prints the largest
difference relative to the peak |F|; the files are not rewritten.

Units: time s, displacement mm, velocity mm/s, force N, parameters in the paper's N-mm-s.
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

HERE = Path(__file__).resolve().parent
DATA = HERE.parents[1] / "data"

SAMPLE_S = 1e-3
DURATION_S = 0.5
RTOL = 1e-10
TIGHTER = 10.0

MODELS = {
    "proposed": "params_table5_combined.json",
    "spencer": "params_spencer_fit_synthetic_table5.json",
    "single_bouc_wen": "params_single_bouc_wen_fit_synthetic_table5.json",
    "berg": "params_berg_filled_rubber.json",
    "fractional": "params_fractional_filled_rubber.json",
}


def random_walk(t: np.ndarray) -> np.ndarray:
    """A seeded sum of 12 sines per axis, 0.5-20 Hz, from 0 [mm], unscaled."""
    rng = np.random.default_rng(41)
    frequencies = rng.uniform(0.5, 20.0, (12, 2))
    phases = rng.uniform(0.0, 2.0 * math.pi, (12, 2))
    amplitudes = rng.normal(size=(12, 2)) / frequencies      # a falling spectrum, as a road's
    return np.stack([np.sum(amplitudes[:, j, None] * (np.sin(2 * math.pi * frequencies[:, j, None] * t
                                                             + phases[:, j, None]) - np.sin(phases[:, j, None])),
                            axis=0) for j in range(2)], axis=1)


def random_path(t: np.ndarray) -> np.ndarray:
    """:func:`random_walk` scaled to a peak radius of 3 mm over the times ``t``."""
    xy = random_walk(t)
    return 3.0 * xy / np.max(np.hypot(xy[:, 0], xy[:, 1]))


def circle(radius_mm: float, frequency_hz: float):
    def path(t):
        w = 2.0 * math.pi * frequency_hz
        return np.stack([radius_mm * (np.cos(w * t) - 1.0), radius_mm * np.sin(w * t)], axis=1)
    return path


def ellipse(a_mm: float, b_mm: float, frequency_hz: float):
    def path(t):
        w = 2.0 * math.pi * frequency_hz
        return np.stack([a_mm * np.sin(w * t), b_mm * (1.0 - np.cos(w * t))], axis=1)
    return path


PATHS = {
    "circle_0.5mm_9.7Hz": circle(0.5, 9.7),
    "circle_4mm_4.7Hz": circle(4.0, 4.7),
    "ellipse_2x0.8mm_9.7Hz": ellipse(2.0, 0.8, 9.7),
    "random_3mm": random_path,
}


def samples() -> np.ndarray:
    return np.arange(round(DURATION_S / SAMPLE_S) + 1) * SAMPLE_S


def bouc_wen(z: np.ndarray, u: np.ndarray, A: float, beta: float, gamma: float, n: float) -> np.ndarray:
    """dz/dt of the isotropic element: A*u - |z|^(n-2)*(gamma*(z.u) + beta*|z.u|)*z."""
    r2 = float(z @ z)
    if r2 == 0.0:
        return A * u
    zu = float(z @ u)
    return A * u - r2 ** (0.5 * n - 1.0) * (gamma * zu + beta * abs(zu)) * z


class _Bushing:
    """A coupled model of parameters ``p`` whose ODE state (``size`` floats) starts at rest at 0."""
    size = 0

    def __init__(self, p):
        self.p = p

    def initial(self):
        return np.zeros(self.size)


class Proposed(_Bushing):
    """Eqs. 1-5 on each component; state (y, z1, w, z2), 2-vectors each."""
    size = 8

    def rates(self, s, x, v):
        p = self.p
        y, z1, w, z2 = s[0:2], s[2:4], s[4:6], s[6:8]
        dy = (p["c1"] * v + p["k1"] * (x - y) - p["k0"] * y + p["alpha1"] * z1) / p["c1"]
        dw = (p["c2"] * v + p["k2"] * (x - w) + p["alpha2"] * z2) / (p["c0"] + p["c2"])
        return np.concatenate([dy, bouc_wen(z1, v - dy, p["A1"], p["beta1"], p["gamma1"], p["n1"]),
                               dw, bouc_wen(z2, v - dw, p["A2"], p["beta2"], p["gamma2"], p["n2"])])

    def force(self, s, x, v):
        p = self.p
        dw = self.rates(s, x, v)[4:6]
        return p["k0"] * s[0:2] + p["c0"] * dw


class Spencer(_Bushing):
    """Spencer et al. on each component (x0 = 0); state (y, z). Spencer's gamma on |z.u|, beta on z.u."""
    size = 4

    def __init__(self, p):
        if p["x0"] != 0.0:
            raise ValueError("the coupled Spencer model takes x0 = 0")
        super().__init__(p)

    def u(self, s, x, v):
        p = self.p
        return (p["c1"] * v - p["k0"] * (x - s[0:2]) - p["alpha"] * s[2:4]) / (p["c0"] + p["c1"])

    def rates(self, s, x, v):
        p = self.p
        u = self.u(s, x, v)
        return np.concatenate([v - u, bouc_wen(s[2:4], u, p["A"], p["gamma"], p["beta"], p["n"])])

    def force(self, s, x, v):
        p = self.p
        return p["c1"] * (v - self.u(s, x, v)) + p["k1"] * x


class SingleBoucWen(_Bushing):
    """F = c0*v + k0*x + alpha*z; state z."""
    size = 2

    def rates(self, s, x, v):
        p = self.p
        return bouc_wen(s, v, p["A"], p["beta"], p["gamma"], p["n"])

    def force(self, s, x, v):
        p = self.p
        return p["c0"] * v + p["k0"] * x + p["alpha"] * s


class FrictionModel:
    """The progressive radial spring, Berg's friction in the plane and Maxwell elements on each
    component (stiffnesses k_j, rates r_j) and a dashpot; the friction's reversal point is kept
    outside the ODE state (x_s and F_s change only at the start of a straight piece)."""

    def __init__(self, p, stiffnesses, rates, dashpot):
        self.p, self.k, self.r, self.dashpot = p, np.asarray(stiffnesses), np.asarray(rates), dashpot
        self.size = 2 * len(self.k)

    def initial(self):
        self.x_s, self.F_s = np.zeros(2), np.zeros(2)
        return np.zeros(self.size)

    def friction(self, x):
        limit, half = self.p["Ff_max"], self.p["x2"]
        d = x - self.x_s
        r = math.hypot(*d)
        if r == 0.0:
            return self.F_s.copy()
        R = limit * d / r - self.F_s
        return self.F_s + R * r * limit / (half * math.hypot(*R) + r * limit)

    def start_piece(self, x, v):
        """A reversal where the piece's velocity shortens the travel since the last one."""
        if float((x - self.x_s) @ v) < 0.0:
            self.F_s, self.x_s = self.friction(x), x.copy()

    def rates(self, s, x, v):
        f = s.reshape(len(self.k), 2)
        return (self.k[:, None] * v[None, :] - self.r[:, None] * f).ravel()

    def force(self, s, x, v):
        p = self.p
        spring = (p["k0"] + p["k3"] * float(x @ x)) * x
        return spring + self.friction(x) + s.reshape(len(self.k), 2).sum(axis=0) + self.dashpot * v


def berg(p):
    return FrictionModel(p, [p["k1"], p["k2"]], [p["k1"] / p["c1"], p["k2"] / p["c2"]], 0.0)


def fractional(p):
    """The 19 modes at 1e-4 ... 1e5 1/s, two per decade, the lower tail and the upper dashpot, as the
    fractional model's docstring defines its realisation."""
    alpha, b, modes = p["alpha"], p["b"], 19
    d = math.log(10.0) / 2.0
    lowest = math.log(1e-4)
    scale = b * math.sin(alpha * math.pi) / math.pi
    rates = [math.exp(lowest + j * d) for j in range(modes)]
    stiffnesses = [scale * d * r ** alpha for r in rates]
    tail = math.exp(lowest - 0.5 * d)
    stiffnesses.append(scale * tail ** alpha / alpha)
    rates.append(tail * (1.0 - alpha) / alpha)
    top = math.exp(lowest + (modes - 0.5) * d)
    return FrictionModel(p, stiffnesses, rates, scale * top ** (alpha - 1.0) / (1.0 - alpha))


# Frequencies whose half period falls between samples: a circle from rest at a sample passes the
# point opposite its start at a sample otherwise, where the travel since the start and the
# secant velocity are exactly perpendicular (d.v = 0), and rounding would decide the friction's
# reversal there.
FACTORIES = {"proposed": Proposed, "spencer": Spencer, "single_bouc_wen": SingleBoucWen, "berg": berg,
             "fractional": fractional}


def parameters(model: str) -> dict:
    return json.loads((DATA / MODELS[model]).read_text())["parameters"]


def solve(model: str, path: str, tighter: float = 1.0) -> np.ndarray:
    """(samples, 5): time, dx, dy, Fx, Fy along the straight pieces between the samples."""
    t = samples()
    return solve_path(FACTORIES[model](parameters(model)), t, PATHS[path](t), SAMPLE_S, tighter)


def solve_path(bushing, t: np.ndarray, xy: np.ndarray, step_s: float, tighter: float = 1.0) -> np.ndarray:
    """(samples, 5): time, dx, dy, Fx, Fy of ``bushing`` (one of the classes above, with its
    parameters) along the straight pieces between the samples ``xy`` [mm] at the times ``t`` [s],
    ``step_s`` [s] apart."""
    state = bushing.initial()
    out = [(t[0], *xy[0], 0.0, 0.0)]
    for k in range(len(t) - 1):
        x0, v = xy[k], (xy[k + 1] - xy[k]) / step_s
        if hasattr(bushing, "start_piece"):
            bushing.start_piece(x0, v)
        solution = solve_ivp(lambda s, y: bushing.rates(y, x0 + v * (s - t[k]), v), (t[k], t[k + 1]), state,
                             method="Radau", rtol=RTOL / tighter, atol=RTOL / tighter * 1e-2)
        state = solution.y[:, -1]
        out.append((t[k + 1], *xy[k + 1], *bushing.force(state, xy[k + 1], v)))
    return np.array(out)


def file_of(model: str, path: str) -> Path:
    return HERE / f"coupled_{model}_{path}.csv"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check-convergence", action="store_true")
    args = parser.parse_args()
    for model in MODELS:
        for path in PATHS:
            result = solve(model, path)
            if args.check_convergence:
                finer = solve(model, path, TIGHTER)
                peak = np.max(np.abs(finer[:, 3:]))
                print(f"{model:16s} {path:22s} {np.max(np.abs(result[:, 3:] - finer[:, 3:])) / peak:.2e} of the peak")
                continue
            np.savetxt(file_of(model, path), result, delimiter=",", fmt="%.12g",
                       header="time_s,dx_mm,dy_mm,Fx_N,Fy_N", comments="")
            print(f"wrote {file_of(model, path).name}")


if __name__ == "__main__":
    main()
