"""The directional derivatives of a native FMU whose model has a compliance in series (``series``):
model exchange's Jacobian (the device's velocity solved from the spring) and co-simulation's dF/dx,
dF/dv (through the step's iteration over the device's velocity) against differences of the FMU's
own values, as ``test_fmu_directional_derivatives`` checks every model's."""
import shutil

import pytest

import test_fmu_directional_derivatives as derivatives
from fmu_src.model.registry import get_model
from fmu_src.parameter_files import save_parameters
from example_parameter_files import defaults


@pytest.fixture(scope="module")
def series_fmus(tmp_path_factory):
    """The native FMUs (FMI 2 and 3) of the single Bouc-Wen model with a Maxwell element in series
    with a compliance of 1e-3 mm/N."""
    import build_fmu
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    folder = tmp_path_factory.mktemp("series_fmus")
    model = get_model("single_bouc_wen+maxwell+series")
    params = dict(defaults("single_bouc_wen"), maxwell_k=50.0, maxwell_c=1.0, series_compliance=1e-3)
    file = save_parameters(folder / "series.json", params, model.name)
    return {version: {"series": build_fmu.build_native_fmu(file, folder / str(version), model=model.name,
                                                           fmi_version=version).path} for version in (2, 3)}


@pytest.mark.parametrize("version", [2, 3])
def test_model_exchange_directional_derivatives_equal_central_differences(series_fmus, version):
    derivatives.test_model_exchange_jacobian_equals_central_differences(series_fmus, "series", version)


@pytest.mark.parametrize("version", [2, 3])
def test_co_simulation_dF_dx_dF_dv_are_those_of_the_output(series_fmus, version):
    derivatives.test_co_simulation_dF_dx_dF_dv_are_those_of_the_output_the_fmu_returns(series_fmus, "series", version)


def test_in_model_exchange_a_device_without_a_dashpot_is_an_error_naming_the_rate(tmp_path):
    # a Kelvin-Voigt device of c = 0 on a spring: its force does not grow with its velocity, so the
    # spring's force gives the device no rate (an index-2 system): an error status, never a NaN
    import ctypes

    import build_fmu
    from fmpy.fmi1 import FMICallException
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler for the native FMU")
    model = get_model("kelvin_voigt+series")
    file = save_parameters(tmp_path / "series.json", dict(k=200.0, c=0.0, preload=0.0, series_compliance=2e-3),
                           model.name)
    opened = derivatives.Opened(build_fmu.build_native_fmu(file, tmp_path, model=model.name).path, "me")
    opened.set_inputs([1e-3, 0.01])
    rates = (ctypes.c_double * len(opened.states))()
    with pytest.raises(FMICallException):
        opened.fmu.getDerivatives(rates, len(opened.states))
    assert any("not finite" in message for message in opened.messages), opened.messages
    opened.free()
