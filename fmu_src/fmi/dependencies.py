"""Which of an axis's unknowns depend on which of its knowns: the ``<ModelStructure>``
dependencies of a native FMU, read off the kernels' source by the tangent generator's activity
analysis (``tangents.Generator``), so that they are exact for every model and a new model gets
them too.

A dependency is listed where the kernel's value can change with the known (structurally: some
assignment path carries it), so a host seeding its Jacobian from the list misses nothing; where no
path exists the entry is structurally zero and is left out. The kind is ``dependent`` throughout:
the kernels are nonlinear in their states and inputs in general, and FMI's ``constant`` (a
constant factor) is not claimed for the linear ones.

Knowns, by kernel argument: the state's elements (model exchange), the displacement x and the
velocity v. In co-simulation the output is ``force(jump(state, x - state_x), x, v)`` (the committed
state taken through the displacement jump to x, ``bw_output`` in the C), so it depends on x also
through every state element the jump moves.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..model.definition import BushingModel
from ..kernels.tangents import Generator, is_active

X = "x"
V = "v"


@dataclass(frozen=True)
class AxisDependencies:
    """One model's dependencies: kernel state indices, and X / V for the inputs."""
    output: frozenset              # model exchange: F on states and inputs
    rates: tuple                   # model exchange: d(state i)/dt on states and inputs, by state index
    cosimulation_output: frozenset  # co-simulation: F on the inputs (through the jump for x)


def _activities(states: int, known) -> tuple:
    """The activities (m, state, x, v) with one known active."""
    return (False, tuple(known == i for i in range(states)), known == X, known == V)


def _elements(activity, count: int) -> list[bool]:
    if isinstance(activity, tuple):
        return [is_active(a) for a in activity]
    return [bool(activity)] * count


def axis_dependencies(model: BushingModel) -> AxisDependencies:
    """``model``'s dependencies (raises ``tangents.TangentError`` where a kernel cannot be analysed)."""
    states = len(model.states)
    generator = Generator()
    knowns = list(range(states)) + [X, V]
    output, rates = set(), [set() for _ in range(states)]
    for known in knowns:
        activities = _activities(states, known)
        if is_active(generator.spec(model.force, activities).return_activity):
            output.add(known)
        if states:
            for i, active in enumerate(_elements(generator.spec(model.derivatives, activities).return_activity,
                                                 states)):
                if active:
                    rates[i].add(known)
    jumped = generator.spec(model.jump, (False, (False,) * states, True)).return_activity
    moved = _elements(jumped[0] if isinstance(jumped, tuple) else jumped, states)
    cosimulation = {known for known in (X, V) if known in output}
    if any(moved[i] and i in output for i in range(states)):
        cosimulation.add(X)
    return AxisDependencies(frozenset(output), tuple(frozenset(r) for r in rates), frozenset(cosimulation))


@dataclass(frozen=True)
class GroupDependencies:
    """A coupled group's dependencies (``definition.CoupledKernels``): knowns are its flat
    state's indices, (X, c) and (V, c) for component c of the inputs; per output component and per
    rate of the flat state."""
    output: tuple                  # model exchange: F[c] on states and inputs
    rates: tuple                   # model exchange: d(state i)/dt
    cosimulation_output: tuple     # co-simulation: F[c] on the inputs (through the jump for x)


def group_dependencies(model: BushingModel) -> GroupDependencies:
    """``model``'s coupled form's dependencies, by the same activity analysis as one axis's."""
    kernels = model.coupled
    states = kernels.size
    generator = Generator()
    knowns = list(range(states)) + [(X, c) for c in range(3)] + [(V, c) for c in range(3)]
    output, rates = [set() for _ in range(3)], [set() for _ in range(states)]

    def activity(known):
        vector = lambda kind: tuple(known == (kind, c) for c in range(3))   # noqa: E731
        return (False, tuple(known == i for i in range(states)), vector(X), vector(V))

    for known in knowns:
        activities = activity(known)
        for c, active in enumerate(_elements(generator.spec(kernels.force, activities).return_activity, 3)):
            if active:
                output[c].add(known)
        for i, active in enumerate(_elements(generator.spec(kernels.derivatives, activities).return_activity,
                                             states)):
            if active:
                rates[i].add(known)
    cosimulation = []
    for c in range(3):
        found = {known for known in knowns if not isinstance(known, int) and known in output[c]}
        for j in range(3):   # the jump along component j moves the state the force reads
            jumped = generator.spec(kernels.jump, (False, (False,) * states, tuple(k == j for k in range(3))))
            moved = _elements(jumped.return_activity[0] if isinstance(jumped.return_activity, tuple)
                              else jumped.return_activity, states)
            if any(moved[i] and i in output[c] for i in range(states)):
                found.add((X, j))
        cosimulation.append(frozenset(found))
    return GroupDependencies(tuple(frozenset(o) for o in output), tuple(frozenset(r) for r in rates),
                             tuple(cosimulation))
