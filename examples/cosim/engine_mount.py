"""Engine on three six-axis bushings: a multibody co-simulation that checks the bushing's frames.

    python examples/cosim/engine_mount.py [--stop 1.0] [--step 0.001] [--decay 3.0] [--decay-step 0.0005]
                                          [--out out/engine_mount] [--native] [--coupling radial]

The system: a 160 kg engine (``EngineBody`` in ``engine_body.py``, its own pythonfmu FMU: mass,
full inertia tensor, 6 DOF) on three ``SixAxisBushing`` FMUs at different positions and
orientations (two main mounts inclined +-30 deg, a rear torque rod turned 90 deg and tilted 20
deg), over a base that moves vertically (1 mm at 20 Hz, the road) and pitches (4 mrad at
11 Hz): the bushings deflect by up to 0.4-1.6 mm, the paper's range. The body computes each bushing's pose and twist in that bushing's J axes and applies
its force and moment with their lever arms (``engine_body.py`` states the frames). The
system is written once as an SSP 1.0 directory (the FMUs, one ``.ssv`` per bushing) and run
(a) in libcosim through libcosimpy and (b) in fmpy's master loop (``ssp_system.py``), both at
the same fixed step with the same Jacobi exchange.

Three checks, printed:

1. libcosim and fmpy agree: every output, relative to its peak.
2. Momentum: over the run, the change of the body's momentum P and of its angular momentum H
   about the centre of mass equals the impulses of the bushing actions as the six-axis
   convention assigns them (body I receives -F at I and -M, in J's axes), summed here from
   the forces and moments the master passed and the body's pose at each step start,
   independently of the body's own bookkeeping. Relative to the peak |P| and |H|.
3. Frames, independently: with every axis Kelvin-Voigt (``KELVIN_VOIGT_AXES``), the six natural
   frequencies of the engine read from a free decay through the FMUs (the peaks of the
   spectrum of its six motions) against those of the linearised system, from the generalised
   eigenproblem K v = w^2 M v with K = sum over mounts of T^T diag(k) T, written here from the
   geometry alone (T maps the body's small translation u and rotation phi to the bushing's
   deflections in J's axes: d = Q^T (u + phi x a), rotation Q^T phi).

Writes ``engine_mount.png`` (the body's six motions, the left mount's hysteresis loops) and the
series. No gravity: the motion is about the static equilibrium, every bushing starts unloaded.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.linalg import eigh
from scipy.spatial.transform import Rotation

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(HERE))

import engine_body  # noqa: E402
import ssp_system  # noqa: E402
from engine_body import BODY_OUTPUTS, BUSHING_INPUTS, BUSHING_OUTPUTS, MOUNTS, port  # noqa: E402
from fmu_src.parameter_files import read_six_axis, save_six_axis, write_ssv_values  # noqa: E402
from ssp_system import Component, Connection  # noqa: E402

BODY = "engine"
BUSHING_SET = REPO / "data" / "params_six_axis_illustrative.json"
KELVIN_VOIGT_AXES = {
    # axis: stiffness k (N/mm translational, N.mm/rad rotational). Chosen so that the six
    # frequencies lie >= 1.7 Hz apart (6.9 ... 22 Hz): a 3 s free decay separates them, and
    # w*h stays small enough for the explicit coupling (its frequency error grows as (w*h)^2).
    "x": 200.0, "y": 1200.0, "z": 50.0, "rx": 2.0e5, "ry": 2.0e5, "rz": 3.0e5,
}
KELVIN_VOIGT_TIME_CONSTANT_S = 2e-5
"""c = k*tau on every axis: a light damping (0.06 % at 10 Hz, 0.35 % at 56 Hz) that keeps the
free decay's spectral peaks sharp."""
KICK = {"v0_x": 0.021, "v0_y": 0.022, "v0_z": 0.007, "w0_x": 0.179, "w0_y": -0.229, "w0_z": -0.108}
"""Initial velocity [m/s] and angular velocity [rad/s] of the free decay, chosen (among random
ones) so that every mode moves at least half as much as the most excited one: a kick nearly
orthogonal to a mode would hide its peak."""


def bushing_name(mount: str) -> str:
    return f"bushing_{mount}"


def body_parameters() -> dict[str, float]:
    """The body FMU's parameter defaults (``engine_body.PARAMETERS``)."""
    return {name: value for name, _, _, value in engine_body.PARAMETERS}


def kelvin_voigt_axes() -> dict:
    """Six Kelvin-Voigt axes, as ``save_six_axis`` takes them."""
    return {axis: ("KelvinVoigtBushing", {"k": k, "c": k * KELVIN_VOIGT_TIME_CONSTANT_S, "preload": 0.0})
            for axis, k in KELVIN_VOIGT_AXES.items()}


def build_fmus(out_dir: Path, bushing_params: Path = BUSHING_SET, native: bool = False) -> tuple[Path, Path]:
    """The six-axis bushing FMU (defaults from ``parameter_specs``; ``native``: the compiled one)
    and the body FMU."""
    import build_fmu
    if native:
        bushing = build_fmu.build_native_fmu(params_file=bushing_params, out_dir=out_dir, model="six_axis").path
    else:
        bushing = build_fmu.build_fmu(params_file=bushing_params, out_dir=out_dir, model="six_axis")
    return bushing, ssp_system.build_pythonfmu(HERE / "engine_body.py", out_dir)


def components(system_dir: Path, bushing_fmu: Path, body_fmu: Path) -> list[Component]:
    body_outputs = tuple(port(m, n) for m in MOUNTS for n in BUSHING_INPUTS) + tuple(n for n, _, _ in BODY_OUTPUTS)
    body = Component(BODY, body_fmu, tuple(port(m, n) for m in MOUNTS for n in BUSHING_OUTPUTS), body_outputs,
                     system_dir / "resources" / f"{BODY}.ssv")
    return [body, *(Component(bushing_name(m), bushing_fmu, BUSHING_INPUTS, BUSHING_OUTPUTS,
                              system_dir / "resources" / f"{bushing_name(m)}.ssv") for m in MOUNTS)]


def connections() -> list[Connection]:
    links = []
    for m in MOUNTS:
        links += [Connection(BODY, port(m, n), bushing_name(m), n) for n in BUSHING_INPUTS]
        links += [Connection(bushing_name(m), n, BODY, port(m, n)) for n in BUSHING_OUTPUTS]
    return links


def write_system(system_dir: Path, bushing_fmu: Path, body_fmu: Path, stop_time: float,
                 body: dict[str, float], bushing_params: Path = BUSHING_SET) -> list[Component]:
    """The SSP directory: the FMUs, the body's parameters and each bushing's set as ``.ssv``."""
    resources = system_dir / "resources"
    resources.mkdir(parents=True, exist_ok=True)
    units = {name: unit for name, unit, _, _ in engine_body.PARAMETERS}
    write_ssv_values(resources / f"{BODY}.ssv", "EngineBody", body, units)
    six = read_six_axis(bushing_params)
    axes = {axis: (one.model.identifier, one.parameters) for axis, one in six.axes.items()}
    for m in MOUNTS:
        save_six_axis(resources / f"{bushing_name(m)}.ssv", axes)
    parts = components(system_dir, bushing_fmu, body_fmu)
    ssp_system.write_ssp(system_dir, "EngineMount", parts, connections(), stop_time)
    return parts


# -- check 2: momentum -------------------------------------------------------------------
def momentum_balance(run: dict, step_size: float, body: dict[str, float]) -> dict[str, float]:
    """Largest |P(t_end) - P(0) - impulse| over peak |P|, and the same for H about the centre
    of mass, the impulses summed from the inputs the master set and the poses at step starts."""
    n = run["time"].size
    start_rotvec = np.vstack([np.zeros(3), np.column_stack([run[f"{BODY}.rot_{a}"] for a in "xyz"])[:-1]])
    orientation = Rotation.from_rotvec(start_rotvec).as_matrix()                     # (n, 3, 3)
    pitch = np.array([engine_body.base_motion(k * step_size, body["road_amplitude"], body["road_frequency"],
                                              body["pitch_amplitude"], body["pitch_frequency"],
                                              body["fade_time"])[2] for k in range(n)])
    c, s, zero, one = np.cos(pitch), np.sin(pitch), np.zeros(n), np.ones(n)
    base = np.stack([np.stack([c, zero, s], -1), np.stack([zero, one, zero], -1), np.stack([-s, zero, c], -1)], 1)
    impulse, angular_impulse = np.zeros(3), np.zeros(3)
    for m, (position, axes) in engine_body.mount_geometry().items():
        R_J = base @ axes
        F = np.column_stack([run[f"{BODY}.{port(m, q)}"] for q in BUSHING_OUTPUTS[:3]])
        M = np.column_stack([run[f"{BODY}.{port(m, q)}"] for q in BUSHING_OUTPUTS[3:]])
        force = -np.einsum("kij,kj->ki", R_J, F)          # body I receives -F at I ...
        lever = orientation @ position
        torque = np.cross(lever, force) - np.einsum("kij,kj->ki", R_J, M)   # ... and -M
        impulse += step_size * force.sum(axis=0)
        angular_impulse += step_size * torque.sum(axis=0)
    inertia = engine_body.inertia_tensor(*(body[k] for k in ("Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")))
    P0 = body["mass"] * np.array([body["v0_x"], body["v0_y"], body["v0_z"]])
    H0 = inertia @ np.array([body["w0_x"], body["w0_y"], body["w0_z"]])
    P = np.column_stack([run[f"{BODY}.P{a}"] for a in "xyz"])
    H = np.column_stack([run[f"{BODY}.H{a}"] for a in "xyz"])
    return {"momentum": float(np.linalg.norm(P[-1] - P0 - impulse) / np.max(np.linalg.norm(P, axis=1))),
            "angular momentum": float(np.linalg.norm(H[-1] - H0 - angular_impulse) /
                                      np.max(np.linalg.norm(H, axis=1)))}


# -- check 3: natural frequencies --------------------------------------------------------
def linearised_frequencies(body: dict[str, float], stiffness=KELVIN_VOIGT_AXES) -> np.ndarray:
    """Natural frequencies [Hz] of the engine on its three Kelvin-Voigt mounts, from
    K v = w^2 M v, built from the geometry and the axis stiffnesses alone."""
    def cross_matrix(a):
        return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])

    # SI: N/mm -> N/m (x 1e3); N.mm/rad -> N.m/rad (x 1e-3)
    k_si = np.diag([stiffness[a] * 1e3 for a in ("x", "y", "z")] + [stiffness[a] * 1e-3 for a in ("rx", "ry", "rz")])
    K = np.zeros((6, 6))
    for position, axes in MOUNTS.values():
        Q = Rotation.from_rotvec(axes).as_matrix()
        T = np.zeros((6, 6))
        T[:3, :3] = Q.T
        T[:3, 3:] = -Q.T @ cross_matrix(np.array(position))    # phi x a = -a x phi
        T[3:, 3:] = Q.T
        K += T.T @ k_si @ T
    M = np.zeros((6, 6))
    M[:3, :3] = body["mass"] * np.eye(3)
    M[3:, 3:] = engine_body.inertia_tensor(*(body[k] for k in ("Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")))
    return np.sqrt(eigh(K, M, eigvals_only=True)) / (2 * np.pi)


def spectral_peaks(run: dict, step_size: float, count: int = 6) -> np.ndarray:
    """The ``count`` highest peaks [Hz] of the summed, normalised power spectra of the body's
    six motions (Hann window, zero-padded x16, parabolic interpolation of the log power)."""
    from scipy.signal import find_peaks
    from scipy.signal.windows import hann
    channels = [run[f"{BODY}.{a}"] for a in ("x", "y", "z", "rot_x", "rot_y", "rot_z")]
    n = channels[0].size
    padded = 16 * n
    window = hann(n)
    power = np.zeros(padded // 2 + 1)
    for signal in channels:
        spectrum = np.abs(np.fft.rfft(window * (signal - signal.mean()), padded)) ** 2
        power += spectrum / spectrum.max()
    peaks, _ = find_peaks(power)
    best = np.sort(peaks[np.argsort(power[peaks])[-count:]])
    log_power = np.log(power)
    left, centre, right = log_power[best - 1], log_power[best], log_power[best + 1]
    offset = 0.5 * (left - right) / (left - 2 * centre + right)
    return (best + offset) / (padded * step_size)


def free_decay(out_dir: Path, step_size: float, duration: float) -> tuple[np.ndarray, np.ndarray, dict]:
    """Kick the engine on Kelvin-Voigt mounts (base still) and return (measured, linearised)
    natural frequencies [Hz] and the run."""
    out_dir.mkdir(parents=True, exist_ok=True)
    kv_params = save_six_axis(out_dir / "params_six_axis_kelvin_voigt.json", kelvin_voigt_axes(),
                              {"note": "Kelvin-Voigt on every axis, for the engine-mount frequency check"})
    bushing_fmu, body_fmu = build_fmus(out_dir / "fmus_kelvin_voigt", kv_params)
    body = {**body_parameters(), "road_amplitude": 0.0, "pitch_amplitude": 0.0, **KICK}
    system_dir = out_dir / "EngineMountKelvinVoigt"
    parts = write_system(system_dir, bushing_fmu, body_fmu, duration, body, kv_params)
    run = ssp_system.run_fmpy(parts, connections(), step_size, duration, progress=True)
    return spectral_peaks(run, step_size), linearised_frequencies(body), run


def plot(run: dict, path: Path, mount: str = "left") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, (translations, rotations, loops) = plt.subplots(1, 3, figsize=(15, 4.4))
    t = run["time"]
    for a in "xyz":
        translations.plot(t, run[f"{BODY}.{a}"] * 1e3, lw=1.0, label=a)
        rotations.plot(t, run[f"{BODY}.rot_{a}"] * 1e3, lw=1.0, label=f"about {a}")
    translations.plot(t, run[f"{BODY}.base_z"] * 1e3, color="0.6", lw=0.8, ls="--", label="base z")
    rotations.plot(t, run[f"{BODY}.base_pitch"] * 1e3, color="0.6", lw=0.8, ls="--", label="base pitch (about y)")
    translations.set(xlabel="time [s]", ylabel="centre of mass [mm]", title="engine: translations (libcosim)")
    rotations.set(xlabel="time [s]", ylabel="rotation vector [mrad]", title="engine: rotations (libcosim)")
    for axes in (translations, rotations):
        axes.legend(fontsize=7, ncol=2, loc="upper left")
    bushing = bushing_name(mount)
    for a, colour in zip("xyz", ("C0", "C1", "C2")):
        loops.plot(run[f"{BODY}.{port(mount, 'd' + a)}"] * 1e3, run[f"{bushing}.F{a}"] / 1e3, color=colour, lw=0.9,
                   label=f"{a}: {'proposed model' if a != 'z' else 'Spencer model'}")
    loops.set(xlabel="deflection in J's axes [mm]", ylabel="force [kN]",
              title=f"{mount} mount: hysteresis loops of its translational axes")
    loops.legend(fontsize=8)
    for axes in (translations, rotations, loops):
        axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def coupled_set(out: Path, coupling: str) -> Path:
    """The illustrative bushing set, its x and y one radial group where ``coupling`` is radial (x and
    y carry the same model and parameters there, the proposed model with Table 5)."""
    if coupling == "none":
        return BUSHING_SET
    six = read_six_axis(BUSHING_SET)
    return save_six_axis(out / "bushing_radial.json", {axis: (one.model.identifier, one.parameters)
                                                        for axis, one in six.axes.items()}, coupling=coupling)


def print_coupling_effect(args, body: dict[str, float], coupled: dict) -> None:
    """4. The same road run with the uncoupled mounts (fmpy): how much each mount's radial force
    vector (Fx, Fy) and the engine's motion differ, relative to their peaks."""
    bushing_fmu, body_fmu = build_fmus(args.out / "fmus_uncoupled", native=args.native)
    parts = write_system(args.out / "EngineMountUncoupled", bushing_fmu, body_fmu, args.stop, body)
    uncoupled = ssp_system.run_fmpy(parts, connections(), args.step, args.stop)
    print("4. the radial coupling against uncoupled mounts, the same road run (fmpy): rms |F_xy| difference "
          "over rms |F_xy| per mount; largest body translation difference over its peak")
    for m in MOUNTS:
        fxy = [np.column_stack([run[f"{bushing_name(m)}.Fx"], run[f"{bushing_name(m)}.Fy"]]) for run in
               (coupled, uncoupled)]
        share = np.sqrt(np.mean(np.sum((fxy[0] - fxy[1]) ** 2, axis=1)) / np.mean(np.sum(fxy[1] ** 2, axis=1)))
        print(f"   {bushing_name(m):16s} {share:8.2%}")
    for c in "xyz":
        a, b = coupled[f"{BODY}.{c}"], uncoupled[f"{BODY}.{c}"]
        print(f"   body {c}: {np.max(np.abs(a - b)) / np.max(np.abs(b)):8.2%} of its peak "
              f"{np.max(np.abs(b)) * 1e3:.3f} mm")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=1.0, help="stop time of the road run [s]")
    parser.add_argument("--step", type=float, default=1e-3, help="communication step [s]")
    parser.add_argument("--decay", type=float, default=3.0, help="length of the free decay [s]; 0 skips it")
    parser.add_argument("--decay-step", type=float, default=5e-4,
                        help="communication step of the free decay [s] (also run at twice this)")
    parser.add_argument("--out", type=Path, default=REPO / "out" / "engine_mount")
    parser.add_argument("--native", action="store_true", help="the native (compiled C) six-axis bushing FMUs")
    parser.add_argument("--coupling", choices=("none", "radial"), default="none",
                        help="radial: the mounts' x and y (the radial plane of each mount) one coupled group; then "
                             "also what the coupling changes against the uncoupled mounts")
    args = parser.parse_args(argv)
    ssp_system.require_extras("examples/cosim/engine_mount.py")
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    bushing_set = coupled_set(args.out, args.coupling)
    bushing_fmu, body_fmu = build_fmus(args.out / "fmus", bushing_set, native=args.native)
    body = body_parameters()
    system_dir = args.out / "EngineMount"
    parts = write_system(system_dir, bushing_fmu, body_fmu, args.stop, body, bushing_set)
    libcosim = ssp_system.run_libcosim(system_dir, parts, args.step, args.stop)
    fmpy_run = ssp_system.run_fmpy(parts, connections(), args.step, args.stop, progress=True)
    differences = ssp_system.largest_difference(libcosim, fmpy_run)
    worst = max(differences, key=differences.get)
    print(f"1. libcosim vs fmpy, {len(differences)} outputs over {args.stop:g} s at {args.step:g} s: "
          f"largest difference {differences[worst]:.1e} of the peak ({worst})")
    balance = momentum_balance(fmpy_run, args.step, body)
    print(f"2. momentum change - bushing impulses: {balance['momentum']:.1e} of peak |P|; angular momentum "
          f"about the centre of mass: {balance['angular momentum']:.1e} of peak |H|")
    for a, label in (("", "mm"), ("rot_", "mrad")):
        peaks = [np.max(np.abs(libcosim[f'{BODY}.{a}{c}'])) * 1e3 for c in 'xyz']
        print(f"   peak body {'rotation' if a else 'translation'} x, y, z: "
              + ", ".join(f"{p:.3f}" for p in peaks) + f" {label}")
    plot(libcosim, args.out / "engine_mount.png")
    if args.coupling == "radial":
        print_coupling_effect(args, body, fmpy_run)
    if args.decay > 0:
        # The explicit (Jacobi) coupling shifts frequencies by O((w*h)^2): two steps show it,
        # and their h^2 extrapolation shows what the FMUs converge to.
        steps = (2 * args.decay_step, args.decay_step)
        measured = [free_decay(args.out, h, args.decay)[0] for h in steps]
        linearised = linearised_frequencies({**body, **KICK})
        extrapolated = (4 * measured[1] - measured[0]) / 3
        print(f"3. Kelvin-Voigt mounts, free decay of {args.decay:g} s: natural frequencies [Hz]")
        print("   linearised (M^-1 K):        " + "  ".join(f"{f:8.3f}" for f in linearised))
        for h, row in zip(steps, measured):
            print(f"   from the FMUs, h = {h * 1e3:g} ms:" + " " * (8 - len(f"{h * 1e3:g}"))
                  + "  ".join(f"{e:+8.2%}" for e in row / linearised - 1) + "  (difference)")
        print("   h^2-extrapolated to h = 0:  " + "  ".join(f"{e:+8.3%}" for e in extrapolated / linearised - 1))
    np.savez(args.out / "series.npz", **{f"libcosim:{k}": v for k, v in libcosim.items()},
             **{f"fmpy:{k}": v for k, v in fmpy_run.items()})
    print(f"wrote {args.out / 'engine_mount.png'} ({time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
