"""The sine steady-state loop of the dynamic-stiffness characterisation, compiled per model.

:func:`_sine_steady_state` is written here and never called here: like the population loop of
``population``, its source is compiled in each model's generated population module, where
``prepare``, ``prepare_step``, ``step_prepared`` (``fmu_src.model.integration``) and ``force`` are
that model's compiled kernels (imported from ``numba_binding.kernel_module``) and ``_VALUES(row)``
a parameter row's values; the step's constants are made once
per case, whose steps all have the same size.

Per item (a parameter set and one sine x = P + X*sin(2*pi*f*t)): the bushing starts in relaxed
equilibrium at the preload P and is driven cycle after cycle, ``steps`` communication steps per
cycle on the secant path through the exact sine's samples (the forward model's input
convention, ``identification.forward.input_path``), the force read at each sample with the sine's
exact velocity. After each cycle its first harmonic, as the sums

    a = (2/N) * sum F_k*cos(phi_k),   b = (2/N) * sum F_k*sin(phi_k),   phi_k = 2*pi*k/N,

is compared with the previous cycle's: K* = (b + i*a)/X (a Kelvin-Voigt F = k*x + c*v gives
b = k*X, a = c*omega*X). Steady state (the criterion): from ``min_cycles`` on, the relative
change d_j = |K*_j - K*_(j-1)|/|K*_j| is at most ``tolerance`` and so is what is left of a
geometric approach, d_j*r/(1 - r) with r = d_j/d_(j-1) < 1 (a mode slower than a cycle, such
as the w relaxation of Table 5 with (c0 + c2)/k2 = 48 s, changes each cycle by little while
far from its end); or d_j is at rounding level (1e-13). After ``max_cycles[i]`` cycles (a cap per
item) the loop stops unconverged (status 1). Rounding: the sums are of rectangle-rule quadrature over a period,
exact for a band-limited force.

Results per item: ``result[i] = (a, b, cycles, status)`` (status 0 converged, 1 cycle cap, 2
failed step or a non-finite force, then a = b = NaN) and ``last[i]`` the forces of the last cycle
simulated.
"""
from __future__ import annotations

import math

from fmu_src.kernels.jit import numba

ROUNDING = 1e-13


def _sine_steady_state(matrix, rows, amplitude, frequency, preload, steps, min_cycles, max_cycles, tolerance,
                       max_substeps, result, last):
    for i in numba.prange(rows.size):
        m = prepare(_VALUES(matrix[rows[i]]))
        X, P = amplitude[i], preload[i]
        omega = 2.0 * math.pi * frequency[i]
        h = 1.0 / (frequency[i] * steps)
        ms = prepare_step(m, h)
        state_x = P
        state = initial_state(m, P)
        previous_re, previous_im, previous_change = 0.0, 0.0, -1.0
        status, cycles, a, b = 1, 0, 0.0, 0.0
        while cycles < max_cycles[i]:
            a, b = 0.0, 0.0
            failed = False
            for k in range(steps):
                phase = 2.0 * math.pi * k / steps
                x_k = P + X * math.sin(phase)
                f_k = force(m, state, state_x, X * omega * math.cos(phase))
                last[i, k] = f_k
                a += f_k * math.cos(phase)
                b += f_k * math.sin(phase)
                x_next = P + X * math.sin(2.0 * math.pi * ((k + 1) % steps) / steps)
                state, used, code = step_prepared(m, ms, state, state_x, x_k, (x_next - x_k) / h, h, max_substeps)
                if code != _OK:
                    failed = True
                    break
                state_x = x_next
            cycles += 1
            a *= 2.0 / steps
            b *= 2.0 / steps
            size = math.sqrt(a * a + b * b)
            if failed or not math.isfinite(size):
                status, a, b = 2, math.nan, math.nan
                break
            change = math.sqrt((a - previous_re) ** 2 + (b - previous_im) ** 2) / size if size > 0.0 else 0.0
            if cycles >= min_cycles and change <= tolerance:
                if change <= ROUNDING:
                    status = 0
                    break
                if previous_change > 0.0 and change < previous_change:
                    ratio = change / previous_change
                    if change * ratio / (1.0 - ratio) <= tolerance:
                        status = 0
                        break
            previous_re, previous_im, previous_change = a, b, change
        result[i, 0] = a
        result[i, 1] = b
        result[i, 2] = cycles
        result[i, 3] = status
