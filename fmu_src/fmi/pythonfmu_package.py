"""The pythonfmu FMU of a bushing model (FMI 2.0 co-simulation; the host needs Python with
pythonfmu): the slave module ``pythonfmu_slave.py`` and the rest of ``fmu_src`` packed by
pythonfmu's builder, the project's modelDescription.xml in place of pythonfmu's.

What the build adds to pythonfmu's output, and why:
- Unique module names. The slave module is packed as ``boucwen_bushing_<hash>.py`` with its
  library in ``boucwen_bushing_<hash>_lib/``, the hash taken over the packed sources, the
  model and the default parameters: pythonfmu imports packed modules into the host's shared
  ``sys.modules``, so two FMUs with equal module names would silently run the first one's code.
- One class per model: the packed slave module ends with ``class <identifier>(BushingSlave)``,
  which pythonfmu picks (longest hierarchy) and which names the modelIdentifier.
- modelDescription.xml: units on every variable and their UnitDefinitions, the
  InitialUnknowns and the output's direct dependencies (pythonfmu writes none of these), and
  a check with ``fmpy.validation.validate_fmu`` that must find no problem.
- ``needsExecutionTool="true"`` is kept on purpose: the FMU runs Python code and needs a
  Python 3 runtime (libpython) in the host process.
"""
from __future__ import annotations

import hashlib
import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from .. import __version__
from ..model.registry import DEFAULT_MODEL
from . import model_description
from .fmu_inputs import BuildError, check_valid, fmu_axes, groups_of

SOURCE_DIR = Path(__file__).resolve().parents[1]
SLAVE_MODULE = "fmi/pythonfmu_slave.py"
PACKED_LIBRARY_INIT = '''"""Packed library of the bushing FMU (written by build_fmu.py)."""
from pathlib import Path

from . import parameter_files
from .fmi import axes, runtime_messages, variables
from .kernels import numba_binding
from .model import integration

# Compiled here, once per process, while the extracted files surely exist (a host may delete them
# after the first instance); STEP_AXES holds the compiled batched step of each model ({} for the
# pure-Python step); STEP says which step runs (logged by every instance).
AXES, STEP_AXES, STEP = numba_binding.compile_axes(
    parameter_files.fmu_axes(Path(__file__).with_name("default_parameters.json")))
GROUPS = parameter_files.fmu_groups(Path(__file__).with_name("default_parameters.json"))
'''
NOT_PACKED = ("fmi/native/", "fmi/model_description.py", "fmi/dependencies.py", "fmi/fmu_inputs.py",
              "fmi/pythonfmu_package.py", "fmi/release.py", "kernels/python_to_c.py")
"""What the pythonfmu FMU leaves out of fmu_src: what builds an FMU and never runs inside one (the
native FMU's generator, the C translator, the model description and its dependencies, the
builders themselves)."""
LIBRARY_MODULES = tuple(sorted(name for name in (path.relative_to(SOURCE_DIR).as_posix()
                                                 for path in SOURCE_DIR.rglob("*.py"))
                               if name not in ("__init__.py", SLAVE_MODULE) and not name.startswith(NOT_PACKED)))
"""What the pythonfmu FMU packs beside its slave module, as paths under fmu_src: every module of
it but the native FMU's generator (the models, the contract, the kernels' machinery, the FMI
layer, the parameter files; its __init__ is PACKED_LIBRARY_INIT), so a model module added to
fmu_src/models/ is packed too."""


def build_fmu(params_file: str | Path | None = None, out_dir: str | Path = "dist",
              model: str = DEFAULT_MODEL) -> Path:
    """Build the pythonfmu FMU (FMI 2.0 co-simulation; the host needs Python with pythonfmu).

    Parameters
    ----------
    params_file : str or Path, optional
        Parameter file whose values become the start values (default: the model's shipped set,
        ``default_parameter_file``).
    out_dir : str or Path
        Directory for ``<Identifier>.fmu`` (created if missing).
    model : str
        A model of ``fmu_src/model/registry.py`` or ``six_axis`` (default: the paper's, ``proposed``).

    Returns
    -------
    Path
        The FMU written.

    Raises
    ------
    BuildError
        The FMU fails fmpy's validation; ``ParameterError`` for an invalid parameter file.
    """
    from pythonfmu import builder
    from pythonfmu.builder import FmuBuilder
    pythonfmu_folder = Path(builder.__file__).parent
    binaries = pythonfmu_folder / "resources" / "binaries"
    if not any(binaries.rglob("*.so")) and not any(binaries.rglob("*.dll")):
        raise BuildError(f"pythonfmu here ({pythonfmu_folder}) has no FMU binaries: it is the copy a "
                         "pythonfmu FMU loaded into this process carries, not an installed one; build before "
                         "loading a pythonfmu FMU, or in another process")

    identifier, title, axes, defaults_json = fmu_axes(params_file, model)
    defaults_text = json.dumps(defaults_json, indent=2) + "\n"
    slave_text = ((SOURCE_DIR / SLAVE_MODULE).read_text()
                  + f"\n\nclass {identifier}(BushingSlave):\n"
                    f"    \"\"\"The {title} (written by build_fmu.py).\"\"\"\n"
                    f"    version = {__version__!r}\n")

    digest = hashlib.sha256(slave_text.encode())
    for name in LIBRARY_MODULES:
        digest.update((SOURCE_DIR / name).read_bytes())
    digest.update(defaults_text.encode())
    module_name = f"boucwen_bushing_{digest.hexdigest()[:12]}"

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="bushing_build_") as stage:
        stage = Path(stage)
        script = stage / f"{module_name}.py"
        script.write_text(slave_text)
        library = stage / f"{module_name}_lib"
        library.mkdir()
        (library / "__init__.py").write_text(PACKED_LIBRARY_INIT)
        for name in LIBRARY_MODULES:
            (library / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(SOURCE_DIR / name, library / name)
        (library / "default_parameters.json").write_text(defaults_text)

        sys.path.insert(0, str(stage))
        try:
            fmu_path = Path(FmuBuilder.build_FMU(
                script, dest=out_dir, project_files=[library],
                canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        finally:
            sys.path.remove(str(stage))
            for loaded in [m for m in sys.modules if m.startswith(module_name)]:
                del sys.modules[loaded]

    _write_model_description(fmu_path, identifier, axes, groups_of(defaults_json))
    return check_valid(fmu_path)


def _write_model_description(fmu_path: Path, identifier: str, axes: list, groups=()) -> None:
    """Replace pythonfmu's modelDescription.xml by the project's one writer's
    (``fmu_src.fmi.model_description``, as for the native FMU), keeping the guid pythonfmu gave it.
    ``axes``: [(axes.Axis, model on it, parameters)], what the packed library reads back from the
    defaults it is given (parameter_files.fmu_axes); ``groups``: its coupled groups."""
    from pythonfmu import __version__ as pythonfmu_version
    with zipfile.ZipFile(fmu_path) as archive:
        entries = {info.filename: archive.read(info.filename) for info in archive.infolist()}
    guid = ET.fromstring(entries["modelDescription.xml"]).get("guid")
    entries["modelDescription.xml"] = model_description.fmi2(axes, identifier, guid,
                                                             model_description.pythonfmu_face(pythonfmu_version),
                                                             groups=groups)
    with zipfile.ZipFile(fmu_path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in entries.items():
            archive.writestr(name, data)
