"""The axes of a bushing FMU: their ports, units, and how their values reach a model's kernels.

A one-axis FMU has one axis: ports ``x`` [m], ``v`` [m/s], ``F`` [N], parameters named as the
model names them. The six-axis FMU (``SixAxisBushing``) joins two markers I and J of a
multibody model: three translational axes x, y, z and three rotational axes rx, ry, rz, all in
the axes of marker J, each one of the models and uncoupled from the others (the diagonal
bushing of MSC Adams' BUSHING, Project Chrono's ``ChLoadBodyBodyBushing*``, Simbody's
``LinearBushing``). Its parameters and locals are named ``<axis>.<name>`` (``x.k0``, ``rz.c``).

Units. Every port is SI. A translational axis works in the paper's N-mm-s units (the kernels
see mm and mm/s; the force is in N). A rotational axis reads an angle where a translational one
reads millimetres: the kernels see rad and rad/s and return N.mm, which the port gives as N.m;
its parameters are the translational ones with mm replaced by rad and N by N.mm (k in
N.mm/rad, c in N.mm.s/rad, z in N.mm, beta and gamma in (N.mm)^(1-n)/rad, x0 in rad, preload
in N.mm), so a one-axis parameter set typed for a torsion test reads the same.

Small rotations. ``rx, ry, rz`` is the rotation vector (axis times angle) of I relative to J;
as in Adams and Chrono, each component is taken as the angle about its own axis, which holds
for small angles only: above ``SMALL_ANGLE_RAD`` (0.35 rad, 20 degrees) the components of a
rotation depend on the order of rotations by more than a few per cent, and the FMU warns.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from ..model.parameter_specs import ParameterError
from ..model.definition import BushingModel
from ..model.units import rotational

SMALL_ANGLE_RAD = 0.35
"""Above this rotation the small-angle bushing is an approximation worth a warning."""
PLAUSIBLE_TRAVEL_M = 0.1
"""|x| beyond this is far outside any rubber bushing's travel: most likely millimetres entered
where metres are expected. Warned about, not refused."""
PLAUSIBLE_ANGULAR_VELOCITY_RAD_S = 50.0
"""The rotational counterpart of definition.PLAUSIBLE_VELOCITY_MM_S (for the force bound)."""

@dataclass(frozen=True)
class Axis:
    """One axis of an FMU: its name (empty for a one-axis FMU) and port names."""
    name: str
    displacement: str
    velocity: str
    output: str
    rotational: bool = False

    @property
    def prefix(self) -> str:
        """What the axis's parameter and local names start with ("x." ...; "" for one axis)."""
        return f"{self.name}." if self.name else ""

    @property
    def label(self) -> str:
        """How messages name the axis ("axis rz: "; "" for one axis)."""
        return f"axis {self.name}: " if self.name else ""

    @property
    def to_kernel(self) -> float:
        """Port value -> kernel value: m -> mm (translational), rad -> rad (rotational)."""
        return 1.0 if self.rotational else 1000.0

    @property
    def from_kernel(self) -> float:
        """Kernel force -> port: N -> N (translational), N.mm -> N.m (rotational)."""
        return 1e-3 if self.rotational else 1.0

    @property
    def displacement_unit(self) -> str:
        return "rad" if self.rotational else "m"

    @property
    def velocity_unit(self) -> str:
        return "rad/s" if self.rotational else "m/s"

    @property
    def output_unit(self) -> str:
        return "N.m" if self.rotational else "N"

    @property
    def plausible_travel(self) -> float:
        """Port displacement above which the FMU warns (once)."""
        return SMALL_ANGLE_RAD if self.rotational else PLAUSIBLE_TRAVEL_M

    def state_port(self, unit: str) -> tuple[str, float]:
        """(FMU unit, kernel -> port factor) of a state declared in "N", "m", "m/s", "1" or "K"
        (definition; a temperature is one on every axis), or of a coupled group's event indicator
        in "N.m/s" (z.u: N times mm/s, or N.mm times rad/s) or "m2/s" (d.v: mm^2/s, or rad^2/s)."""
        if unit in ("1", "K"):
            return (unit, 1.0)
        if unit == "N.m/s":
            return ("N.m/s", 1e-3)
        if unit == "m2/s":
            return ("rad2/s", 1.0) if self.rotational else ("m2/s", 1e-6)
        if unit == "N":
            return ("N.m", 1e-3) if self.rotational else ("N", 1.0)
        if unit == "m/s":
            return ("rad/s", 1.0) if self.rotational else ("m/s", 1e-3)
        return ("rad", 1.0) if self.rotational else ("m", 1e-3)


ONE_AXIS = Axis("", "x", "v", "F")
SIX_AXES = (
    Axis("x", "dx", "vx", "Fx"), Axis("y", "dy", "vy", "Fy"), Axis("z", "dz", "vz", "Fz"),
    Axis("rx", "rx", "wx", "Mx", rotational=True), Axis("ry", "ry", "wy", "My", rotational=True),
    Axis("rz", "rz", "wz", "Mz", rotational=True),
)
SIX_AXIS_NAMES = tuple(axis.name for axis in SIX_AXES)
SIX_AXIS_IDENTIFIER = "SixAxisBushing"


GROUPS = {"translation": {"none": (), "radial": ("x", "y"), "spherical": ("x", "y", "z")},
          "rotation": {"none": (), "conical": ("rx", "ry")}}
"""The coupled groups of the six-axis FMU, per kind of axis: radial = x and y (the bushing's axis
along J's z, Adams' convention), spherical = x, y and z, conical = rx and ry (tilt about the
bushing's axis' normals). The axes of a group carry one model and one parameter set, whose coupled
form (``definition.CoupledKernels``) acts on their displacements as one vector."""


@dataclass(frozen=True)
class Coupling:
    """Which axes of the six-axis FMU are coupled: ``translation`` one of none, radial, spherical;
    ``rotation`` one of none, conical (:data:`GROUPS`)."""
    translation: str = "none"
    rotation: str = "none"

    def __post_init__(self):
        for kind in ("translation", "rotation"):
            name = getattr(self, kind)
            if name not in GROUPS[kind]:
                raise ParameterError(f"unknown {kind} coupling {name!r}; allowed: {', '.join(GROUPS[kind])}")

    @classmethod
    def of(cls, value) -> "Coupling":
        """From a parameter file's ``"coupling"``: absent (none), an object {"translation": ...,
        "rotation": ...}, or one group's name ("radial" is short for {"translation": "radial"})."""
        if value is None:
            return cls()
        if isinstance(value, Coupling):
            return value
        if isinstance(value, str):
            for kind, names in GROUPS.items():
                if value in names:
                    return cls(**{kind: value})
            raise ParameterError(f"unknown coupling {value!r}; allowed: "
                                 + ", ".join(name for names in GROUPS.values() for name in names if name != "none")
                                 + ", or an object {\"translation\": ..., \"rotation\": ...}")
        if isinstance(value, dict):
            unknown = sorted(set(value) - set(GROUPS))
            if unknown:
                raise ParameterError(f"unknown coupling keys {unknown}; allowed: translation, rotation")
            return cls(**{kind: str(name) for kind, name in value.items()})
        raise ParameterError(f"coupling {value!r}: give a group's name or an object {{\"translation\": ..., "
                             "\"rotation\": ...}")

    @property
    def named_groups(self) -> tuple[tuple[str, tuple[str, ...]], ...]:
        """(the group's name, its axes) of each coupled group."""
        return tuple((name, GROUPS[kind][name]) for kind, name in (("translation", self.translation),
                                                                    ("rotation", self.rotation)) if name != "none")

    @property
    def groups(self) -> tuple[tuple[str, ...], ...]:
        """The coupled groups' axis names (none for uncoupled axes)."""
        return tuple(axes for _, axes in self.named_groups)

    def as_json(self) -> dict[str, str]:
        return {"translation": self.translation, "rotation": self.rotation}

    def describe(self) -> str:
        """In words, for messages: 'radial (x, y)', 'none'."""
        return " and ".join(f"{name} ({', '.join(axes)})" for name, axes in self.named_groups) or "none"


def group_name(names: tuple[str, ...]) -> str:
    """The name of the coupled group of these axes (radial, spherical, conical)."""
    for kind in GROUPS.values():
        for name, group in kind.items():
            if group == tuple(names) and name != "none":
                return name
    raise ParameterError(f"the axes {', '.join(names)} are no coupled group")


def model_on_axis(model: BushingModel, axis: Axis) -> BushingModel:
    """``model`` with the parameter units of ``axis`` (the same kernels and checks)."""
    if not axis.rotational:
        return model
    specs = tuple(replace(spec, unit=rotational(spec.unit)) for spec in model.specs)
    return replace(model, specs=specs, title=f"{model.title}, rotational", rotational=True)


def six_axis(name: str) -> Axis:
    """The axis called ``name`` (x, y, z, rx, ry, rz)."""
    for axis in SIX_AXES:
        if axis.name == name:
            return axis
    raise ParameterError(f"unknown axis {name!r}; the six axes are {', '.join(SIX_AXIS_NAMES)}")
