"""Identification of the bushing models' parameters from rig tests.

The front door (run from the repository, whose data/ holds synthetic Table 5 tests; a fit takes
about a minute on two cores)::

    import numpy as np
    from identification import characterise, fit, predict, simulate, training_tests

    if __name__ == "__main__":
        tests = training_tests(sine=["data/synthetic_table5_sine_2mm_10Hz.csv"],
                               step=["data/synthetic_table5_step_2mm_rise0.4s.csv"], rise_times_s=[0.4])
        result = fit(tests, model="proposed", seed=0)          # FitResult
        print(result.summary())                                 # noise, NRMSE, agreement, identifiability
        result.save("params.json", ensemble="ensemble.json")   # what build_fmu.py --params takes
        time_s = np.arange(0.0, 1.0, 1e-3)
        displacement_mm = 3.0 * np.sin(2 * np.pi * 5.0 * time_s)
        force_N = simulate(result, time_s, displacement_mm)    # the best set
        band = predict(result, time_s, displacement_mm)         # best force and the ensemble's envelope
        table = characterise(result, [0.5, 1, 2], [1, 10, 30])  # dynamic stiffness and loss angle per case
        print(table.format())

Units: s, mm, mm/s, N; parameters in the paper's N-mm-s units. With ``workers`` > 1 the fit
starts worker processes: guard a script's top level with ``if __name__ == "__main__":``.

A ``model`` (``fit``, ``simulate``, ``predict``, ``characterise``, ``compare.compare_models``) is a
model's name or the model itself (a ``BushingModel``, ``fmu_src.model.registry.get_model``):
resolved once at the front door, the model object is what the modules below pass on.

The subpackages, in the order of the workflow (each ``__init__`` names its modules and what
they may import):

- ``measured``: the measured data (one-axis and multi-axis CSV tests, the rig tests and their
  manifest, data-sheet tables, noise levels, the paper's test signals);
- ``forward``: the forward model (``simulate``, the input path, the compiled population loop,
  the sine loop, ``characterise``, the forces' derivatives);
- ``fitting``: ``fit`` and what it returns, the search box, starts, objective, multistart,
  ensemble, where tasks run, progress, fleets;
- ``analysis``: predictions and their bands, the next test, sensitivities, ``compare``, the
  paper's verification tables, plots;
- ``property_files``: other tools' bushing property files read into parameter sets (Chrono's
  vehicle JSON);
- ``cli``: the command line.

Beside them, what every subpackage may use: ``errors`` (every error and warning type),
``extras`` (the one-line error that names a missing extra) and ``interrupt`` (Ctrl-C and
SIGTERM: one line, exit 130/143, outputs whole or untouched).
"""
from identification.interrupt import exit_quietly_on_early_ctrl_c

exit_quietly_on_early_ctrl_c()   # first: before the imports below take their second or two

from fmu_src.model.parameter_specs import ParameterError  # noqa: E402
from fmu_src.parameter_files import (ParameterEnsemble, ParameterSet, read_ensemble, read_parameter_set,  # noqa: E402
                                     save_ensemble, save_parameters)
from identification.forward.dynamic_stiffness import characterise  # noqa: E402
from identification.errors import FitNotConvergedWarning, IdentificationError, MeasurementError, MissingExtraError  # noqa: E402
from identification.fitting.result import FitResult  # noqa: E402
from identification.fitting.fit import fit  # noqa: E402
from identification.fitting.presets import FitOptions  # noqa: E402
from identification.analysis.fmu_input import fmu_input, simulate_measurement  # noqa: E402
from identification.measured.measurements import load_measurement  # noqa: E402
from identification.analysis.predict import predict  # noqa: E402
from identification.measured.rig_tests import RigTest, load_manifest, training_tests  # noqa: E402
from identification.forward.simulate import simulate  # noqa: E402

__all__ = ["fit", "FitOptions", "FitResult", "FitNotConvergedWarning", "simulate", "predict", "characterise", "load_measurement",
           "fmu_input", "simulate_measurement",
           "RigTest", "training_tests", "load_manifest",
           "read_parameter_set", "save_parameters", "read_ensemble", "save_ensemble", "ParameterSet", "ParameterEnsemble",
           "IdentificationError", "MeasurementError", "ParameterError", "MissingExtraError"]
