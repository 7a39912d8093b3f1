"""How closely do the fractional model's relaxation modes realise b*(i*omega)^alpha?

    python benchmarks/bench_fractional_realisation.py

The fractional element of ``fmu_src/models/fractional_model.py`` is MODES Maxwell elements on a fixed
grid of rates, one for the rates below the grid and a dashpot for those above it (its module
docstring). Its dynamic stiffness is sum(k_j*s/(s + r_j)) + c*s at s = i*omega, from the model's
own ``prepare``; this prints, for orders alpha from 0.05 to 0.95 and three frequency bands, the
largest relative error of its magnitude and the largest error of its phase against the exact
b*(i*omega)^alpha (both independent of b), 2000 frequencies per band, log-spaced.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]

from fmu_src.models.fractional_model import ELEMENTS, MODEL  # noqa: E402
import harness  # noqa: E402

BANDS_HZ = ((0.01, 300.0), (0.001, 1000.0), (1.0, 100.0))
ORDERS = (0.05, 0.1, 0.2, 0.22, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95)


def realised(alpha: float, frequency_hz: np.ndarray) -> np.ndarray:
    """The element's dynamic stiffness for b = 1 [N/mm]."""
    _, _, _, _, stiffness, rates, dashpot = MODEL.prepare((0.0, 0.0, 0.0, 1.0, 1.0, alpha))
    s = 2j * math.pi * frequency_hz
    return sum(k * s / (s + r) for k, r in zip(stiffness, rates)) + dashpot * s


def main() -> None:
    print(f"{harness.provenance()}\n{ELEMENTS} Maxwell elements and a dashpot")
    header = "alpha " + "".join(f"| {low:g}-{high:g} Hz: |K*| err, phase err " for low, high in BANDS_HZ)
    print(header)
    for alpha in ORDERS:
        cells = []
        for low, high in BANDS_HZ:
            f = np.logspace(math.log10(low), math.log10(high), 2000)
            ratio = realised(alpha, f) / (2j * math.pi * f) ** alpha
            magnitude = np.max(np.abs(np.abs(ratio) - 1.0))
            phase = np.max(np.abs(np.degrees(np.angle(ratio))))
            cells.append(f"| {magnitude:10.1e} {phase:9.3f} deg         ")
        print(f"{alpha:5.2f} " + "".join(cells))


if __name__ == "__main__":
    main()
