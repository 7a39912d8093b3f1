"""The release bundle (``build_fmu.py --release``): the native FMU of every model, FMI 2 and 3,
with the binaries of every platform whose compiler is here (``native/platforms.py``) and its C
sources, its model's default set as start values; the default sets as SSP 1.0 ``.ssv``,
README.txt (from ``release_readme.txt``) and SHA256SUMS (``sha256sum -c``). A user without a
compiler applies a parameter set to the bundle's FMU as start values.
"""
from __future__ import annotations

import hashlib
import shutil
import string
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from .. import __version__
from ..model.registry import MODEL_NAMES, get_model
from ..parameter_files import read_parameter_set, read_six_axis, save_parameters, save_six_axis
from .fmu_inputs import SIX_AXIS, BuildError, default_parameter_file, identifier_of, is_six_axis
from .native.build import NO_COMPILER, build_native_fmu, missing_platforms, platform_names

RELEASE_FMI_VERSIONS = (2, 3)
RELEASE_DIR = Path("dist") / "release"
CHECKSUMS = "SHA256SUMS"
README = "README.txt"
README_TEMPLATE = "release_readme.txt"


def release_models() -> tuple[str, ...]:
    """What a release bundle carries: every one-axis model, then the six-axis FMU."""
    return (*MODEL_NAMES, SIX_AXIS)


def release_fmu_name(model: str, fmi_version: int) -> str:
    """``BoucWenBushing-fmi2.fmu``: the FMU's identifier and FMI version."""
    return f"{identifier_of(model)}-fmi{fmi_version}.fmu"


def release_parameter_name(model: str) -> str:
    """``BoucWenBushing-default.ssv``: the default parameter set of ``model``'s FMUs."""
    return f"{identifier_of(model)}-default.ssv"


@dataclass
class ReleaseBundle:
    """What :func:`build_release` wrote into ``folder``."""
    folder: Path
    fmus: dict[tuple[str, int], Path] = field(default_factory=dict)      # (model, FMI version) -> FMU
    parameter_files: dict[str, Path] = field(default_factory=dict)       # model -> its default set (.ssv)
    platforms: dict[int, list[str]] = field(default_factory=dict)        # FMI version -> binaries in every FMU
    missing: dict[int, dict[str, str]] = field(default_factory=dict)     # FMI version -> {platform: why}
    readme: Path | None = None
    checksums: Path | None = None
    seconds: float = 0.0

    @property
    def files(self) -> list[Path]:
        """Every file of the bundle, the checksum list last."""
        return [*self.fmus.values(), *self.parameter_files.values(), self.readme, self.checksums]


def missing_text(missing: dict[int, dict[str, str]]) -> str:
    """``win64 (FMI 2): why; ...`` of {FMI version: {platform: why it is missing}}."""
    return "; ".join(f"{platform} (FMI {version}): {why}" for version, platforms in missing.items()
                     for platform, why in platforms.items())


def build_release(out_dir: str | Path = RELEASE_DIR, allow_missing_platforms: bool = False,
                  models: tuple[str, ...] | None = None,
                  fmi_versions: tuple[int, ...] = RELEASE_FMI_VERSIONS) -> ReleaseBundle:
    """Build the release bundle: the native FMU of every model (FMI 2 and 3, the binaries of every
    platform of ``fmu_src/fmi/native/platforms.py`` and the C sources in each, the model's default
    parameter set as start values), the default sets as SSP 1.0 ``.ssv``, ``README.txt`` and
    ``SHA256SUMS`` (``sha256sum -c``).

    The FMUs' parameters are start values, so one binary per model serves every parameter set:
    a user without a compiler applies a fitted set to the bundle's FMU (fmpy's
    ``simulate_fmu(start_values=...)``, or the host's SSP import of a ``.ssv``).

    Parameters
    ----------
    out_dir : str or Path
        Directory of the bundle (created if missing; the bundle's files in it are replaced, once
        every FMU is built).
    allow_missing_platforms : bool
        Build without a platform whose compiler is missing (the README and ``missing`` say which)
        instead of refusing.
    models : tuple of str, optional
        The models (default: :func:`release_models`, every one); fewer only for tests.
    fmi_versions : tuple of int
        Default 2 and 3.

    Returns
    -------
    ReleaseBundle

    Raises
    ------
    BuildError
        A platform's compiler is missing (and not ``allow_missing_platforms``), or no platform
        can be built at all; an FMU fails fmpy's validation.
    """
    started = time.perf_counter()
    models = tuple(models or release_models())
    missing = {version: why for version in fmi_versions if (why := missing_platforms(version))}
    if any(len(why) == len(platform_names(version)) for version, why in missing.items()):
        raise BuildError(f"no platform could be built: {missing_text(missing)}; {NO_COMPILER}")
    if missing and not allow_missing_platforms:
        raise BuildError(f"a release bundle carries every platform, and {missing_text(missing)}; install the "
                         "compiler, or give --allow-missing-platforms to make a bundle without them")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    bundle = ReleaseBundle(out_dir, missing=missing)
    with tempfile.TemporaryDirectory(prefix="bushing_release_") as stage:
        stage = Path(stage)
        staged = {}
        for model in models:
            default = default_parameter_file(model)
            name = release_parameter_name(model)
            _write_default_ssv(default, model, stage / name)
            staged[name] = ("ssv", model, default)
            for version in fmi_versions:
                build = build_native_fmu(default, stage / f"fmi{version}", model, version,
                                         tuple(p for p in platform_names(version) if p not in missing.get(version, {})))
                fmu = release_fmu_name(model, version)
                build.path.rename(stage / fmu)
                staged[fmu] = ("fmu", model, version)
                bundle.platforms[version] = build.platforms
        (stage / README).write_text(_release_readme(staged, bundle), encoding="utf-8")
        names = sorted(staged, key=lambda n: (staged[n][0] != "fmu", n)) + [README]
        lines = [f"{hashlib.sha256((stage / name).read_bytes()).hexdigest()}  {name}\n" for name in names]
        (stage / CHECKSUMS).write_text("".join(lines), encoding="utf-8")
        for name in [*names, CHECKSUMS]:
            target = out_dir / name
            shutil.move(stage / name, target)
            kind, model, detail = staged.get(name, (None, None, None))
            if kind == "fmu":
                bundle.fmus[model, detail] = target
            elif kind == "ssv":
                bundle.parameter_files[model] = target
        bundle.readme, bundle.checksums = out_dir / README, out_dir / CHECKSUMS
    bundle.seconds = time.perf_counter() - started
    return bundle


def _write_default_ssv(default: Path, model: str, path: Path) -> None:
    """The release's start values of ``model``: every parameter its FMU has, the mounting's (0
    where the default set has none) included, so that the set applied to the FMU is all of it."""
    def complete(one):
        return {spec.name: one.parameters.get(spec.name, 0.0) for spec in one.model.fmu_specs}
    if is_six_axis(model):
        six = read_six_axis(default)
        save_six_axis(path, {axis: (one.model.identifier, complete(one)) for axis, one in six.axes.items()})
    else:
        save_parameters(path, complete(read_parameter_set(default, model)), model)


def _release_readme(staged: dict, bundle: ReleaseBundle) -> str:
    """The bundle's README.txt: ``release_readme.txt`` with the bundle's version, platforms, files."""
    fmus = [(name, model, version) for name, (kind, model, version) in staged.items() if kind == "fmu"]
    sets = [(name, model, default) for name, (kind, model, default) in staged.items() if kind == "ssv"]
    width = max(len(name) for name in staged) + 2

    def title(model: str) -> str:
        return "six uncoupled axes, each one of the models" if is_six_axis(model) else get_model(model).title

    missing = ""
    if bundle.missing:
        missing = "\n".join(["MISSING PLATFORMS: this bundle was made without",
                             *(f"    {platform} (FMI {version}): {why}" for version, platforms in bundle.missing.items()
                               for platform, why in platforms.items()),
                             "Rebuild it where that compiler is installed for a complete bundle.", "", ""])
    files = [f"{name:<{width}}{title(model)}; FMI {version}.0" for name, model, version in fmus]
    files += [f"{name:<{width}}default parameter set of its FMUs (SSP 1.0 ParameterValues; {default.name})"
              for name, model, default in sets]
    files += [f"{README:<{width}}this file",
              f"{CHECKSUMS:<{width}}SHA-256 of every file above: check with `sha256sum -c {CHECKSUMS}`"]
    template = string.Template((Path(__file__).with_name(README_TEMPLATE)).read_text(encoding="utf-8"))
    return template.substitute(
        version=__version__, underline="=" * (len(__version__) + 37),
        platforms="\n".join(f"    FMI {version}: {', '.join(names)}" for version, names in bundle.platforms.items()),
        missing=missing, files="\n".join(files), example_fmu=fmus[0][0])
