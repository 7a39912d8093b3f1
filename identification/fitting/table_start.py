"""Starts from the data: a fluid track's tuning, read off a dynamic-stiffness table.

A model whose box declares ``SearchBox.table_start`` (a ``definition.TrackStart``: the
names of its static spring, bulge stiffness, lower-chamber stiffness, track mass and damping and
decoupler travel) has a fluid column that resonates against its chambers, in parallel with the
rubber. Its data sheet shows the column, and the linear form of the model,

    K*(omega) = rubber + kb*(kc - mf*omega^2 + i*omega*cf)/(kb + kc - mf*omega^2 + i*omega*cf),

reads back from it (at the table's largest amplitude, where the decoupler rests on its cage):

- the resonance f_r, where the loss stiffness K'' = |K*|*sin(delta) peaks (a parabola through the
  peak and its neighbours in log f; the loss angle itself peaks below the resonance, where the
  storage stiffness dips);
- the bulge stiffness kb from the rise of the storage stiffness K' = |K*|*cos(delta) from the
  lowest frequency to the highest (the fluid path goes from kb*kc/(kb + kc) to kb, a rise of
  kb^2/(kb + kc), 0.91*kb with the bellows below; the rubber's Maxwell element adds to the rise
  about as much, so the rise itself is taken);
- kc as a tenth of kb (a soft bellows: the notch that would give it moves with the rubber's
  damping and the track's, too much to read);
- the mass mf = (kb + kc)/(2*pi*f_r)^2;
- the track damping from the loss stiffness K'' = |K*|*sin(delta) at the peak, which the
  column's kb^2/(omega_r*cf) dominates there;
- the static spring k0 = K'(lowest frequency) - kb*kc/(kb + kc) (at least 1 % of it);
- the decoupler's travel from the amplitudes: the peak appears once the pressure kb*X exceeds
  what the membrane (or the free plate) takes, (kb + kc + kd)*gap with kd its stiffness, taken as
  small against kb + kc (a soft membrane, a weakly centred plate), so gap is about kb/(kb + kc)
  times the smallest amplitude whose peak loss angle reaches half the largest amplitude's (the
  geometric mean of it and the largest amplitude below it, where the table has one);
- a free plate's cage (``TrackStart.engagement``, ``cage``, ``centring``), which the sheet's
  few amplitudes do not resolve: an engagement over 5 % of the travel, a cage ten times as stiff
  as the chambers (kb + kc) and a centring spring 2 % of them.

Time series alone (no table) give the same starts where their sines do: :func:`sines_as_table`
reads each sine's first harmonic, and sines at three or more frequencies at their largest
amplitude give the track, as a table's rows would.

Read at one preload: the table's most common one among the largest amplitude's rows (the one
nearest 0 of equally common ones). What the table cannot give (no peak of the loss stiffness
inside its frequencies, fewer than three frequencies, a single amplitude for the travel) is left
to the box, and :func:`table_start` says so.
The fit's screening then adds ``loop_start.LOOP_STARTS`` candidates anchored at these values
(``multistart.screen``), as it does for a slow loop's.

Units: mm, Hz, N/mm, N.s/mm, N.s^2/mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from identification.measured.kdyn_table import KdynTable
from identification.measured.rig_tests import RigTest
from identification.fitting.search_space import SearchSpace

MIN_FREQUENCIES = 3
"""Frequencies at the largest amplitude below which no resonance is read."""
ENGAGEMENT_SHARE = 0.05
CAGE_TIMES = 10.0
CENTRING_SHARE = 0.02
"""A free plate's starts (:func:`_free_plate`): what the sheet does not resolve, so typical
proportions of a hydromount's decoupler, left to the fit to move."""


@dataclass(frozen=True)
class TableStart:
    """What the table gives: the parameters, the table and what it could not give."""
    parameters: dict[str, float]
    source: str
    missing: str = ""

    def describe(self) -> str:
        values = ", ".join(f"{name} = {value:.4g}" for name, value in self.parameters.items())
        return (f"fluid track from the data sheet {self.source}: {values}"
                + (f" ({self.missing})" if self.missing else ""))


def sine_frequency_hz(time_s: np.ndarray, displacement_mm: np.ndarray) -> float:
    """A sine's frequency [Hz]: whole cycles between its first and last upward mean-crossings over
    the time between them, each crossing placed by linear interpolation between its samples; 0
    with fewer than two crossings."""
    x = displacement_mm - np.mean(displacement_mm)
    up = np.flatnonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))
    if up.size < 2:
        return 0.0
    crossing = time_s[up] + (time_s[up + 1] - time_s[up]) * (-x[up]) / (x[up + 1] - x[up])
    return (up.size - 1) / (crossing[-1] - crossing[0])


def sines_as_table(tests: Sequence[RigTest]) -> KdynTable | None:
    """The sine tests' first harmonics as a data sheet, for a fit given time series alone: each
    sine's |K*| and loss angle from a least-squares fit of a sine, a cosine and a constant at its
    frequency (``loop_start.dominant_frequency_hz``) to its displacement and its force over the
    later half of its whole cycles (the earlier half holds the settling from rest), the amplitude
    rounded to two significant digits so that sines at one nominal amplitude make one row set.
    None where fewer than one sine has two whole cycles."""
    rows, names = [], []
    for test in tests:
        m = test.measurement
        frequency = sine_frequency_hz(m.time_s, m.displacement_mm) if test.kind == "sine" else 0.0
        cycles = math.floor(frequency * (m.time_s[-1] - m.time_s[0])) if frequency > 0 else 0
        if cycles < 2:
            continue
        window = m.time_s >= m.time_s[-1] - math.ceil(cycles / 2) / frequency
        phase = 2.0 * math.pi * frequency * m.time_s[window]
        basis = np.column_stack([np.sin(phase), np.cos(phase), np.ones(phase.size)])
        (xs, xc, _), (fs, fc, _) = np.linalg.lstsq(basis, np.column_stack(
            [m.displacement_mm[window], m.force_N[window]]), rcond=None)[0].T
        stiffness = complex(fc, -fs) / complex(xc, -xs)    # phasors: a*sin + b*cos = Re((b - i*a)*exp(i*phase))
        angle = math.degrees(math.atan2(stiffness.imag, stiffness.real))
        if not (0.0 < angle < 90.0 and stiffness.real > 0.0):
            continue                                        # no spring-and-damper reading (noise, a bad test)
        amplitude = float(f"{abs(complex(xc, -xs)):.2g}")
        rows.append((amplitude, frequency, abs(stiffness), angle))
        names.append(m.source and Path(m.source).name or test.name)
    if not rows:
        return None
    amplitude, frequency, kdyn, angle = (np.array(column) for column in zip(*rows))
    return KdynTable(amplitude, frequency, np.zeros(amplitude.size), kdyn, angle, np.ones(amplitude.size),
                     f"of the sines' first harmonics ({', '.join(names)})")


def _named(table: KdynTable) -> str:
    """How a note names the table: by its source (a file, or the sines it was read from)."""
    return f"the table {table.source}"


def _peak_frequency(frequency: np.ndarray, values: np.ndarray) -> float | None:
    """Where ``values`` peak over ``frequency`` [Hz], refined by a parabola in log f; None at either end."""
    k = int(np.argmax(values))
    if k == 0 or k == frequency.size - 1:
        return None
    u = np.log(frequency[k - 1:k + 2])
    a, b, _ = np.polyfit(u, values[k - 1:k + 2], 2)
    peak = -b / (2.0 * a) if a < 0 else u[1]
    return float(math.exp(np.clip(peak, u[0], u[2])))


def table_start(table: KdynTable | None, space: SearchSpace) -> TableStart | str | None:
    """The track's starting values from ``table`` (module docstring): a TableStart; a sentence
    saying why the table gives none (the fit then starts from its box); None where the model
    declares no track start or no table is given."""
    track = space.bushing.search.table_start if space.bushing.search is not None else None
    if track is None or table is None:
        return None
    kept = table.weight > 0
    largest = float(table.amplitude_mm[kept].max())
    preloads, counts = np.unique(table.preload_mm[kept & (table.amplitude_mm == largest)], return_counts=True)
    preload = min(preloads[counts == counts.max()], key=abs)
    kept &= table.preload_mm == preload
    amplitude, frequency = table.amplitude_mm[kept], table.frequency_hz[kept]
    kdyn, angle = table.kdyn_N_per_mm[kept], table.loss_angle_deg[kept]
    rows = np.flatnonzero(amplitude == largest)
    rows = rows[np.argsort(frequency[rows])]
    at = f"at its largest amplitude ({largest:g} mm" + (f", preload {preload:g} mm)" if preload else ")")
    if rows.size < MIN_FREQUENCIES:
        count = "a single frequency" if rows.size == 1 else f"{rows.size} frequencies"
        return (f"note: {_named(table)} has {count} {at}, fewer than {MIN_FREQUENCIES}: no resonance to read, the "
                f"fit starts from the default box (sines at {MIN_FREQUENCIES} or more frequencies around the track's "
                "resonance give it a start)")
    f, k, d = frequency[rows], kdyn[rows], np.radians(angle[rows])
    storage, loss = k * np.cos(d), k * np.sin(d)
    resonance = _peak_frequency(f, loss)
    if resonance is None:
        return (f"note: the loss stiffness of {_named(table)} {at} has no peak inside its frequencies "
                f"({f[0]:g}-{f[-1]:g} Hz): no resonance to read, the fit starts from the default box")
    bulge = max(storage[-1] - storage[0], 0.01 * storage[0])
    chamber = 0.1 * bulge
    omega = 2.0 * math.pi * resonance
    peak_loss = float(np.interp(math.log(resonance), np.log(f), loss))
    values = {track.mass: (bulge + chamber) / omega ** 2,
              track.stiffness: bulge, track.compliance: chamber,
              track.damping: bulge ** 2 / (omega * max(peak_loss, 1e-6 * bulge)),
              track.static: max(storage[0] - bulge * chamber / (bulge + chamber), 0.01 * storage[0])}
    missing = ""
    if track.travel:
        travel = _travel(amplitude, angle, largest, bulge / (bulge + chamber))
        if travel is None:
            missing = (f"the table has a single amplitude ({largest:g} mm): the decoupler's travel is left to "
                       "the box")
        else:
            values[track.travel] = travel
            values.update(_free_plate(track, travel, bulge + chamber))
    return TableStart(values, table.source, missing)


def _free_plate(track, travel: float, chambers: float) -> dict[str, float]:
    """Starts for a free decoupler plate's cage (those ``track`` names): the cage engaging over
    ENGAGEMENT_SHARE of the free travel, CAGE_TIMES the chambers' stiffness kb + kc (a cage
    much stiffer than the walls the fluid bulges), a centring spring CENTRING_SHARE of it."""
    values = {}
    if track.engagement:
        values[track.engagement] = ENGAGEMENT_SHARE * travel
    if track.cage:
        values[track.cage] = CAGE_TIMES * chambers
    if track.centring:
        values[track.centring] = CENTRING_SHARE * chambers
    return values


def _travel(amplitude: np.ndarray, angle: np.ndarray, largest: float, share: float) -> float | None:
    """The decoupler's travel [mm] from the smallest amplitude whose peak loss angle reaches half
    the largest amplitude's (module docstring); None with a single amplitude."""
    amplitudes = np.unique(amplitude)
    if amplitudes.size < 2:
        return None
    peaks = np.array([angle[amplitude == a].max() for a in amplitudes])
    top = peaks[amplitudes == largest][0]
    showing = amplitudes[peaks >= 0.5 * top]
    on = float(showing.min())
    quiet = amplitudes[amplitudes < on]
    return share * (math.sqrt(on * float(quiet.max())) if quiet.size else on)
