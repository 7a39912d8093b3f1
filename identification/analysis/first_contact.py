"""A new device's first contact: what ``compare`` assumes about the training tests before it fits
any model, why, and how to turn it off.

A user who has never fitted this device names no option. Five things in the records say that
the models need one, and each is recognised here from the data alone:

- **the rig's offsets** (``rig``): a stroke that is not centred on 0 (a sine's centre beyond
  ``ONE_SIDED`` of its half range: a damper pushed from 0 to 25 mm), a force held at rest before
  the test starts, or a sine whose whole cycles average a force (each beyond ``offsets.OFFSET_FORCE`` of
  the record's force half range and ``offsets.NOISE_LEVELS`` of its noise). No model of zero mean says
  any of them; the rig's zeros, fitted as nuisance parameters (``models.md#options``), do;
- **a backbone** (``backbone<K>``): a quasi-static test (``--static``, or a training test of at
  most ``offsets.QUASI_STATIC_HZ``): its loading and unloading branches' mean is the static
  curve, held as every model's backbone. K is 9 where the monotone cubic through 9 knots reads
  the curve at 17 within ``KNOT_TOLERANCE`` of its force range, else 17 (a void's corner, a stop);
- **a rate-dependent element** (``maxwell``): a dynamic test stiffer than that static curve over
  its stroke (the least-squares slope of its force on the displacement, beside the velocity and a
  constant, beyond ``1 + RATE_STIFFENING`` times the static curve's on the same samples): the
  rubber's rate dependence, which a static backbone leaves to the rest of the model;
- **travel limits** (``limits``): without a quasi-static test, where the mean of the largest
  sine's loading and unloading branches stiffens towards its ends (the end segments'
  slope beyond ``END_STIFFENING`` times the middle's): a stop each side;
- **a temperature law** (``wlf``): training tests whose temperatures (a ``temperature_C`` or
  ``temperature_K`` column) span more than ``search.TEMPERATURE_SPREAD_K``: one model across them,
  each test run at its own temperature.

One more is tried rather than assumed: where a sine's loops dissipate more than
``DISSIPATIVE_LOOP`` of the rectangle their force and stroke span (the energy a cycle takes,
over 4 F x with F and x the force's and the stroke's half ranges: 1 for Coulomb's friction,
(pi/4) sin(delta) for a linear element of loss angle delta, under 0.3 for the rubber bushings
here), the device dissipates as friction (or a fluid) does, and ``band`` (self-energizing
friction through a play) is tried on the recommended model (``--try-options``), unless the
training shows its dissipation depends on the rate, as a fluid's or rubber's does and friction's
does not: a training data sheet whose loss angle spans more than ``RATE_DEPENDENT_LOSS_DEG`` over
frequency at one amplitude, or two sines of one amplitude (within ``SAME_AMPLITUDE``) whose
loops' shares differ by more than ``RATE_DEPENDENT_SHARE`` of the larger, itself beyond
``DISSIPATIVE_LOOP`` (a linear viscous element's share doubles with the frequency).

``compare`` races every model with what was assumed and then weighs the recommended model
without each assumed option in turn (``compare.CompareOptions.alternatives``): an option that
does not earn its parameters is dropped there. ``--options none`` turns every assumption off;
naming any option (``--options rig``) takes those instead.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.interpolate import PchipInterpolator

from identification.errors import MeasurementError
from identification.measured.offsets import RecordOffsets, offset_floor, record_offsets
from identification.measured.repeatability import cycle_starts
from identification.measured.rig_tests import RigTest
from identification.measured.static_curve import read_static_curve

ONE_SIDED = 0.2
"""A sine whose stroke is centred beyond this fraction of its half range is one-sided."""
KNOT_TOLERANCE = 0.01
"""A backbone of 9 knots reads the static curve well enough where it is within this fraction of
its force range at the 17 knots' positions."""
RATE_STIFFENING = 0.1
"""Dynamic tests stiffer than the static curve by more than this fraction are rate-dependent."""
END_STIFFENING = 3.0
"""A static curve whose end segments are this much stiffer than its middle has stops."""
KNOT_COUNTS = (9, 17)
DISSIPATIVE_LOOP = 0.35
"""A sine whose loops take more than this share of 4 F x a cycle dissipates as friction does."""
RATE_DEPENDENT_LOSS_DEG = 10.0
"""A data sheet whose loss angle spans more than this over frequency at one amplitude is rate-dependent."""
SAME_AMPLITUDE, RATE_DEPENDENT_SHARE = 0.2, 0.4
"""Two sines within this fraction of one amplitude whose loops' shares differ by more than this
fraction of the larger dissipate by the rate."""


@dataclass(frozen=True)
class Assumption:
    """One option assumed: its token (``derived.Options``' names: rig, backbone17, maxwell,
    limits) and why."""
    option: str
    reason: str


@dataclass(frozen=True)
class FirstContact:
    """What ``compare`` assumes (:func:`first_contact`): the options, each with its reason, and
    the quasi-static test the backbone is read off (None without one)."""
    assumptions: tuple[Assumption, ...]
    static_test: RigTest | None = None
    trials: tuple[Assumption, ...] = ()
    """Options tried on the recommended model (``--try-options``), each with its reason."""

    @property
    def tokens(self) -> tuple[str, ...]:
        return tuple(a.option for a in self.assumptions)

    @property
    def tried(self) -> tuple[str, ...]:
        return tuple(a.option for a in self.trials)

    def format(self) -> str:
        """The summary's lines: what was assumed, why, and how to turn it off."""
        if not self.assumptions:
            lines = ["assumed: no option (the records show no offset, no quasi-static test and no stop)"]
        else:
            lines = [f"assumed: {a.option}: {a.reason}" for a in self.assumptions]
            lines.append("  (each option assumed was weighed against the recommended model without it; turn them "
                         "off with --options none, or name the ones you want with --options)")
        lines += [f"tried: {a.option}: {a.reason}" for a in self.trials]
        if self.trials:
            lines.append("  (each option tried was weighed on the recommended model; --try-options none tries "
                         "nothing, --try-options LIST those instead)")
        return "\n".join(lines)


def _offsets_shown(offsets: RecordOffsets, test: RigTest) -> dict[str, tuple[float, float, str]]:
    """What one record shows that needs the rig's offsets, by kind ("stroke", "rest", "mean"):
    (the value, its fraction of the record's range, the sentence for this record alone)."""
    shown, name = {}, test.name
    if test.kind == "sine" and offsets.one_sided > ONE_SIDED:
        shown["stroke"] = (offsets.centre_mm, offsets.one_sided,
                           f"the stroke of {name} is one-sided (centred at {offsets.centre_mm:+.3g} mm, "
                           f"{offsets.half_range_mm:.3g} mm each way about it)")
    floor = offset_floor(test.measurement, offsets)
    if math.isfinite(offsets.rest_force_N) and abs(offsets.rest_force_N) > floor:
        shown["rest"] = (offsets.rest_force_N, abs(offsets.rest_force_N) / offsets.force_half_range_N,
                         f"{name} holds {offsets.rest_force_N:+.4g} N at rest before it moves "
                         f"({offsets.rest_s:.3g} s at {offsets.start_mm:+.3g} mm)")
    if test.kind == "sine" and math.isfinite(offsets.cycle_mean_force_N) and abs(offsets.cycle_mean_force_N) > floor:
        fraction = abs(offsets.cycle_mean_force_N) / offsets.force_half_range_N
        shown["mean"] = (offsets.cycle_mean_force_N, fraction,
                         f"the whole cycles of {name} average {offsets.cycle_mean_force_N:+.4g} N ({fraction:.1%} "
                         "of its force half range)")
    return shown


def _offset_reasons(tests: Sequence[RigTest], offsets: Sequence[RecordOffsets]) -> list[str]:
    """Why the records need the rig's offsets, a clause per kind of offset (empty: they do not):
    one record's own sentence, or the count and range of several."""
    by_kind: dict[str, list] = {}
    for test, record in zip(tests, offsets):
        for kind, entry in _offsets_shown(record, test).items():
            by_kind.setdefault(kind, []).append(entry)
    reasons = []
    for kind, entries in by_kind.items():
        if len(entries) == 1:
            reasons.append(entries[0][2])
            continue
        low, high = min(e[0] for e in entries), max(e[0] for e in entries)
        least, most = min(e[1] for e in entries), max(e[1] for e in entries)
        reasons.append({
            "stroke": f"the strokes of {len(entries)} sines are one-sided (centred at {low:+.3g} to {high:+.3g} mm)",
            "rest": f"{len(entries)} records hold {low:+.4g} to {high:+.4g} N at rest before they move",
            "mean": f"the whole cycles of {len(entries)} sines average {low:+.4g} to {high:+.4g} N ({least:.1%} to "
                    f"{most:.1%} of their force half range)"}[kind])
    return reasons


def _knot_count(measurement) -> tuple[int, str]:
    """The backbone's knots for a quasi-static test and why (module docstring)."""
    coarse, fine = (read_static_curve(measurement, count=count) for count in KNOT_COUNTS)
    between = PchipInterpolator(coarse.knots_mm, coarse.forces_N)(fine.knots_mm)
    miss = float(np.max(np.abs(between - fine.forces_N)))
    span = float(np.ptp(fine.forces_N))
    if miss <= KNOT_TOLERANCE * span:
        return KNOT_COUNTS[0], (f"{KNOT_COUNTS[0]} knots read the curve to {miss:.3g} N between them "
                                f"({miss / span:.2%} of its range)")
    return KNOT_COUNTS[1], (f"{KNOT_COUNTS[0]} knots miss the curve by {miss:.3g} N between them "
                            f"({miss / span:.2%} of its range, more than {KNOT_TOLERANCE:.0%})")


def _rate_stiffening(static_test: RigTest, dynamic: Sequence[RigTest]) -> str:
    """Why a rate-dependent element is tried beside the static curve ("": it is not): the dynamic
    test whose force is stiffest against the static curve's on the same samples (least-squares
    slopes on the displacement, the velocity and a constant)."""
    curve = read_static_curve(static_test.measurement, count=KNOT_COUNTS[1])
    backbone = PchipInterpolator(curve.knots_mm, curve.forces_N)
    worst, words = 0.0, ""
    for test in dynamic:
        m = test.measurement
        inside = (m.displacement_mm >= curve.knots_mm[0]) & (m.displacement_mm <= curve.knots_mm[-1])
        if np.count_nonzero(inside) < 10:
            continue
        x = m.displacement_mm[inside]
        design = np.column_stack([x - np.mean(x), m.velocity_mm_s[inside], np.ones(x.size)])
        (static, _, _), (stiffness, _, _) = (np.linalg.lstsq(design, force, rcond=None)[0]
                                             for force in (backbone(x), m.force_N[inside]))
        if static > 0 and stiffness / static - 1.0 > worst:
            worst = stiffness / static - 1.0
            words = (f"{test.name} is {worst:.0%} stiffer ({stiffness:.4g} N/mm) than the static curve "
                     f"({static:.4g} N/mm) over its stroke")
    return words if worst > RATE_STIFFENING else ""


def _stops(test: RigTest) -> str:
    """Why travel limits are tried for the largest sine ("": they are not)."""
    try:
        curve = read_static_curve(test.measurement, count=KNOT_COUNTS[0])
    except MeasurementError:
        return ""
    slopes = np.diff(curve.forces_N) / np.diff(curve.knots_mm)
    middle = float(np.median(np.abs(slopes[1:-1]))) if slopes.size > 2 else 0.0
    ends = max(abs(float(slopes[0])), abs(float(slopes[-1])))
    if middle > 0 and ends > END_STIFFENING * middle:
        return (f"the mean of {test.name}'s loading and unloading branches stiffens towards its ends "
                f"({ends:.4g} N/mm against {middle:.4g} N/mm in the middle)")
    return ""


def loop_dissipation(measurement) -> float:
    """The share of the rectangle 4 F x that a sine's whole cycles dissipate each [1] (module
    docstring); NaN without two cycle starts."""
    t, x, force = measurement.time_s, measurement.displacement_mm, measurement.force_N
    starts = cycle_starts(t, x) if np.ptp(x) > 0 else np.array([])
    if starts.size < 2:
        return math.nan
    inside = (t >= starts[0]) & (t <= starts[-1])
    xi, fi = x[inside], force[inside]
    if xi.size < 3 or np.ptp(fi) <= 0.0:
        return math.nan
    energy = float(np.sum(0.5 * (fi[1:] + fi[:-1]) * np.diff(xi))) / (starts.size - 1)
    return energy / (float(np.ptp(fi)) * float(np.ptp(xi)))       # 4 F x with F, x the half ranges


def _rate_dependent(sines, table) -> bool:
    """Whether the training shows a dissipation that depends on the rate (module docstring):
    ``sines`` the (loop dissipation, amplitude [mm]) of the training sines, ``table`` a training
    data sheet or None."""
    if table is not None:
        for amplitude in np.unique(table.amplitude_mm):
            angles = table.loss_angle_deg[table.amplitude_mm == amplitude]
            if angles.size > 1 and float(np.ptp(angles)) > RATE_DEPENDENT_LOSS_DEG:
                return True
    sines = [(a, share) for share, a in sines if a > 0]
    for i, (a, share) in enumerate(sines):
        for b, other in sines[i + 1:]:
            larger = max(share, other)      # only loops that dissipate count: a small share is mostly noise
            if abs(a - b) <= SAME_AMPLITUDE * max(a, b) and larger > DISSIPATIVE_LOOP and \
                    abs(share - other) > RATE_DEPENDENT_SHARE * larger:
                return True
    return False


def _dissipative(tests: Sequence[RigTest], table=None) -> str:
    """Why the band is tried ("": it is not): the sine whose loops dissipate most, where the
    training shows no rate-dependent dissipation."""
    shares = [(loop_dissipation(t.measurement), t.name, 0.5 * float(np.ptp(t.measurement.displacement_mm)))
              for t in tests if t.kind == "sine"]
    shares = [entry for entry in shares if math.isfinite(entry[0])]
    if not shares or _rate_dependent([(share, a) for share, _, a in shares], table):
        return ""
    share, name, _ = max(shares)
    if share <= DISSIPATIVE_LOOP:
        return ""
    return (f"the loops of {name} dissipate {share:.2f} of the rectangle their force and stroke span (Coulomb's "
            "friction 1, a linear element (pi/4) sin(loss angle), the rubber bushings here under 0.3), as friction "
            "does: a band brake's self-energizing friction through a play is tried")


def first_contact(tests: Sequence[RigTest], static_test: RigTest | None = None, table=None) -> FirstContact:
    """What the training ``tests`` (and a quasi-static ``static_test``, and a training data sheet
    ``table``, if given) ask the models to have (module docstring). A quasi-static training test is
    taken as the static test where none is given."""
    tests = list(tests)
    offsets = [record_offsets(t.measurement) for t in tests]
    if static_test is None:
        slow = [t for t, o in zip(tests, offsets) if t.kind != "step" and o.quasi_static]
        static_test = slow[0] if slow else None
    assumptions = []
    reasons = _offset_reasons(tests, offsets)
    if reasons:
        assumptions.append(Assumption("rig", "; ".join(reasons) + ": no model of zero mean says that, the rig's "
                                             "zeros fitted beside it do"))
    if static_test is not None:
        knots, why = _knot_count(static_test.measurement)
        assumptions.append(Assumption(f"backbone{knots}", f"{static_test.name} is quasi-static: its branches' mean "
                                                          f"is every model's static curve ({why})"))
        dynamic = [t for t in tests if t.kind != "step" and t.name != static_test.name]
        stiffening = _rate_stiffening(static_test, dynamic)
        if stiffening:
            assumptions.append(Assumption("maxwell", stiffening + ": a rate-dependent element beside the backbone"))
    else:
        sines = [t for t in tests if t.kind == "sine"]
        if sines:
            largest = max(sines, key=lambda t: float(np.ptp(t.measurement.displacement_mm)))
            stops = _stops(largest)
            if stops:
                assumptions.append(Assumption("limits", stops + ": a travel limit each side"))
    temperatures = _temperatures(tests, table)
    if temperatures:
        assumptions.append(Assumption("wlf", temperatures + ": a temperature law runs each at its own"))
    dissipative = _dissipative(tests, table)
    trials = (Assumption("band", dissipative),) if dissipative else ()
    return FirstContact(tuple(assumptions), static_test, trials)


def _temperatures(tests: Sequence[RigTest], table=None) -> str:
    """Words on the training tests' and data sheet's temperatures where they span more than
    TEMPERATURE_SPREAD_K (a temperature matrix), else ""."""
    from identification.fitting.search import TEMPERATURE_SPREAD_K
    kelvin = [t.measurement.mean_temperature_K for t in tests
              if getattr(t.measurement, "temperature_K", None) is not None]
    if table is not None and table.temperature_K is not None:
        kelvin += [float(t) for t in table.temperature_K]
    means = sorted({round(k - 273.15, 1) for k in kelvin})
    if len(means) < 2 or means[-1] - means[0] <= TEMPERATURE_SPREAD_K:
        return ""
    return f"the training tests are at {', '.join(f'{c:g}' for c in means)} degC"
