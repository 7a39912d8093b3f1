"""A model resolved once: it crosses to another process by its name, and the inner functions take
the model, not a name to resolve again."""
import dataclasses
import pickle
import subprocess
import sys

import numpy as np
import pytest

from conftest import REPO
from fmu_src.model.registry import MODELS, get_model
from identification.forward.population import parameter_matrix, simulate_population_held


@pytest.mark.parametrize("name", ["proposed", "kelvin_voigt", "asymmetric_bouc_wen+band+rig"])
def test_a_model_pickles_as_its_name_and_loads_as_the_registered_one(name):
    model = get_model(name)
    assert pickle.loads(pickle.dumps(model)) is model
    assert name.encode() in pickle.dumps(model)


def test_a_derived_model_arrives_in_a_fresh_process_under_its_name():
    # the process that loads it has never made the model: get_model derives it from the name
    payload = pickle.dumps(get_model("berg+limits+rig"))
    script = ("import pickle, sys; model = pickle.loads(sys.stdin.buffer.read()); "
              "print(model.name, len(model.specs))")
    done = subprocess.run([sys.executable, "-c", script], input=payload, capture_output=True, cwd=REPO, check=True)
    assert done.stdout.decode().split() == ["berg+limits+rig", str(len(get_model("berg+limits+rig").specs))]


def test_a_model_that_is_not_the_registered_one_of_its_name_refuses_to_pickle():
    changed = dataclasses.replace(MODELS["spencer"], title="another Spencer")
    with pytest.raises(pickle.PicklingError, match="not the registered model"):
        pickle.dumps(changed)


def test_an_inner_function_given_a_name_says_to_give_the_model():
    t = np.linspace(0.0, 0.01, 11)
    with pytest.raises(TypeError, match=r"get_model\('spencer'\)"):
        simulate_population_held(np.ones((1, len(MODELS["spencer"].specs))), t, t, t, model="spencer")
    with pytest.raises(TypeError, match="not its name"):
        parameter_matrix([{"k": 1.0, "c": 1.0}], "kelvin_voigt")
