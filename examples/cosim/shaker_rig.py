"""Co-simulation example: a 300 kg body on four bushing FMUs over a shaker table (2 mm, 12 Hz).

    python examples/cosim/shaker_rig.py [--stop 1.0] [--step 0.001] [--out out/shaker_rig]

The system (``RigBody`` in ``rig_body.py``, built with pythonfmu like the bushings): the body's
displacement and velocity relative to the table go to the ``x`` and ``v`` of four instances
of ``BoucWenBushing.fmu``, each with its own parameter set (the paper's Tables 2, 4 and 5,
and the fit to the real friction damper), and the four forces come back to the body. It is
written once as an SSP 1.0 system (``SystemStructure.ssd``, the FMUs and one ``.ssv`` per
bushing bound to its component) and run twice, with the same fixed step and the same
exchange scheme (every FMU steps from the outputs of the previous step, Jacobi):

(a) by libcosim (Open Simulation Platform) through libcosimpy, from the SSP directory;
(b) by fmpy, in the short master loop :func:`run_fmpy`, with the same ``.ssv`` files as
    start values (``fmu_src.parameter_files.load_parameters``).

It prints the largest difference between the two and writes a plot and both time series.

Tool differences met on the way (documented in the README): libcosim applies a component's
first ``ParameterBinding`` with unprefixed names and needs an explicit step size and both
``startElement`` and ``endElement`` on every connection; fmpy's ``simulate_ssp`` ignores the
SSD's parameter bindings, hence the explicit loop in (b).
"""
from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO))

from fmu_src.parameter_files import load_parameters, save_parameters  # noqa: E402

BUSHINGS = {  # component name -> parameter set of the proposed model
    "bushing_front_left": REPO / "data" / "params_table2_sine.json",
    "bushing_front_right": REPO / "data" / "params_table4_step.json",
    "bushing_rear_left": REPO / "data" / "params_table5_combined.json",
    "bushing_rear_right": REPO / "data" / "params_fit_brfd_sine_0.5Hz_1in.json",
}
BODY = "body"
SSD_NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
          "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon"}


def build_fmus(out_dir: Path) -> tuple[Path, Path]:
    """The bushing FMU (Table 5 defaults) and the body FMU."""
    import build_fmu
    from pythonfmu.builder import FmuBuilder
    bushing = build_fmu.build_fmu(out_dir=out_dir)
    with tempfile.TemporaryDirectory() as stage:
        script = Path(stage) / "rig_body.py"
        shutil.copy2(HERE / "rig_body.py", script)
        body = Path(FmuBuilder.build_FMU(script, dest=out_dir))
    return bushing, body


def write_ssp(system_dir: Path, bushing_fmu: Path, body_fmu: Path, stop_time: float) -> Path:
    """An SSP 1.0 system in ``system_dir`` (unzipped): SystemStructure.ssd + resources/."""
    resources = system_dir / "resources"
    resources.mkdir(parents=True, exist_ok=True)
    shutil.copy2(bushing_fmu, resources / bushing_fmu.name)
    shutil.copy2(body_fmu, resources / body_fmu.name)
    ssd, ssc = SSD_NS["ssd"], SSD_NS["ssc"]
    ET.register_namespace("ssd", ssd)
    ET.register_namespace("ssc", ssc)
    root = ET.Element(f"{{{ssd}}}SystemStructureDescription", version="1.0", name="ShakerRig")
    system = ET.SubElement(root, f"{{{ssd}}}System", name="ShakerRig")
    elements = ET.SubElement(system, f"{{{ssd}}}Elements")

    def component(name, fmu, inputs, outputs, ssv=None):
        element = ET.SubElement(elements, f"{{{ssd}}}Component", name=name, source=f"resources/{fmu.name}",
                                type="application/x-fmu-sharedlibrary")
        connectors = ET.SubElement(element, f"{{{ssd}}}Connectors")
        for kind, names in (("input", inputs), ("output", outputs)):
            for connector in names:
                c = ET.SubElement(connectors, f"{{{ssd}}}Connector", name=connector, kind=kind)
                ET.SubElement(c, f"{{{ssc}}}Real")
        if ssv is not None:
            bindings = ET.SubElement(element, f"{{{ssd}}}ParameterBindings")
            ET.SubElement(bindings, f"{{{ssd}}}ParameterBinding", source=f"resources/{ssv.name}")

    component(BODY, body_fmu, ["F1", "F2", "F3", "F4"], ["x_rel", "v_rel"])
    for name, params_file in BUSHINGS.items():
        ssv = save_parameters(resources / f"{name}.ssv", load_parameters(params_file))
        component(name, bushing_fmu, ["x", "v"], ["F"], ssv)
    connections = ET.SubElement(system, f"{{{ssd}}}Connections")
    for i, name in enumerate(BUSHINGS, start=1):
        for start, start_connector, end, end_connector in ((BODY, "x_rel", name, "x"), (BODY, "v_rel", name, "v"),
                                                           (name, "F", BODY, f"F{i}")):
            ET.SubElement(connections, f"{{{ssd}}}Connection", startElement=start, startConnector=start_connector,
                          endElement=end, endConnector=end_connector)
    # The step size is not part of SSP 1.0's DefaultExperiment: libcosim takes it as an argument.
    ET.SubElement(root, f"{{{ssd}}}DefaultExperiment", startTime="0.0", stopTime=repr(stop_time))
    ET.indent(root)
    path = system_dir / "SystemStructure.ssd"
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)
    return path


OUTPUTS = {BODY: ["x_rel", "v_rel"], **{name: ["F"] for name in BUSHINGS}}


def run_libcosim(system_dir: Path, step_size: float, stop_time: float) -> dict[str, np.ndarray]:
    """Run the SSP system in libcosim; returns time and every output after each step."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.WARNING)  # libcosim's default debug output is very long
    # libcosimpy takes the step in integer nanoseconds.
    execution = CosimExecution.from_ssp_file(str(system_dir), step_size=int(round(step_size * 1e9)))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    indices = {info.name.decode(): info.index for info in execution.slave_infos()}
    references = {}
    for component, names in OUTPUTS.items():
        variables = {v.name.decode(): v.reference for v in execution.slave_variables(indices[component])}
        references[component] = [variables[name] for name in names]
    steps = int(round(stop_time / step_size))
    series = {f"{c}.{n}": np.empty(steps) for c, names in OUTPUTS.items() for n in names}
    for k in range(steps):
        if not execution.step():
            raise RuntimeError(f"libcosim failed at step {k} (t = {k * step_size} s)")
        for component, names in OUTPUTS.items():
            values = observer.last_real_values(indices[component], references[component])
            for name, value in zip(names, values):
                series[f"{component}.{name}"][k] = value
    series["time"] = step_size * np.arange(1, steps + 1)
    return series


def run_fmpy(bushing_fmu: Path, body_fmu: Path, system_dir: Path, step_size: float,
             stop_time: float) -> dict[str, np.ndarray]:
    """The same system in a plain fmpy master loop (Jacobi: all FMUs step from the outputs
    of the previous step), parameter sets from the same .ssv files."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    instances, refs = {}, {}
    for component, fmu in [(BODY, body_fmu), *((name, bushing_fmu) for name in BUSHINGS)]:
        description = read_model_description(str(fmu))
        refs[component] = {v.name: v.valueReference for v in description.modelVariables}
        instance = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(fmu)),
                             modelIdentifier=description.coSimulation.modelIdentifier, instanceName=component)
        instance.instantiate()
        instance.setupExperiment(startTime=0.0)
        instance.enterInitializationMode()
        if component != BODY:
            start_values = load_parameters(system_dir / "resources" / f"{component}.ssv")
            instance.setReal([refs[component][n] for n in start_values], list(start_values.values()))
        instance.exitInitializationMode()
        instances[component] = instance

    def get(component, name):
        return instances[component].getReal([refs[component][name]])[0]

    steps = int(round(stop_time / step_size))
    series = {f"{c}.{n}": np.empty(steps) for c, names in OUTPUTS.items() for n in names}
    outputs = {f"{c}.{n}": get(c, n) for c, names in OUTPUTS.items() for n in names}
    for k in range(steps):
        for i, name in enumerate(BUSHINGS, start=1):
            instances[name].setReal([refs[name]["x"], refs[name]["v"]], [outputs[f"{BODY}.x_rel"], outputs[f"{BODY}.v_rel"]])
            instances[BODY].setReal([refs[BODY][f"F{i}"]], [outputs[f"{name}.F"]])
        for instance in instances.values():
            instance.doStep(currentCommunicationPoint=k * step_size, communicationStepSize=step_size)
        outputs = {key: get(*key.split(".")) for key in outputs}
        for key, value in outputs.items():
            series[key][k] = value
    for instance in instances.values():
        instance.terminate()
        instance.freeInstance()
    series["time"] = step_size * np.arange(1, steps + 1)
    return series


def largest_difference(a: dict, b: dict) -> dict[str, float]:
    """Per signal: max |a - b| over the run, relative to the signal's peak in b."""
    return {key: float(np.max(np.abs(a[key] - b[key])) / max(np.max(np.abs(b[key])), 1e-300))
            for key in a if key != "time"}


def plot(libcosim: dict, fmpy_run: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, (forces, loops) = plt.subplots(1, 2, figsize=(12, 4.4))
    t = libcosim["time"]
    for i, name in enumerate(BUSHINGS):
        color = f"C{i}"
        label = f"{name.replace('bushing_', '')} ({BUSHINGS[name].stem.replace('params_', '')})"
        forces.plot(t, libcosim[f"{name}.F"] / 1e3, color=color, lw=1.2, label=label)
        forces.plot(t, fmpy_run[f"{name}.F"] / 1e3, color="k", lw=0.6, ls=":")
        loops.plot(libcosim[f"{BODY}.x_rel"] * 1e3, libcosim[f"{name}.F"] / 1e3, color=color, lw=1.0)
    forces.plot([], [], color="k", lw=0.6, ls=":", label="fmpy master loop (same system)")
    forces.set(xlabel="time [s]", ylabel="bushing force [kN]", title="libcosim (colours) and fmpy (dotted)")
    loops.set(xlabel="body minus table displacement [mm]", ylabel="bushing force [kN]",
              title="hysteresis loops of the four bushings")
    forces.legend(fontsize=7, loc="lower left")
    for axes in (forces, loops):
        axes.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=1.0, help="stop time [s]")
    parser.add_argument("--step", type=float, default=1e-3, help="communication step [s]")
    parser.add_argument("--out", type=Path, default=REPO / "out" / "shaker_rig")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    bushing_fmu, body_fmu = build_fmus(args.out / "fmus")
    system_dir = args.out / "ShakerRig"
    write_ssp(system_dir, bushing_fmu, body_fmu, args.stop)
    libcosim = run_libcosim(system_dir, args.step, args.stop)
    fmpy_run = run_fmpy(bushing_fmu, body_fmu, system_dir, args.step, args.stop)
    differences = largest_difference(libcosim, fmpy_run)
    for key, value in differences.items():
        print(f"{key:32s} peak {np.max(np.abs(fmpy_run[key])):10.4g}   libcosim vs fmpy: {value:.2e} of peak")
    plot(libcosim, fmpy_run, args.out / "shaker_rig.png")
    np.savez(args.out / "series.npz", **{f"libcosim:{k}": v for k, v in libcosim.items()},
             **{f"fmpy:{k}": v for k, v in fmpy_run.items()})
    print(f"wrote {args.out / 'shaker_rig.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
