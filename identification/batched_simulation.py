"""The model core's integrator over a whole population of parameter sets at once (numpy).

Each function mirrors its scalar twin in ``fmu_src.bushing_core`` operation for operation,
with ``numpy.where`` in place of branches and per-candidate substep counts (a candidate that
has finished its step takes steps of length 0 and is masked out), so every candidate
follows the scalar path: ``tests/test_batched_simulation.py`` checks the forces against the
FMU to 1e-9. Large displacement jumps, rare, are handed to the scalar code itself.

Units as in the core: mm, mm/s, N, s; parameters in the paper's N-mm-s units. A candidate
whose step fails (overflow, non-finite state, too many substeps) gets NaN forces from then on.
"""
from __future__ import annotations

from typing import Mapping, NamedTuple

import numpy as np

from fmu_src import bushing_core as core
from fmu_src.bushing_params import PARAMETER_NAMES


class _Block(NamedTuple):
    K: np.ndarray
    alpha: np.ndarray
    c: np.ndarray
    A: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray
    n: np.ndarray


class BatchModel(NamedTuple):
    k0: np.ndarray
    k1: np.ndarray
    k2: np.ndarray
    c0: np.ndarray
    c1: np.ndarray
    c2: np.ndarray
    C: np.ndarray
    K1: np.ndarray
    alpha1: np.ndarray
    alpha2: np.ndarray
    block1: _Block
    block2: _Block


def parameter_matrix(parameter_sets) -> np.ndarray:
    """(P, 16) array in PARAMETER_NAMES order from a sequence of mappings or a (P, 16) array."""
    if isinstance(parameter_sets, np.ndarray):
        matrix = np.atleast_2d(np.asarray(parameter_sets, dtype=float))
    else:
        matrix = np.array([[float(p[name]) for name in PARAMETER_NAMES] for p in parameter_sets])
    if matrix.ndim != 2 or matrix.shape[1] != len(PARAMETER_NAMES):
        raise ValueError(f"expected a (P, {len(PARAMETER_NAMES)}) parameter matrix, got shape {matrix.shape}")
    return matrix


def compile_batch(matrix: np.ndarray) -> BatchModel:
    """The batched counterpart of ``bushing_core.compile_model``."""
    p = {name: matrix[:, i].copy() for i, name in enumerate(PARAMETER_NAMES)}
    C = p["c0"] + p["c2"]
    K1 = p["k0"] + p["k1"]
    return BatchModel(
        k0=p["k0"], k1=p["k1"], k2=p["k2"], c0=p["c0"], c1=p["c1"], c2=p["c2"], C=C, K1=K1,
        alpha1=p["alpha1"], alpha2=p["alpha2"],
        block1=_Block(K1, p["alpha1"], p["c1"], p["A1"], p["beta1"], p["gamma1"], p["n1"]),
        block2=_Block(p["k2"], p["alpha2"], C, p["A2"], p["beta2"], p["gamma2"], p["n2"]),
    )


def _gain(z, A, cpos, cneg, n):
    return A - np.where(z > 0.0, cpos, cneg) * np.abs(z) ** n


def _decay_factors(x):
    small = np.abs(x) < 1e-3
    E = np.exp(-x)
    phi1 = (1.0 - E) / x
    phi2 = (1.0 - phi1) / x
    return (np.where(small, 1.0 - x + 0.5 * x * x, E),
            np.where(small, 1.0 - 0.5 * x + x * x / 6.0, phi1),
            np.where(small, 0.5 - x / 6.0 + x * x / 24.0, phi2))


def _rk4_in_xi(z, dxi, A, cpos, cneg, n):
    k1 = _gain(z, A, cpos, cneg, n)
    k2 = _gain(z + 0.5 * dxi * k1, A, cpos, cneg, n)
    k3 = _gain(z + 0.5 * dxi * k2, A, cpos, cneg, n)
    k4 = _gain(z + dxi * k3, A, cpos, cneg, n)
    return z + dxi * (k1 + 2.0 * (k2 + k3) + k4) / 6.0


def _segment(u0, z0, h, a, blk, sigma):
    K, alpha, c, A, beta, gamma, n = blk
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = _gain(z0, A, cpos, cneg, n)
    E0, phi1_0, phi2_0 = _decay_factors((K + alpha * g0) / c * h)
    xi = h * (u0 * phi1_0 + a * h * phi2_0)
    still = xi == 0.0
    z1 = _rk4_in_xi(z0, xi, A, cpos, cneg, n)
    lam = (K + alpha * (z1 - z0) / np.where(still, 1.0, xi)) / c
    E, phi1, phi2 = _decay_factors(lam * h)
    corrected = h * (u0 * phi1 + a * h * phi2)
    small = np.abs(corrected - xi) <= 0.01 * np.abs(xi)
    z_end = z1 + _gain(z1, A, cpos, cneg, n) * (corrected - xi)
    repeat = np.flatnonzero(~small & ~still)
    if repeat.size:  # the RK4 repeat only where the Taylor step is not enough
        pick = (lambda array: array[repeat] if np.ndim(array) else array)
        z_end[repeat] = _rk4_in_xi(z0[repeat], corrected[repeat], pick(A), pick(cpos), pick(cneg), pick(n))
    return (np.where(still, u0 * E0 + a * h * phi1_0, u0 * E + a * h * phi1),
            np.where(still, z0, z_end),
            np.where(still, 0.0, corrected))


def _block_step(u0, z0, h, a, blk):
    K, alpha, c, A, beta, gamma, n = blk
    sigma = np.where(u0 > 0.0, 1.0, np.where(u0 < 0.0, -1.0, np.where(a > 0.0, 1.0, -1.0)))
    cz = np.where(z0 > 0.0, gamma + beta * sigma, gamma - beta * sigma)
    lam = (K + alpha * (A - cz * np.abs(z0) ** n)) / c
    u_target = a / lam
    t_cross = -np.log(u_target / (u_target - u0)) / lam
    crosses = (a * u0 < 0.0) & (lam > 0.0) & (t_cross < h)
    u, z, xi = _segment(u0, z0, np.where(crosses, t_cross, h), a, blk, sigma)
    across = np.flatnonzero(crosses)
    if across.size:  # the rest of the substep, from u = 0 on the other branch
        pick = (lambda array: array[across] if np.ndim(array) else array)
        u_b, z_b, xi_b = _segment(np.zeros(across.size), z[across], (h - t_cross)[across], pick(a),
                                  _Block(*(pick(array) for array in blk)), -sigma[across])
        u[across], z[across], xi[across] = u_b, z_b, xi[across] + xi_b
    return u, z, xi


def _substeps_needed(u0, z0, T, a, blk):
    K, alpha, c, A, beta, gamma, n = blk
    heads_across = (a * u0 <= 0.0) & (a != 0.0)
    sigma = np.where(heads_across, np.where(a > 0.0, 1.0, -1.0), np.where(u0 >= 0.0, 1.0, -1.0))
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = _gain(z0, A, cpos, cneg, n)
    lam_c = K + alpha * g0
    target = a * c / lam_c
    rate = np.where((a != 0.0) & (lam_c > 0.0) & (np.abs(target) > np.abs(u0)), target, u0)
    z_pred = z0 + g0 * rate * T
    g_pred = _gain(z_pred, A, cpos, cneg, n)
    crosses_zero = (z_pred > 0.0) != (z0 > 0.0)
    dg = np.where(crosses_zero, np.abs(g0 - A) + np.abs(g_pred - A), np.abs(g_pred - g0))
    rel = np.where(g0 != 0.0, dg / np.abs(g0), np.inf)
    rel_lam = np.abs(alpha) * dg / (np.abs(lam_c) + c / T)
    worst = np.maximum(rel, rel_lam)
    count = np.ceil(np.where(np.isfinite(worst) & (worst <= 1e9), worst, 1e9 * core.THETA) / core.THETA)
    return np.where((dg == 0.0) | (worst <= core.THETA), 1.0, count)


def _apply_jump(model, scalar_models, state, jump_mm, alive):
    """``bushing_core.apply_displacement_jump`` for every candidate: Heun's step where g2
    changes by under 1 %, the scalar code itself elsewhere."""
    y, z1, w, z2 = state
    K, alpha, c, A, beta, gamma, n = model.block2
    xi = model.c0 / model.C * jump_mm
    sigma = np.where(xi > 0.0, 1.0, -1.0)
    cpos = gamma + beta * sigma
    cneg = gamma - beta * sigma
    g0 = _gain(z2, A, cpos, cneg, n)
    z_pred = z2 + g0 * xi
    g_pred = _gain(z_pred, A, cpos, cneg, n)
    crosses_zero = (z_pred > 0.0) != (z2 > 0.0)
    dg = np.where(crosses_zero, np.abs(g0 - A) + np.abs(g_pred - A), np.abs(g_pred - g0))
    heun = ~crosses_zero & (dg <= core.HEUN_JUMP_LIMIT * np.abs(g0))
    new = [y + jump_mm, z1.copy(), w + (model.C - model.c0) / model.C * jump_mm, z2 + 0.5 * xi * (g0 + g_pred)]
    for i in np.flatnonzero(~heun & alive):
        try:
            jumped = core.apply_displacement_jump(scalar_models[i], (y[i], z1[i], w[i], z2[i]), jump_mm)
            for array, value in zip(new, jumped):
                array[i] = value
        except (core.StepError, OverflowError, ZeroDivisionError, ValueError):
            for array in new:
                array[i] = np.nan
    return tuple(new)


def _take(model: BatchModel, keep) -> BatchModel:
    """The candidates selected by ``keep`` (index array or mask)."""
    def pick(arrays):
        return type(arrays)(*(array[keep] for array in arrays))
    fields = [array[keep] for array in model[:10]]
    return BatchModel(*fields, pick(model.block1), pick(model.block2))


def _advance(model, scalar_models, state, state_x, x, v, h, alive, max_substeps):
    """``bushing_core.advance`` for every candidate (shared input x, v, h). Candidates that
    finish the step leave the working set, so extra substeps cost only where needed."""
    if x != state_x:
        state = _apply_jump(model, scalar_models, state, x - state_x, alive)
    full = [np.array(s, dtype=float) for s in state]
    index = np.flatnonzero(alive)
    sub_model = model if index.size == alive.size else _take(model, index)
    y, z1, w, z2 = (array[index] for array in full)
    elapsed = np.zeros(index.size)
    used = np.zeros(index.size)
    while index.size:
        k0, k1, k2, c0, c1, _, C, K1, alpha1, alpha2, blk1, blk2 = sub_model
        a1 = k0 * v / c1
        remaining = h - elapsed
        x_now = x + v * elapsed
        u1 = -(k1 * (x_now - y) - k0 * y + alpha1 * z1) / c1
        u2 = (c0 * v - k2 * (x_now - w) - alpha2 * z2) / C
        count = np.maximum(_substeps_needed(u1, z1, remaining, a1, blk1),
                           _substeps_needed(u2, z2, remaining, 0.0, blk2))
        failed = (used + 1 > max_substeps) | (count > max_substeps) | ~np.isfinite(count)
        last = count == 1.0
        sub = np.where(failed, 0.0, np.where(last, remaining, remaining / np.where(failed, 1.0, count)))
        u1, z1, xi1 = _block_step(u1, z1, sub, a1, blk1)
        u2, z2, xi2 = _block_step(u2, z2, sub, 0.0, blk2)
        elapsed = np.where(last, h, elapsed + sub)
        x_now = x + v * elapsed
        safe_K1 = np.where(K1 > 0.0, K1, 1.0)
        y = np.where(K1 > 0.0, (k1 * x_now + alpha1 * z1 + c1 * u1) / safe_K1, y + v * sub - xi1)
        w = w + v * sub - xi2
        used += 1
        for array, values in zip(full, (y, z1, w, z2)):
            array[index] = values
        alive[index[failed]] = False
        keep = ~(last | failed)
        if not keep.all():
            index, elapsed, used = index[keep], elapsed[keep], used[keep]
            y, z1, w, z2 = y[keep], z1[keep], w[keep], z2[keep]
            sub_model = _take(sub_model, keep)
    finite = np.isfinite(full[0]) & np.isfinite(full[1]) & np.isfinite(full[2]) & np.isfinite(full[3])
    alive &= finite
    return tuple(full), alive


def simulate_batch(parameter_sets, time_s, displacement_mm, velocity_mm_s,
                   max_substeps: int = core.DEFAULT_MAX_SUBSTEPS) -> np.ndarray:
    """Forces [N], shape (P, samples), of P parameter sets on one sampled input.

    The same convention as ``identification.simulate.simulate`` (and the FMU with a
    communication point at every sample). Parameter sets must be valid
    (``bushing_params.validate_parameters``); candidates that fail a step get NaN.
    """
    matrix = parameter_matrix(parameter_sets)
    model = compile_batch(matrix)
    scalar_models = [core.compile_model(dict(zip(PARAMETER_NAMES, row))) for row in matrix]
    t = np.asarray(time_s, dtype=float)
    x = np.asarray(displacement_mm, dtype=float)
    v = np.asarray(velocity_mm_s, dtype=float)
    count = matrix.shape[0]
    state_x = float(x[0])
    y0 = np.where(model.K1 > 0.0, model.k1 * state_x / np.where(model.K1 > 0.0, model.K1, 1.0), state_x)
    state = (y0, np.zeros(count), np.full(count, state_x), np.zeros(count))
    alive = np.ones(count, dtype=bool)
    forces = np.empty((count, t.size))
    forces[:, 0] = _force(model, state, state_x, float(v[0]))
    with np.errstate(all="ignore"):
        for k in range(t.size - 1):
            x_k, v_k = float(x[k]), float(v[k])
            state, alive = _advance(model, scalar_models, state, state_x, x_k, v_k,
                                    float(t[k + 1]) - float(t[k]), alive, max_substeps)
            state_x = x_k + v_k * (float(t[k + 1]) - float(t[k]))
            forces[:, k + 1] = np.where(alive, _force(model, state, state_x, v_k), np.nan)
    return forces


def _force(model: BatchModel, state, x, v):
    """Eq. 5 with eq. 4, as ``bushing_core.force``."""
    y, _, w, z2 = state
    return model.k0 * y + model.c0 * ((model.c2 * v + model.k2 * (x - w) + model.alpha2 * z2) / model.C)


def as_parameter_dicts(matrix: np.ndarray) -> list[Mapping[str, float]]:
    return [dict(zip(PARAMETER_NAMES, row)) for row in parameter_matrix(matrix)]
