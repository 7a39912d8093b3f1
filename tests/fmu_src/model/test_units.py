"""Units read from their names (fmu_src/model/units.py): the SI form FMI and SSP declare and the
form on a rotational axis, against the table the project kept by hand until units were derived
(typed here as it stood), and a name it cannot read refused."""
import pytest

from fmu_src.model.parameter_specs import ParameterSpec
from fmu_src.model.registry import MODELS
from fmu_src.model.units import UnitError, rotational, si_form

SI_FORMS = {
    "m": {"m": "1"}, "s": {"s": "1"}, "m/s": {"m": "1", "s": "-1"}, "N": {"kg": "1", "m": "1", "s": "-2"},
    "N/mm": {"kg": "1", "s": "-2", "factor": "1000"}, "N.s/mm": {"kg": "1", "s": "-1", "factor": "1000"},
    "1": {}, "N^(1-n1)/mm": None, "N^(1-n2)/mm": None, "mm": {"m": "1", "factor": "0.001"}, "N^(1-n)/mm": None,
    "N/mm^3": {"kg": "1", "m": "-2", "s": "-2", "factor": "1000000000"}, "N.s^alpha/mm": None,
    "rad": {"rad": "1"}, "rad/s": {"rad": "1", "s": "-1"}, "N.m": {"kg": "1", "m": "2", "s": "-2"},
    "N.mm": {"kg": "1", "m": "2", "s": "-2", "factor": "0.001"},
    "N.mm/rad": {"kg": "1", "m": "2", "s": "-2", "rad": "-1", "factor": "0.001"},
    "N.mm.s/rad": {"kg": "1", "m": "2", "s": "-1", "rad": "-1", "factor": "0.001"},
    "N/s": {"kg": "1", "m": "1", "s": "-3"}, "1/s": {"s": "-1"}, "N.m/s": {"kg": "1", "m": "2", "s": "-3"},
    "m2/s": {"m": "2", "s": "-1"}, "rad2/s": {"rad": "2", "s": "-1"},
    "N.mm/rad^3": {"kg": "1", "m": "2", "s": "-2", "rad": "-3", "factor": "0.001"}, "N.mm.s^alpha/rad": None,
    "(N.mm)^(1-n)/rad": None, "(N.mm)^(1-n1)/rad": None, "(N.mm)^(1-n2)/rad": None,
    "N.s^2/mm": {"kg": "1", "factor": "1000"}, "N.s^2/mm^2": {"kg": "1", "m": "-1", "factor": "1000000"},
    "m/s/s": {"m": "1", "s": "-2"}, "N.mm.s^2/rad": {"kg": "1", "m": "2", "rad": "-1", "factor": "0.001"},
    "N.mm.s^2/rad^2": {"kg": "1", "m": "2", "rad": "-2", "factor": "0.001"}, "rad/s/s": {"rad": "1", "s": "-2"},
}
"""Every unit the FMUs declared, with its SI form as FMI writes it (value_SI = factor * value)."""
ROTATIONAL = {
    "N/mm": "N.mm/rad", "N.s/mm": "N.mm.s/rad", "mm": "rad", "N": "N.mm", "1": "1",
    "N^(1-n)/mm": "(N.mm)^(1-n)/rad", "N^(1-n1)/mm": "(N.mm)^(1-n1)/rad", "N^(1-n2)/mm": "(N.mm)^(1-n2)/rad",
    "N/mm^3": "N.mm/rad^3", "N.s^alpha/mm": "N.mm.s^alpha/rad", "N.s^2/mm": "N.mm.s^2/rad",
    "N.s^2/mm^2": "N.mm.s^2/rad^2",
}
"""A translational parameter's unit -> its unit on a rotational axis (rad for mm, N.mm for N)."""


FMI_ORDER = ("kg", "m", "s", "A", "K", "mol", "cd", "rad", "factor")
"""The order of a BaseUnit's attributes in FMI's schema."""


@pytest.mark.parametrize("unit", SI_FORMS)
def test_the_si_form_is_read_from_the_name_in_fmis_order(unit):
    form = si_form(unit)
    assert form == SI_FORMS[unit]
    if form is not None:
        assert list(form) == [name for name in FMI_ORDER if name in form]


@pytest.mark.parametrize("unit", ROTATIONAL)
def test_a_rotational_axis_reads_rad_for_mm_and_gives_n_mm_for_n(unit):
    assert rotational(unit) == ROTATIONAL[unit]


def test_every_models_units_are_read_on_both_kinds_of_axis():
    for model in MODELS.values():
        for spec in model.specs:
            si_form(spec.unit), si_form(rotational(spec.unit))


def test_a_frequency_and_the_example_bodys_units_are_read():
    assert si_form("Hz") == {"s": "-1"} and si_form("kg.m2") == {"kg": "1", "m": "2"}
    assert si_form("N.m.s") == {"kg": "1", "m": "2", "s": "-1"}


@pytest.mark.parametrize("unit", ["N/inch", "N/mm.s", "N^2.5", "kN", ""])
def test_a_unit_it_cannot_read_is_refused_with_the_parameter_named(unit):
    with pytest.raises(UnitError, match=r"^parameter k: unit .* is not one of|^parameter k: unit .*write a product"):
        ParameterSpec("k", unit, "stiffness")
