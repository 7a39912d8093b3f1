"""One co-simulation system, written once as SSP 1.0 and run by two masters: libcosim and fmpy.

The examples (``shaker_rig.py``, ``engine_mount.py``) describe their system as components
(an FMU, its connected inputs and outputs, optionally an ``.ssv`` parameter set bound to it)
and connections (output of one component -> input of another). From that:

- :func:`write_ssp` writes an unzipped SSP 1.0 directory: ``SystemStructure.ssd`` and
  ``resources/`` with the FMUs and ``.ssv`` files;
- :func:`run_libcosim` runs that directory in libcosim (Open Simulation Platform) through
  libcosimpy;
- :func:`run_fmpy` runs the same components and connections in a plain fmpy master loop,
  the start values from the same ``.ssv`` files (read with fmpy's own ``read_ssv``).

Both use one fixed communication step and the same exchange (Jacobi: every FMU steps from the
outputs of the previous step), so they agree to rounding. Both return a dict of time series,
``"<component>.<output>"`` -> the value after each step, and ``"time"``; the fmpy run also
records every connected input as it was set before each step (``"<component>.<input>"``).

Tool differences met (see the README): libcosim applies a component's first
``ParameterBinding`` with unprefixed names, needs ``startElement`` and ``endElement`` on every
connection and takes the step size explicitly, in integer nanoseconds (SSP 1.0's
DefaultExperiment has none); fmpy's ``simulate_ssp`` ignores the SSD's parameter bindings, hence
the explicit loop.
"""
from __future__ import annotations

import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence
from xml.etree import ElementTree as ET

import numpy as np

def require_extras(script: str) -> None:
    """Stop with one line naming the first missing extra (exit 2): the examples run libcosim
    (``cosim``) and plot (``plot``)."""
    from identification.extras import require_or_exit
    require_or_exit("cosim", script)
    require_or_exit("plot", script)


SSD_NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
          "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon"}


@dataclass(frozen=True)
class Component:
    """One FMU instance of the system. ``ssv``: its parameter set (copied to resources/)."""
    name: str
    fmu: Path
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    ssv: Path | None = None


@dataclass(frozen=True)
class Connection:
    """``start.output`` drives ``end.input``."""
    start: str
    output: str
    end: str
    input: str


def build_pythonfmu(script: Path, out_dir: Path) -> Path:
    """Build the FMU of a single-file pythonfmu slave (``script``) into ``out_dir``."""
    from pythonfmu.builder import FmuBuilder
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as stage:
        staged = Path(stage) / script.name
        shutil.copy2(script, staged)
        return Path(FmuBuilder.build_FMU(staged, dest=out_dir))


def write_ssp(system_dir: Path, system_name: str, components: Sequence[Component],
              connections: Sequence[Connection], stop_time: float) -> Path:
    """An SSP 1.0 system in ``system_dir`` (unzipped): SystemStructure.ssd + resources/."""
    resources = system_dir / "resources"
    resources.mkdir(parents=True, exist_ok=True)
    ssd, ssc = SSD_NS["ssd"], SSD_NS["ssc"]
    ET.register_namespace("ssd", ssd)
    ET.register_namespace("ssc", ssc)
    root = ET.Element(f"{{{ssd}}}SystemStructureDescription", version="1.0", name=system_name)
    system = ET.SubElement(root, f"{{{ssd}}}System", name=system_name)
    elements = ET.SubElement(system, f"{{{ssd}}}Elements")
    for component in components:
        if not (resources / component.fmu.name).exists():
            shutil.copy2(component.fmu, resources / component.fmu.name)
        element = ET.SubElement(elements, f"{{{ssd}}}Component", name=component.name,
                                source=f"resources/{component.fmu.name}", type="application/x-fmu-sharedlibrary")
        connectors = ET.SubElement(element, f"{{{ssd}}}Connectors")
        for kind, names in (("input", component.inputs), ("output", component.outputs)):
            for name in names:
                connector = ET.SubElement(connectors, f"{{{ssd}}}Connector", name=name, kind=kind)
                ET.SubElement(connector, f"{{{ssc}}}Real")
        if component.ssv is not None:
            if component.ssv.parent.resolve() != resources.resolve():
                shutil.copy2(component.ssv, resources / component.ssv.name)
            bindings = ET.SubElement(element, f"{{{ssd}}}ParameterBindings")
            ET.SubElement(bindings, f"{{{ssd}}}ParameterBinding", source=f"resources/{component.ssv.name}")
    links = ET.SubElement(system, f"{{{ssd}}}Connections")
    for c in connections:
        ET.SubElement(links, f"{{{ssd}}}Connection", startElement=c.start, startConnector=c.output,
                      endElement=c.end, endConnector=c.input)
    # The step size is not part of SSP 1.0's DefaultExperiment: libcosim takes it as an argument.
    ET.SubElement(root, f"{{{ssd}}}DefaultExperiment", startTime="0.0", stopTime=repr(stop_time))
    ET.indent(root)
    path = system_dir / "SystemStructure.ssd"
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)
    return path


def run_libcosim(system_dir: Path, components: Sequence[Component], step_size: float,
                 stop_time: float) -> dict[str, np.ndarray]:
    """Run the SSP system in libcosim; every component output after each step, and time [s]."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.WARNING)  # libcosim's default debug output is very long
    execution = CosimExecution.from_ssp_file(str(system_dir), step_size=int(round(step_size * 1e9)))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    indices = {info.name.decode(): info.index for info in execution.slave_infos()}
    references = {}
    for component in components:
        variables = {v.name.decode(): v.reference for v in execution.slave_variables(indices[component.name])}
        references[component.name] = [variables[name] for name in component.outputs]
    steps = int(round(stop_time / step_size))
    series = {f"{c.name}.{n}": np.empty(steps) for c in components for n in c.outputs}
    for k in range(steps):
        if not execution.step():
            raise RuntimeError(f"libcosim failed at step {k} (t = {k * step_size} s)")
        for component in components:
            values = observer.last_real_values(indices[component.name], references[component.name])
            for name, value in zip(component.outputs, values):
                series[f"{component.name}.{name}"][k] = value
    series["time"] = step_size * np.arange(1, steps + 1)
    return series


def run_fmpy(components: Sequence[Component], connections: Sequence[Connection], step_size: float,
             stop_time: float, progress: bool = False) -> dict[str, np.ndarray]:
    """The same system in a plain fmpy master loop (Jacobi), start values from each
    component's ``.ssv``. Records the outputs after each step and the connected inputs as set
    before it."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.ssp.ssd import read_ssv
    instances, refs, unzipped = {}, {}, {}
    for component in components:
        key = str(component.fmu)
        if key not in unzipped:
            unzipped[key] = (read_model_description(key), extract(key))
        description, directory = unzipped[key]
        refs[component.name] = {v.name: v.valueReference for v in description.modelVariables}
        instance = FMU2Slave(guid=description.guid, unzipDirectory=directory,
                             modelIdentifier=description.coSimulation.modelIdentifier, instanceName=component.name)
        instance.instantiate()
        instance.setupExperiment(startTime=0.0)
        instance.enterInitializationMode()
        if component.ssv is not None:
            start_values = {p.name: float(p.value) for p in read_ssv(str(component.ssv)).parameters
                            if p.type == "Real"}
            instance.setReal([refs[component.name][n] for n in start_values], list(start_values.values()))
        instance.exitInitializationMode()
        instances[component.name] = instance

    by_name = {c.name: c for c in components}
    output_refs = {c.name: [refs[c.name][n] for n in c.outputs] for c in components}
    # the connections grouped by the component they drive, in one setReal call each
    driven = {c.name: [x for x in connections if x.end == c.name] for c in components}
    input_refs = {name: [refs[name][x.input] for x in links] for name, links in driven.items()}

    def read_outputs():
        return {name: dict(zip(by_name[name].outputs, instances[name].getReal(output_refs[name])))
                for name in instances}

    steps = int(round(stop_time / step_size))
    series = {f"{c.name}.{n}": np.empty(steps) for c in components for n in c.outputs}
    series.update({f"{x.end}.{x.input}": np.empty(steps) for x in connections})
    outputs = read_outputs()
    iterator = range(steps)
    if progress:
        from tqdm import tqdm
        iterator = tqdm(iterator, desc="fmpy master", unit="step", leave=False)
    for k in iterator:
        for name, links in driven.items():
            if links:
                values = [outputs[x.start][x.output] for x in links]
                instances[name].setReal(input_refs[name], values)
                for x, value in zip(links, values):
                    series[f"{x.end}.{x.input}"][k] = value
        for instance in instances.values():
            instance.doStep(currentCommunicationPoint=k * step_size, communicationStepSize=step_size)
        outputs = read_outputs()
        for name, values in outputs.items():
            for output, value in values.items():
                series[f"{name}.{output}"][k] = value
    for instance in instances.values():
        instance.terminate()
        instance.freeInstance()
    series["time"] = step_size * np.arange(1, steps + 1)
    return series


def largest_difference(a: dict, b: dict, keys=None) -> dict[str, float]:
    """Per signal: max |a - b| over the run, relative to the signal's peak in b."""
    keys = [key for key in a if key != "time" and key in b] if keys is None else keys
    return {key: float(np.max(np.abs(a[key] - b[key])) / max(np.max(np.abs(b[key])), 1e-300)) for key in keys}
