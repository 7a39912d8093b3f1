"""pythonfmu slave: a rigid body on a shaker, the other half of the co-simulation example.

The body (mass ``mass`` [kg], vertical, about its static equilibrium: no gravity) sits on
four bushings whose base is a shaker table moving as ``u(t) = amplitude*sin(2*pi*f*t)``
(after a half-cosine fade-in over the first period). The body outputs its displacement and
velocity relative to the table, ``x_rel`` [m] and ``v_rel`` [m/s], which are every bushing's
``x`` and ``v``; it takes the four bushing forces ``F1``..``F4`` [N] (each the force the
bushing exerts on its base, so the body feels ``-F``).

Within a communication step the forces are held (the master passes them once per step), so
the body's motion over the step is exact for a constant acceleration.
"""
import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status


class RigBody(Fmi2Slave):
    author = "Bouc-Wen bushing project"
    description = "Rigid body on four bushings over a shaker table (co-simulation example)"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=1.0, step_size=1e-3)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.mass = 300.0            # kg
        self.amplitude = 0.002       # m
        self.frequency = 12.0        # Hz
        self.F1 = self.F2 = self.F3 = self.F4 = 0.0  # N
        self.z = 0.0                 # m, body displacement
        self.vz = 0.0                # m/s
        self.x_rel = 0.0             # m
        self.v_rel = 0.0             # m/s
        self.acceleration = 0.0      # m/s^2
        for name, unit, meaning in (("mass", "kg", "body mass"), ("amplitude", "m", "table amplitude"),
                                    ("frequency", "Hz", "table frequency")):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed, description=f"{meaning} [{unit}]"))
        for name in ("F1", "F2", "F3", "F4"):
            self.register_variable(Real(name, causality=Fmi2Causality.input,
                                        description="force of a bushing on its base (the body) [N]"))
        for name, meaning in (("x_rel", "body minus table displacement [m]"),
                              ("v_rel", "body minus table velocity [m/s]"),
                              ("z", "body displacement [m]"), ("vz", "body velocity [m/s]"),
                              ("acceleration", "body acceleration [m/s2]")):
            self.register_variable(Real(name, causality=Fmi2Causality.output, description=meaning))

    def _table(self, t):
        """Table displacement [m] and velocity [m/s]: a sine faded in over one period."""
        omega = 2.0 * math.pi * self.frequency
        period = 1.0 / self.frequency
        if t >= period:
            return self.amplitude * math.sin(omega * t), self.amplitude * omega * math.cos(omega * t)
        fade = 0.5 * (1.0 - math.cos(math.pi * t / period))
        dfade = 0.5 * math.pi / period * math.sin(math.pi * t / period)
        s, c = math.sin(omega * t), math.cos(omega * t)
        return self.amplitude * fade * s, self.amplitude * (dfade * s + fade * omega * c)

    def do_step(self, current_time, step_size):
        if not (self.mass > 0 and step_size > 0):
            self.log(f"mass = {self.mass} kg and step size {step_size} s must be > 0",
                     Fmi2Status.error, "logStatusError")
            return False
        self.acceleration = -(self.F1 + self.F2 + self.F3 + self.F4) / self.mass
        self.z += self.vz * step_size + 0.5 * self.acceleration * step_size ** 2
        self.vz += self.acceleration * step_size
        u, du = self._table(current_time + step_size)
        self.x_rel, self.v_rel = self.z - u, self.vz - du
        return True
