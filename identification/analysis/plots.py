"""Figures: measured and predicted forces (paper Figs. 9-19), the multi-start waterfall, the
ensemble's prediction band. Every function writes a PNG and returns its path."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from fmu_src.model.registry import required_model
from identification.interrupt import writing
from identification.measured.measurements import Measurement
from identification.fitting.objectives import nrmse

def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(figure, path) -> Path:
    """Write ``figure`` as a PNG at ``path``, whole or not at all (``interrupt.writing``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with writing(path) as temporary:
            figure.savefig(temporary, dpi=90)   # the format from the suffix, which the temporary keeps
    finally:
        _pyplot().close(figure)
    return path


def plot_comparison(measurement: Measurement, predictions: dict, path: Path, band: tuple | None = None,
                    measured: bool = True) -> Path:
    """Measured and predicted force over time and against displacement (paper Figs. 15-17);
    ``predictions``: {model (the ``BushingModel``, drawn in its style): force [N]};
    ``band``: (lower, upper) force [N] of an ensemble, shaded around the first prediction;
    ``measured``: whether to draw the measurement's force (False for a displacement-only input)."""
    plt = _pyplot()
    m = measurement
    figure, (in_time, loop) = plt.subplots(1, 2, figsize=(12, 4.4))
    if measured:
        in_time.plot(m.time_s, m.force_N / 1e3, color="0.55", lw=1.4, label="measured")
        loop.plot(m.displacement_mm, m.force_N / 1e3, color="0.55", lw=1.2)
    if band is not None:
        lower, upper = band
        in_time.fill_between(m.time_s, lower / 1e3, upper / 1e3, color="C0", alpha=0.25, lw=0,
                             label="ensemble band")
    for model, predicted in predictions.items():
        bushing = required_model(model)
        color, style = bushing.plot_style
        label = bushing.title + (f" (NRMSE {nrmse(predicted, m.force_N):.1%})" if measured else "")
        in_time.plot(m.time_s, predicted / 1e3, color=color, ls=style, lw=1.1, label=label)
        loop.plot(m.displacement_mm, predicted / 1e3, color=color, ls=style, lw=1.0)
    in_time.set(xlabel="time [s]", ylabel="force [kN]", title=Path(m.source).name)
    loop.set(xlabel="displacement [mm]", ylabel="force [kN]", title="force-displacement")
    in_time.legend(loc="best", fontsize=7)
    for axes in (in_time, loop):
        axes.grid(alpha=0.3)
    figure.tight_layout()
    return _save(figure, path)


def plot_multiaxis(measurement, predictions: dict, path: Path, measured: bool = True) -> Path:
    """A multi-axis test (``multiaxis.MultiAxisMeasurement``): each axis's measured and predicted force
    over time, and the force vector's path (Fy against Fx) beside the displacement's (dy against dx).
    ``predictions``: {label: force vectors (samples, d) [N]}, drawn in the order given."""
    from identification.measured.multiaxis import vector_nrmse
    plt = _pyplot()
    m = measurement
    figure, (in_time, force_path, motion) = plt.subplots(1, 3, figsize=(15, 4.4))
    styles = ("-", "--", ":")
    if measured:
        for c, axis in enumerate(m.axes):
            in_time.plot(m.time_s, m.force_N[:, c] / 1e3, color="0.55", lw=1.4, ls=styles[c],
                         label=f"measured F{axis}")
        force_path.plot(m.force_N[:, 0] / 1e3, m.force_N[:, 1] / 1e3, color="0.55", lw=1.2, label="measured")
    for i, (label, predicted) in enumerate(predictions.items()):
        text = label + (f" (NRMSE {vector_nrmse(predicted, m.force_N):.1%})" if measured else "")
        for c, axis in enumerate(m.axes):
            in_time.plot(m.time_s, predicted[:, c] / 1e3, color=f"C{i}", lw=1.0, ls=styles[c],
                         label=f"{text}: F{axis}" if measured or c == 0 else f"F{axis}")
        force_path.plot(predicted[:, 0] / 1e3, predicted[:, 1] / 1e3, color=f"C{i}", lw=1.0, label=text)
    motion.plot(m.displacement_mm[:, 0], m.displacement_mm[:, 1], color="0.3", lw=1.0)
    in_time.set(xlabel="time [s]", ylabel="force [kN]", title=m.name)
    force_path.set(xlabel="Fx [kN]", ylabel="Fy [kN]", title="force vector")
    motion.set(xlabel="dx [mm]", ylabel="dy [mm]", title="displacement path")
    in_time.legend(loc="best", fontsize=7)
    force_path.legend(loc="best", fontsize=7)
    for axes in (in_time, force_path, motion):
        axes.grid(alpha=0.3)
    for axes in (force_path, motion):
        axes.set_aspect("equal", adjustable="datalim")
    figure.tight_layout()
    return _save(figure, path)


def plot_waterfall(misfits: Sequence[float], stages: Sequence[int], best: float, threshold: float,
                   path: Path) -> Path:
    """pyPESTO's waterfall: every start's final misfit, sorted, coloured by the last stage it
    ran in; the band up to the agreement threshold shaded. Starts on the plateau at the left
    found the same optimum."""
    plt = _pyplot()
    misfits = np.asarray(misfits, dtype=float)
    stages = np.asarray(stages)
    order = np.argsort(misfits, kind="stable")
    figure, axes = plt.subplots(figsize=(7, 4.2))
    finite = np.isfinite(misfits[order])
    for stage in sorted(set(stages.tolist())):
        chosen = (stages[order] == stage) & finite
        axes.semilogy(np.flatnonzero(chosen) + 1, misfits[order][chosen], "o", ms=4,
                      label=f"ended in stage {stage + 1}")
    axes.axhspan(best, best + threshold, color="C2", alpha=0.25, label="within the ensemble threshold")
    axes.axhline(1.0, color="0.3", ls="--", lw=1, label="noise floor (misfit 1)")
    axes.set(xlabel="start, sorted by final misfit", ylabel="misfit chi^2/n",
             title="multi-start waterfall")
    axes.grid(alpha=0.3, which="both")
    axes.legend(fontsize=8)
    figure.tight_layout()
    return _save(figure, path)


def plot_dynamic_stiffness(table, folder: Path, measured=None) -> list[Path]:
    """A bushing data sheet of a ``dynamic_stiffness.DynamicStiffness``: |K*| and the loss angle
    against frequency (log axis, one curve per amplitude), against amplitude (one curve per
    frequency), each with an ensemble's min-max shaded; and the steady-state loops of the
    smallest and largest amplitude at the lowest and highest frequency. ``measured``: a
    ``kdyn_table.KdynTable`` drawn as crosses on its curves (a fit's training table). Returns
    the three PNGs."""
    plt = _pyplot()
    folder = Path(folder)
    amplitudes = np.unique(table.amplitude_mm)
    frequencies = np.unique(table.frequency_hz)
    written = []
    for along, curves, unit, label, name, log in (
            (table.frequency_hz, table.amplitude_mm, "mm", "frequency [Hz]", "kdyn_vs_frequency.png", True),
            (table.amplitude_mm, table.frequency_hz, "Hz", "amplitude [mm]", "kdyn_vs_amplitude.png", False)):
        figure, (stiffness, angle) = plt.subplots(1, 2, figsize=(12, 4.4))
        for index, value in enumerate(np.unique(curves)):
            chosen = np.flatnonzero(curves == value)
            chosen = chosen[np.argsort(along[chosen])]
            for axes, column in ((stiffness, "kdyn_N_per_mm"), (angle, "loss_angle_deg")):
                axes.plot(along[chosen], table.column(column)[chosen], "o-", color=f"C{index % 10}", ms=3.5, lw=1.2,
                          label=f"{value:g} {unit}")
                if table.minimum:
                    axes.fill_between(along[chosen], table.minimum[column][chosen], table.maximum[column][chosen],
                                      color=f"C{index % 10}", alpha=0.2, lw=0)
                if measured is not None:
                    on_curve = np.isclose(measured.amplitude_mm if unit == "mm" else measured.frequency_hz, value)
                    points = measured.frequency_hz if unit == "mm" else measured.amplitude_mm
                    axes.plot(points[on_curve], getattr(measured, column)[on_curve], "x", color=f"C{index % 10}",
                              ms=7, mew=1.5, label="table" if (index == 0 and column == "kdyn_N_per_mm") else None)
        stiffness.set(xlabel=label, ylabel="dynamic stiffness |K*| [N/mm]")
        angle.set(xlabel=label, ylabel="loss angle [deg]")
        for axes in (stiffness, angle):
            if log:
                axes.set_xscale("log")
            axes.grid(alpha=0.3, which="both")
        stiffness.legend(fontsize=8, title="amplitude" if unit == "mm" else "frequency")
        shaded = ", ensemble min-max shaded" if table.minimum else ""
        figure.suptitle(f"{table.title or table.model}: dynamic stiffness and loss angle{shaded}", fontsize=10)
        figure.tight_layout()
        written.append(_save(figure, folder / name))
    figure, axes = plt.subplots(figsize=(7, 5))
    corners = {(a, f) for a in (amplitudes[0], amplitudes[-1]) for f in (frequencies[0], frequencies[-1])}
    for index, case in enumerate(i for i in range(len(table))
                                 if (table.amplitude_mm[i], table.frequency_hz[i]) in corners):
        # normalised, so that a 0.1 mm loop shows beside a 3 mm one
        x = (table.loop_displacement_mm(case) - table.preload_mm[case]) / table.amplitude_mm[case]
        force = table.loop_force_N[case] / table.peak_force_N[case]
        axes.plot(np.append(x, x[:1]), np.append(force, force[:1]), color=f"C{index}", lw=1.2,
                  label=f"{table.amplitude_mm[case]:g} mm, {table.frequency_hz[case]:g} Hz: peak "
                        f"{table.peak_force_N[case]:.0f} N, |K*| {table.kdyn_N_per_mm[case]:.0f} N/mm, "
                        f"{table.loss_angle_deg[case]:.1f} deg")
    axes.set(xlabel="displacement / amplitude", ylabel="force / peak force", title="steady-state loops (normalised)")
    axes.grid(alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    written.append(_save(figure, folder / "steady_state_loops.png"))
    return written


def plot_temperature_sheet(tables, folder: Path) -> Path:
    """A data sheet over temperature (``dynamic_stiffness.characterise_at_temperatures``' (T [K],
    table) pairs): |K*| and the loss angle against the temperature [degC], one curve per
    amplitude and frequency, each with an ensemble's min-max shaded. Returns the PNG."""
    plt = _pyplot()
    celsius = np.array([temperature - 273.15 for temperature, _ in tables])
    first = tables[0][1]
    figure, (stiffness, angle) = plt.subplots(1, 2, figsize=(12, 4.4))
    for case in range(len(first)):
        label = f"{first.amplitude_mm[case]:g} mm, {first.frequency_hz[case]:g} Hz"
        for axes, column in ((stiffness, "kdyn_N_per_mm"), (angle, "loss_angle_deg")):
            values = [table.column(column)[case] for _, table in tables]
            axes.plot(celsius, values, "o-", color=f"C{case % 10}", ms=3.5, lw=1.2, label=label)
            if first.minimum:
                axes.fill_between(celsius, [table.minimum[column][case] for _, table in tables],
                                  [table.maximum[column][case] for _, table in tables], color=f"C{case % 10}",
                                  alpha=0.2, lw=0)
    stiffness.set(xlabel="temperature [degC]", ylabel="dynamic stiffness |K*| [N/mm]", yscale="log")
    angle.set(xlabel="temperature [degC]", ylabel="loss angle [deg]")
    for axes in (stiffness, angle):
        axes.grid(alpha=0.3, which="both")
    stiffness.legend(fontsize=7, ncol=2)
    shaded = ", ensemble min-max shaded" if first.minimum else ""
    figure.suptitle(f"{first.title or first.model}: dynamic stiffness and loss angle over temperature{shaded}",
                    fontsize=10)
    figure.tight_layout()
    return _save(figure, Path(folder) / "kdyn_vs_temperature.png")


def plot_table_comparison(table, fits: dict, path: Path) -> Path:
    """A held-out dynamic-stiffness table (``kdyn_table.KdynTable``, crosses) and each model's
    prediction of its rows (lines in the model's style; ``fits``: {model (the ``BushingModel``):
    ``result.TableFit``}):
    |K*| (top) and the loss angle (bottom) against frequency, one column per amplitude."""
    plt = _pyplot()
    kept = table.weight > 0
    amplitudes = np.unique(table.amplitude_mm[kept])
    figure, axes = plt.subplots(2, amplitudes.size, figsize=(3.2 * amplitudes.size + 1.5, 6.2), squeeze=False,
                                sharex=True)
    amplitude, frequency = table.amplitude_mm[kept], table.frequency_hz[kept]
    measured = {"kdyn": table.kdyn_N_per_mm[kept], "angle": table.loss_angle_deg[kept]}
    for column, X in enumerate(amplitudes):
        rows = np.flatnonzero(amplitude == X)
        rows = rows[np.argsort(frequency[rows])]
        top, bottom = axes[0, column], axes[1, column]
        top.plot(frequency[rows], measured["kdyn"][rows], "kx", ms=7, mew=1.5, label="table")
        bottom.plot(frequency[rows], measured["angle"][rows], "kx", ms=7, mew=1.5)
        for model, fitted in fits.items():
            color, style = required_model(model).plot_style
            kdyn = measured["kdyn"][rows] * (1.0 + fitted.kdyn_errors[rows])
            angle = measured["angle"][rows] + fitted.angle_errors_deg[rows]
            top.plot(frequency[rows], kdyn, color=color, ls=style, lw=1.3, label=model.name)
            bottom.plot(frequency[rows], angle, color=color, ls=style, lw=1.3)
        top.set_title(f"{X:g} mm")
        bottom.set_xlabel("frequency [Hz]")
        for a in (top, bottom):
            a.set_xscale("log")
            a.grid(alpha=0.3, which="both")
    axes[0, 0].set_ylabel("dynamic stiffness |K*| [N/mm]")
    axes[1, 0].set_ylabel("loss angle [deg]")
    axes[0, 0].legend(fontsize=7)
    figure.suptitle(f"{table.name}: the table (held out) and each model's prediction", fontsize=10)
    figure.tight_layout()
    return _save(figure, path)
