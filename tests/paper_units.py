"""The parameters' units, written out here from the equations (not read from the model
definitions under test), in the paper's N-mm-s system.

Springs k [N/mm] and dashpots c [N.s/mm] by F = k*x + c*v; the Bouc-Wen variable z is a force
[N], so in dz/dt = A*dx/dt - beta*|dx/dt|*|z|^(n-1)*z - gamma*dx/dt*|z|^n the gain A is N/mm and
beta, gamma are N^(1-n)/mm; n and the weights alpha (F = alpha*z + ...) are dimensionless;
Spencer's x0 is a length [mm]; the Kelvin-Voigt preload is a force [N].
"""
_BLOCK = {"A{}": "N/mm", "beta{}": "N^(1-n{})/mm", "gamma{}": "N^(1-n{})/mm", "n{}": "1", "alpha{}": "1"}


def _block(suffix: str) -> dict[str, str]:
    return {name.format(suffix): unit.format(suffix) for name, unit in _BLOCK.items()}


PARAMETER_UNITS = {
    "proposed": {"c0": "N.s/mm", "k0": "N/mm", "c1": "N.s/mm", "k1": "N/mm", "c2": "N.s/mm", "k2": "N/mm",
                 **_block("1"), **_block("2")},
    "spencer": {"c0": "N.s/mm", "k0": "N/mm", "c1": "N.s/mm", "k1": "N/mm", "x0": "mm", **_block("")},
    "single_bouc_wen": {"c0": "N.s/mm", "k0": "N/mm", **_block("")},
    "kelvin_voigt": {"k": "N/mm", "c": "N.s/mm", "preload": "N"},
    # F = k0*x + k3*x^3 + F_f(x; Ff_max, x2) + ...: k3*x^3 is a force with x in mm; the friction's
    # limit is a force and x2 a travel; Maxwell elements k*(x - q), dq/dt = k*(x - q)/c;
    # b*D^alpha x is a force with D^alpha x in mm/s^alpha
    "berg": {"k0": "N/mm", "k3": "N/mm^3", "Ff_max": "N", "x2": "mm", "k1": "N/mm", "c1": "N.s/mm", "k2": "N/mm",
             "c2": "N.s/mm"},
    "fractional": {"k0": "N/mm", "k3": "N/mm^3", "Ff_max": "N", "x2": "mm", "b": "N.s^alpha/mm", "alpha": "1"},
}

MOUNTING_UNITS = {"offset": "mm", "preload": "N"}
"""Every FMU axis's mounting, F = model(x - offset) + preload: a length and a force (Kelvin-Voigt's
preload is its own parameter, the same force)."""


def fmu_parameter_units(model: str) -> dict[str, str]:
    """The parameters an FMU of ``model`` declares: the model's, then its mounting's."""
    return {**PARAMETER_UNITS[model], **MOUNTING_UNITS}
