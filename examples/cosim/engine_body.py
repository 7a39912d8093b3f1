"""pythonfmu slave: a rigid engine (6 DOF) on three six-axis bushings over a moving base.

The other half of ``engine_mount.py``: the work a multibody tool does around a bushing. The
body computes, for each mount, the pose and twist of the bushing's marker I (on the engine)
relative to its marker J (on the base) in J's axes, which are the six-axis bushing FMU's
inputs, and applies the bushing's outputs back with their lever arms.

Frames and conventions (SI throughout):
- world: fixed, z up. The base (the car body) translates vertically, ``base_z(t)`` [m] (the
  road input), and pitches about the world y axis, ``base_pitch(t)`` [rad]: both sines faded
  in over ``fade_time`` (a half-cosine), so the run starts from rest.
- body: the engine's centre of mass; at rest it sits at the world origin with its axes on
  the world's. Its orientation R maps body axes to world axes.
- mount m (``MOUNTS``): at rest, markers I (fixed in the body) and J (fixed in the base)
  coincide at ``position`` [m] from the centre of mass, with axes rotated from the body's
  (and base's) by the rotation vector ``axes`` [rad]. No gravity: the motion is about the
  static equilibrium, and every bushing starts unloaded.
- what goes to bushing m, in J's axes: d = R_J^T (p_I - p_J) [m]; the rotation vector of
  R_J^T R_I [rad]; the rate of d as seen from J, R_J^T (v_I - v_J - w_J x (p_I - p_J)) [m/s];
  the relative angular velocity R_J^T (w_I - w_J) [rad/s] (the small-angle bushing's rate).
- what comes back (the convention of SixAxisBushing, Adams's): body I receives -F at I's
  origin and the moment -M, both in J's axes: in world axes the force f = -R_J F and, about
  the centre of mass, the torque r x f - R_J M with r = p_I - p (the lever arm).

Integration: within a communication step the bushing actions are held (the master passes
them once per step) as a world force and a world torque about the centre of mass. The
momentum P = m v [N.s] and the angular momentum about the centre of mass H [N.m.s] (world
axes) are the state and change by exactly h*force and h*torque; then the body moves with the
new momenta (semi-implicit Euler, stable for w*h < 2): the centre of mass by h*P/m, the
orientation with w = R J^-1 R^T H (J the body-axes inertia tensor) by ``ROTATION_SUBSTEPS``
midpoint steps of the exponential map.
"""
import math

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status
from scipy.spatial.transform import Rotation

MOUNTS = {
    # name: (position of I and J at rest from the centre of mass [m], axes as a rotation vector [rad])
    "left": ((0.05, 0.32, 0.10), (math.radians(30.0), 0.0, 0.0)),       # main mount, inclined 30 deg
    "right": ((0.05, -0.28, 0.12), (-math.radians(30.0), 0.0, 0.0)),    # main mount, inclined -30 deg
    "rear": ((-0.38, 0.02, -0.15),                                       # torque rod: turned 90 deg
             tuple(Rotation.from_euler("zy", [90.0, 20.0], degrees=True).as_rotvec())),  # and tilted 20
}
BUSHING_INPUTS = ("dx", "dy", "dz", "rx", "ry", "rz", "vx", "vy", "vz", "wx", "wy", "wz")
BUSHING_OUTPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")
ROTATION_SUBSTEPS = 4

BODY_OUTPUTS = (
    ("x", "m", "centre of mass position, world x"), ("y", "m", "centre of mass position, world y"),
    ("z", "m", "centre of mass position, world z"),
    ("rot_x", "rad", "body orientation as a rotation vector, world x"),
    ("rot_y", "rad", "body orientation as a rotation vector, world y"),
    ("rot_z", "rad", "body orientation as a rotation vector, world z"),
    ("omega_x", "rad/s", "angular velocity, world x"), ("omega_y", "rad/s", "angular velocity, world y"),
    ("omega_z", "rad/s", "angular velocity, world z"),
    ("Px", "N.s", "momentum, world x"), ("Py", "N.s", "momentum, world y"), ("Pz", "N.s", "momentum, world z"),
    ("Hx", "N.m.s", "angular momentum about the centre of mass, world x"),
    ("Hy", "N.m.s", "angular momentum about the centre of mass, world y"),
    ("Hz", "N.m.s", "angular momentum about the centre of mass, world z"),
    ("base_z", "m", "base (car body) vertical position"), ("base_pitch", "rad", "base pitch about world y"),
)
PARAMETERS = (
    ("mass", "kg", "engine mass", 160.0),
    ("Ixx", "kg.m2", "inertia tensor about the centre of mass, body axes, xx", 6.0),
    ("Iyy", "kg.m2", "inertia tensor, yy", 8.0), ("Izz", "kg.m2", "inertia tensor, zz", 7.0),
    ("Ixy", "kg.m2", "inertia tensor entry xy (= yx; the tensor's entry, minus the product of inertia)", 0.4),
    ("Ixz", "kg.m2", "inertia tensor entry xz", -0.8), ("Iyz", "kg.m2", "inertia tensor entry yz", 0.3),
    ("road_amplitude", "m", "base vertical amplitude", 1.0e-3), ("road_frequency", "Hz", "base vertical frequency", 20.0),
    ("pitch_amplitude", "rad", "base pitch amplitude", 4.0e-3), ("pitch_frequency", "Hz", "base pitch frequency", 11.0),
    ("fade_time", "s", "half-cosine fade-in of the base motion", 0.1),
    ("v0_x", "m/s", "initial velocity, world x", 0.0), ("v0_y", "m/s", "initial velocity, world y", 0.0),
    ("v0_z", "m/s", "initial velocity, world z", 0.0),
    ("w0_x", "rad/s", "initial angular velocity, world x", 0.0),
    ("w0_y", "rad/s", "initial angular velocity, world y", 0.0),
    ("w0_z", "rad/s", "initial angular velocity, world z", 0.0),
)


def port(mount: str, name: str) -> str:
    """The body's port for ``name`` of bushing ``mount`` ("left_dx", "rear_Mz")."""
    return f"{mount}_{name}"


def mount_geometry():
    """Per mount: (position from the centre of mass [m], J's axes in base/body axes as a matrix)."""
    return {name: (np.array(position), Rotation.from_rotvec(axes).as_matrix())
            for name, (position, axes) in MOUNTS.items()}


def inertia_tensor(Ixx, Iyy, Izz, Ixy, Ixz, Iyz) -> np.ndarray:
    return np.array([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])


def base_motion(t, road_amplitude, road_frequency, pitch_amplitude, pitch_frequency, fade_time):
    """(z [m], dz/dt [m/s], pitch [rad], dpitch/dt [rad/s]) of the base at time t [s]."""
    if t < fade_time:
        fade = 0.5 * (1.0 - math.cos(math.pi * t / fade_time))
        dfade = 0.5 * math.pi / fade_time * math.sin(math.pi * t / fade_time)
    else:
        fade, dfade = 1.0, 0.0

    def faded_sine(amplitude, frequency):
        omega = 2.0 * math.pi * frequency
        s, c = math.sin(omega * t), math.cos(omega * t)
        return amplitude * fade * s, amplitude * (dfade * s + fade * omega * c)

    z, dz = faded_sine(road_amplitude, road_frequency)
    pitch, dpitch = faded_sine(pitch_amplitude, pitch_frequency)
    return z, dz, pitch, dpitch


def pitch_matrix(angle: float) -> np.ndarray:
    """Rotation by ``angle`` [rad] about the world y axis."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def exp_so3(w: np.ndarray) -> np.ndarray:
    """The rotation matrix of the rotation vector ``w`` (Rodrigues)."""
    angle = math.sqrt(float(w @ w))
    K = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    if angle < 1e-8:
        return np.eye(3) + K + 0.5 * K @ K
    return np.eye(3) + math.sin(angle) / angle * K + (1.0 - math.cos(angle)) / angle ** 2 * K @ K


class EngineBody(Fmi2Slave):
    author = "Bouc-Wen bushing project"
    description = "Rigid engine (6 DOF) on three six-axis bushings over a vertically moving, pitching base"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-3)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name, unit, meaning, value in PARAMETERS:
            setattr(self, name, value)
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed, description=f"{meaning} [{unit}]"))
        for mount in MOUNTS:
            for name in BUSHING_OUTPUTS:
                unit = "N" if name.startswith("F") else "N.m"
                setattr(self, port(mount, name), 0.0)
                self.register_variable(Real(port(mount, name), causality=Fmi2Causality.input,
                                            description=f"bushing {mount}: {name} in its J axes [{unit}]"))
            for name in BUSHING_INPUTS:
                unit = {"d": "m", "r": "rad", "v": "m/s", "w": "rad/s"}[name[0]]
                setattr(self, port(mount, name), 0.0)
                self.register_variable(Real(port(mount, name), causality=Fmi2Causality.output,
                                            description=f"bushing {mount}: {name} of I relative to J, J axes [{unit}]"))
        for name, unit, meaning in BODY_OUTPUTS:
            setattr(self, name, 0.0)
            self.register_variable(Real(name, causality=Fmi2Causality.output, description=f"{meaning} [{unit}]"))
        self._mounts = mount_geometry()
        self._position = np.zeros(3)        # m, centre of mass, world
        self._orientation = np.eye(3)       # body axes -> world axes
        self._momentum = np.zeros(3)        # N.s
        self._angular_momentum = np.zeros(3)   # N.m.s about the centre of mass, world axes

    # -- state ---------------------------------------------------------------------------
    def _inertia(self) -> np.ndarray:
        return inertia_tensor(self.Ixx, self.Iyy, self.Izz, self.Ixy, self.Ixz, self.Iyz)

    def _angular_velocity(self, orientation, angular_momentum) -> np.ndarray:
        return orientation @ np.linalg.solve(self._inertia(), orientation.T @ angular_momentum)

    def _base(self, t):
        return base_motion(t, self.road_amplitude, self.road_frequency, self.pitch_amplitude,
                           self.pitch_frequency, self.fade_time)

    def _valid(self) -> bool:
        inertia_ok = np.all(np.linalg.eigvalsh(self._inertia()) > 0)
        if self.mass > 0 and inertia_ok and self.fade_time > 0:
            return True
        self.log(f"mass = {self.mass} kg must be > 0, the inertia tensor [kg.m2] positive definite, and "
                 f"fade_time = {self.fade_time} s > 0", Fmi2Status.error, "logStatusError")
        return False

    def exit_initialization_mode(self):
        self._position = np.zeros(3)
        self._orientation = np.eye(3)
        self._momentum = self.mass * np.array([self.v0_x, self.v0_y, self.v0_z])
        self._angular_momentum = self._inertia() @ np.array([self.w0_x, self.w0_y, self.w0_z])
        if self._valid():
            self._write_outputs(0.0)

    # -- the step ------------------------------------------------------------------------
    def do_step(self, current_time, step_size):
        if not (self._valid() and step_size > 0):
            return False
        h = step_size
        base_pitch = self._base(current_time)[2]
        base_rotation = pitch_matrix(base_pitch)
        force, torque = np.zeros(3), np.zeros(3)
        for mount, (position, axes) in self._mounts.items():
            R_J = base_rotation @ axes
            F = np.array([getattr(self, port(mount, n)) for n in BUSHING_OUTPUTS[:3]])
            M = np.array([getattr(self, port(mount, n)) for n in BUSHING_OUTPUTS[3:]])
            f = -R_J @ F                              # body I receives -F at I ...
            force += f
            torque += np.cross(self._orientation @ position, f) - R_J @ M   # ... and -M
        # semi-implicit (symplectic) Euler: the impulse first, then the motion with the new
        # momenta. (Moving exactly for the held force, p += h*v + h^2/2*a, grows every
        # oscillation by sqrt(1 + (w*h)^2/2) per step: unstable.)
        self._momentum = self._momentum + h * force
        self._angular_momentum = self._angular_momentum + h * torque
        self._position = self._position + h * self._momentum / self.mass
        R = self._orientation
        dt = h / ROTATION_SUBSTEPS
        for _ in range(ROTATION_SUBSTEPS):
            half = exp_so3(0.5 * dt * self._angular_velocity(R, self._angular_momentum)) @ R
            R = exp_so3(dt * self._angular_velocity(half, self._angular_momentum)) @ R
        self._orientation = R
        if not (np.all(np.isfinite(self._momentum)) and np.all(np.isfinite(R))):
            self.log(f"the body's motion is not finite at t = {current_time + h} s", Fmi2Status.error,
                     "logStatusError")
            return False
        self._write_outputs(current_time + h)
        return True

    def _write_outputs(self, t):
        base_z, base_dz, base_pitch, base_dpitch = self._base(t)
        base_rotation = pitch_matrix(base_pitch)
        base_origin, base_velocity = np.array([0.0, 0.0, base_z]), np.array([0.0, 0.0, base_dz])
        base_omega = np.array([0.0, base_dpitch, 0.0])
        R = self._orientation
        velocity = self._momentum / self.mass
        omega = self._angular_velocity(R, self._angular_momentum)
        for mount, (position, axes) in self._mounts.items():
            R_J = base_rotation @ axes
            p_J = base_origin + base_rotation @ position
            v_J = base_velocity + np.cross(base_omega, base_rotation @ position)
            lever = R @ position
            p_I = self._position + lever
            v_I = velocity + np.cross(omega, lever)
            gap = p_I - p_J
            values = np.concatenate([
                R_J.T @ gap,
                Rotation.from_matrix(R_J.T @ R @ axes).as_rotvec(),
                R_J.T @ (v_I - v_J - np.cross(base_omega, gap)),
                R_J.T @ (omega - base_omega)])
            for name, value in zip(BUSHING_INPUTS, values):
                setattr(self, port(mount, name), float(value))
        rotation_vector = Rotation.from_matrix(R).as_rotvec()
        for names, values in ((("x", "y", "z"), self._position), (("rot_x", "rot_y", "rot_z"), rotation_vector),
                              (("omega_x", "omega_y", "omega_z"), omega), (("Px", "Py", "Pz"), self._momentum),
                              (("Hx", "Hy", "Hz"), self._angular_momentum)):
            for name, value in zip(names, values):
                setattr(self, name, float(value))
        self.base_z, self.base_pitch = base_z, base_pitch
