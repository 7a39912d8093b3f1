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
model's name or the model itself (a ``BushingModel``, ``fmu_src.bushing_models.get_model``):
resolved once at the front door, the model object is what the modules below pass on.

The modules, in the order of the workflow:

- reading the tests: ``measurements`` (CSV files), ``rig_tests`` (which file is which test, the
  manifest), ``multiaxis`` (tests along two or three axes at once, and their coupling), ``kdyn_table`` (the dynamic-stiffness table's CSV file, read and written), ``noise`` (each test's noise
  level), ``protocols`` (the paper's test signals);
- the forward model: ``simulate`` (the front door), ``parameter_input`` (what counts as
  parameters), ``forward_model`` (the input between samples), ``compiled_core`` and
  ``steady_state`` (the models' kernels, compiled per model), ``refinement`` (finer steps where
  needed) and ``fit_jacobian`` (the forces' sensitivities to the parameters, computed with them);
- fitting: ``fitting`` (``fit``), ``fit_result`` (what it returns), ``presets``, ``search_space``
  (the box), ``loop_start`` (starts from a slow loop), ``table_start`` (starts from a data sheet),
  ``objectives`` (the misfit), ``multistart``
  (screening and least-squares stages),
  ``ensemble`` (how sure), ``engine`` (where tasks run), ``progress``, ``fleet`` (many bushings);
- analysis: ``predict`` (force and band), ``fmu_input`` (a measurement as an FMU's input), ``dynamic_stiffness`` (data sheet), ``design`` (the next
  test), ``sensitivity``, ``report`` (the paper's §5 tables), ``compare`` (fit every model, recommend one),
  ``six_axis`` (one file from six fits), ``plots``;
- the command line: ``cli`` (arguments), ``commands`` (what each does), ``interrupt`` (Ctrl-C and
  SIGTERM: one line, exit 130/143, outputs whole or untouched), ``extras``, ``errors`` (every error
  and warning type).
"""
from identification.interrupt import exit_quietly_on_early_ctrl_c

exit_quietly_on_early_ctrl_c()   # first: before the imports below take their second or two

from fmu_src.bushing_params import ParameterError  # noqa: E402
from fmu_src.parameter_files import (ParameterEnsemble, ParameterSet, read_ensemble, read_parameter_set,  # noqa: E402
                                     save_ensemble, save_parameters)
from identification.dynamic_stiffness import characterise  # noqa: E402
from identification.errors import FitNotConvergedWarning, IdentificationError, MeasurementError, MissingExtraError  # noqa: E402
from identification.fit_result import FitResult  # noqa: E402
from identification.fitting import fit  # noqa: E402
from identification.fmu_input import fmu_input, simulate_measurement  # noqa: E402
from identification.measurements import load_measurement  # noqa: E402
from identification.predict import predict  # noqa: E402
from identification.rig_tests import RigTest, load_manifest, training_tests  # noqa: E402
from identification.simulate import simulate  # noqa: E402

__all__ = ["fit", "FitResult", "FitNotConvergedWarning", "simulate", "predict", "characterise", "load_measurement",
           "fmu_input", "simulate_measurement",
           "RigTest", "training_tests", "load_manifest",
           "read_parameter_set", "save_parameters", "read_ensemble", "save_ensemble", "ParameterSet", "ParameterEnsemble",
           "IdentificationError", "MeasurementError", "ParameterError", "MissingExtraError"]
