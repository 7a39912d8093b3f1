"""Identification of the bushing models' parameters from rig tests.

The front door::

    from identification import fit, simulate, predict, load_measurement

    tests = training_tests(sine=["sine.csv"], step=["step.csv"], rise_times_s=[0.4])
    result = fit(tests, model="proposed", seed=0)          # FitResult
    print(result.summary())                                 # noise, NRMSE, agreement, identifiability
    result.save("params.json", ensemble="ensemble.json")   # what build_fmu.py --params takes
    force_N = simulate(result.parameters, time_s, displacement_mm)
    band = predict(result, time_s, displacement_mm)         # best force and the ensemble's envelope
    table = characterise(result, [0.5, 1, 2], [1, 10, 30])  # dynamic stiffness and loss angle per case

Units: s, mm, mm/s, N; parameters in the paper's N-mm-s units. With ``workers`` > 1 the fit
starts worker processes: guard a script's top level with ``if __name__ == "__main__":``.
"""
from identification.dynamic_stiffness import characterise
from identification.fitting import FitNotConvergedWarning, FitResult, fit
from identification.measurements import load_measurement
from identification.predict import predict
from identification.rig_tests import RigTest, load_manifest, training_tests
from identification.simulate import simulate

__all__ = ["fit", "FitResult", "FitNotConvergedWarning", "simulate", "predict", "characterise", "load_measurement",
           "RigTest", "training_tests", "load_manifest"]
