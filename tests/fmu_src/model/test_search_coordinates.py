"""The search coordinates' kinds (fmu_src/model/search_coordinates.py): each kind's map and inverse
agree, its complex-step derivative is a derivative, the order respects what each reads, and no
generic module names a model."""
import ast
import math
from pathlib import Path

import numpy as np
import pytest

from fmu_src.model.registry import ALIASES, MODELS
from fmu_src.model.definition import SearchCoordinate
from fmu_src.model.search_coordinates import KIND, evaluation_order
from identification.fitting.search_space import SearchSpace

ROOT = Path(__file__).resolve().parents[3]
SPACE = SearchSpace(1850.0, 2.7, 4400.0, 0.001, x_ref=2.0)
# what the kinds that read other parameters read, at plausible values of a proposed-model set
OTHERS = {"k1": 400.0, "k2": 50.0, "n": 0.8, "beta": 2e-3, "c1": 30.0, "mf": 0.07,
          "backbone_F3": -150.0, "backbone_x3": -1.0, "backbone_x4": 1.5}
COORDINATES = {
    "stiffness": SearchCoordinate("p", KIND.stiffness, -3.0, 1.0),
    "damping": SearchCoordinate("p", KIND.damping, -4.0, 2.0),
    "force": SearchCoordinate("p", KIND.force, -3.0, 0.5),
    "travel": SearchCoordinate("p", KIND.travel, -4.0, 0.5),
    "compliance": SearchCoordinate("p", KIND.compliance, -3.0, 1.0),
    "gain": SearchCoordinate("p", KIND.gain, -4.0, 1.0),
    "exponent": SearchCoordinate("p", KIND.exponent, 0.1, 1.5),
    "value": SearchCoordinate("p", KIND.value, 60.0, 600.0),
    "cubic": SearchCoordinate("p", KIND.cubic, 0.0, 2.0),
    "time_constant": SearchCoordinate("p", KIND.time_constant, -math.inf, 4.0, over=("k1",)),
    "slower": SearchCoordinate("p", KIND.slower, 0.0, 6.0, over=("k2",), partner="c1"),
    "shape": SearchCoordinate("p", KIND.shape, 0.0, 20.0, "n"),
    "shape_sum": SearchCoordinate("p", KIND.shape_sum, 0.0, 40.0, "n", partner="beta", sign=-1.0),
    "power_law": SearchCoordinate("p", KIND.power_law, -4.0, 3.0, exponent="n"),
    "resonance": SearchCoordinate("p", KIND.resonance, -0.5, 2.5, over=("k1", "k2")),
    "damping_ratio": SearchCoordinate("p", KIND.damping_ratio, -3.0, 0.5, over=("k1", "k2"), partner="mf"),
    "quadratic_damping": SearchCoordinate("p", KIND.quadratic_damping, -6.0, 1.0),
    "offset_force": SearchCoordinate("p", KIND.offset_force, -0.5, 0.5),
    "rig_travel": SearchCoordinate("p", KIND.rig_travel, -0.25, 0.25),
    "rig_force": SearchCoordinate("p", KIND.rig_force, -0.5, 0.5),
    # a backbone's knot 4 from its neighbour 3, 2.5 mm apart
    "segment": SearchCoordinate("p", KIND.segment, -4.0, 2.0, over=("backbone_x4", "backbone_x3"),
                                partner="backbone_F3"),
}


class Scales:
    """SearchSpace's scales, with the partner dashpot c1 over k1 for ``slower``."""
    k_ref, c_ref, F_ref, x_ref = SPACE.k_ref, SPACE.c_ref, SPACE.F_ref, SPACE.x_ref
    tau_ref, shortest_time_constant_s = SPACE.tau_ref, SPACE.shortest_time_constant_s
    x_zero, F_zero = 1.5, 120.0         # the records' centres, the rig's zeros' origin

    @staticmethod
    def time_constant(values, dashpot):
        return values[dashpot] / values["k1"]


def test_every_kind_is_covered_here():
    assert sorted(COORDINATES) == sorted(kind.name for kind in KIND)


@pytest.mark.parametrize("name", sorted(COORDINATES))
def test_each_kind_maps_back_and_forth_inside_its_bounds(name):
    c = COORDINATES[name]
    low, high = c.kind.bounds(c, Scales)
    low = max(low, -6.0)
    assert low < high
    u = np.linspace(low, high, 7)[1:-1]           # inside: away from the gain's clamp at its floor
    values = {key: np.full(u.size, value) for key, value in OTHERS.items()}
    parameter = c.kind.to_parameter(c, u, values, Scales)
    back = [c.kind.to_coordinate(c, float(p), OTHERS, Scales) for p in parameter]
    np.testing.assert_allclose(back, u, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", sorted(COORDINATES))
def test_each_kinds_complex_step_is_its_derivative(name):
    # the search differentiates every kind by complex step of its map: against a central difference
    c = COORDINATES[name]
    low, high = c.kind.bounds(c, Scales)
    u = 0.5 * (max(low, -6.0) + high)
    values = {key: np.array([value]) for key, value in OTHERS.items()}
    exact = c.kind.to_parameter(c, np.array([u + 1e-30j]), values, Scales).imag[0] / 1e-30
    h = 1e-6 * max(1.0, abs(u))
    central = (c.kind.to_parameter(c, np.array([u + h]), values, Scales)[0]
               - c.kind.to_parameter(c, np.array([u - h]), values, Scales)[0]) / (2 * h)
    assert exact == pytest.approx(central, rel=1e-7, abs=1e-12)


@pytest.mark.parametrize("model", [m for m in MODELS.values() if m.search is not None], ids=lambda m: m.name)
def test_every_model_reads_only_its_parameters_and_in_order(model):
    ordered = evaluation_order(model.search.coordinates)
    assert sorted(c.parameter for c in ordered) == sorted(c.parameter for c in model.search.coordinates)
    seen = set(model.search.unit_weights) | set(model.search.zeros)
    coordinates = {c.parameter for c in model.search.coordinates}
    for c in ordered:
        for name in c.kind.reads(c):
            assert name in model.parameter_names, (c.parameter, name)
            assert name in seen or name not in coordinates, (c.parameter, name)
        seen.add(c.parameter)


def test_the_resonance_and_damping_ratio_kinds_mean_what_they_say():
    # a mass m with stiffness k = 450 N/mm: f = sqrt(k/m)/(2*pi) (typed), and the damping ratio
    # of a dashpot c against them c/(2*sqrt(k*m))
    values = {"k1": np.array([400.0]), "k2": np.array([50.0]), "mf": np.array([0.07])}
    mass = KIND.resonance.to_parameter(COORDINATES["resonance"], np.array([1.0]), values, Scales)[0]
    assert math.sqrt(450.0 / mass) / (2.0 * math.pi) == pytest.approx(10.0, rel=1e-14)
    dashpot = KIND.damping_ratio.to_parameter(COORDINATES["damping_ratio"], np.array([math.log10(0.15)]), values,
                                              Scales)[0]
    assert dashpot / (2.0 * math.sqrt(450.0 * 0.07)) == pytest.approx(0.15, rel=1e-14)


def test_a_cycle_of_reads_is_refused_with_the_coordinates_named():
    a = SearchCoordinate("a", KIND.shape, 0.0, 1.0, "b")
    b = SearchCoordinate("b", KIND.shape, 0.0, 1.0, "a")
    with pytest.raises(ValueError, match="a, b read each other in a cycle"):
        evaluation_order((a, b))


GENERIC = [p for p in sorted((ROOT / "identification").rglob("*.py")) + sorted((ROOT / "fmu_src").rglob("*.py"))
           if not p.name.endswith("_model.py") and p.name != "registry.py"]


def _code_strings(path: Path):
    """Every string constant of a module's code, docstrings left out (prose may name a model)."""
    tree = ast.parse(path.read_text())
    docstrings = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list):
            for statement in body:
                if isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant):
                    docstrings.add(id(statement.value))
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            yield node.lineno, node.value


def test_no_generic_module_names_a_model():
    # what a model needs from the generic code is a property of its BushingModel or SearchBox;
    # the registry names the default model and the linear baseline once
    names = set(MODELS) | set(ALIASES)
    found = [f"{path.relative_to(ROOT)}:{line} {value!r}" for path in GENERIC for line, value in _code_strings(path)
             if value in names]
    assert not found, found


@pytest.mark.parametrize("name", ["stiffness", "damping", "force", "travel", "power_law", "slower"])
def test_a_subnormal_value_maps_far_below_the_box_not_to_an_error(name):
    # a slow loop's least-squares start gave Berg's friction 5e-324 N, whose ratio to a scale of
    # 150 underflows to 0: the coordinate is log10(5e-324) - log10(scale), about -325.5 (a time
    # constant over a stiffness underflows before: -inf), which the box's clip takes to its bound
    c = COORDINATES[name]
    u = c.kind.to_coordinate(c, 5e-324, dict(OTHERS, p=5e-324), Scales)
    assert u < -300.0
    if name != "slower":
        assert math.isfinite(u)
