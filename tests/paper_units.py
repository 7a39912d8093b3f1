"""The parameters' units, written out here from the equations (not read from the model
definitions under test), in the paper's N-mm-s system.

Springs k [N/mm] and dashpots c [N.s/mm] by F = k*x + c*v; the Bouc-Wen variable z is a force
[N], so in dz/dt = A*dx/dt - beta*|dx/dt|*|z|^(n-1)*z - gamma*dx/dt*|z|^n the gain A is N/mm and
beta, gamma are N^(1-n)/mm; n and the weights alpha (F = alpha*z + ...) are dimensionless;
Spencer's x0 is a length [mm]; the Kelvin-Voigt preload is a force [N]; the hydraulic mount's
fluid column has a mass [N.s^2/mm] and a turbulent damping [N.s^2/mm^2] (in the mount's coordinates).
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
    # F = c0*v + k0*x + z with z = A*D(e) and de/dt = v*(1 - (|z|/Z)^n): A turns a deflection in mm
    # into N (N/mm); the yields zp, zn are forces; (|z|/Z)^n and the breakaway factor 1 + eps*q are
    # pure numbers; the play gap, its width and the breakaway's travel delta are lengths
    "asymmetric_bouc_wen": {"c0": "N.s/mm", "k0": "N/mm", "A": "N/mm", "zp": "N", "zn": "N", "n": "1", "gap": "mm",
                            "width": "mm", "eps": "1", "delta": "mm"},
    # F = k0*x + k3*x^3 + F_f(x; Ff_max, x2) + ...: k3*x^3 is a force with x in mm; the friction's
    # limit is a force and x2 a travel; Maxwell elements k*(x - q), dq/dt = k*(x - q)/c;
    # b*D^alpha x is a force with D^alpha x in mm/s^alpha
    "berg": {"k0": "N/mm", "k3": "N/mm^3", "Ff_max": "N", "x2": "mm", "k1": "N/mm", "c1": "N.s/mm", "k2": "N/mm",
             "c2": "N.s/mm"},
    "fractional": {"k0": "N/mm", "k3": "N/mm^3", "Ff_max": "N", "x2": "mm", "b": "N.s^alpha/mm", "alpha": "1"},
    # F = k0*x + c0*dx/dt + f1 + kb*(x - y - u) and P = kb*(x - y) - kc*y are forces with x, y, u
    # in mm: k0, kb, kc are N/mm, c0 (times mm/s) N.s/mm; df1/dt = k1*dx/dt - (k1/c1)*f1 makes k1
    # N/mm and k1/c1 a rate [1/s], so c1 N.s/mm; mf*dw/dt = dp - cf*w - ct*|w|*w is a force with
    # w in mm/s and dw/dt in mm/s^2: cf N.s/mm, mf N.s^2/mm, ct N.s^2/mm^2; u = gap*tanh(...) is a
    # travel, so gap is mm; kd*u is the membrane's force against P, so kd is N/mm
    "hydraulic": {"k0": "N/mm", "c0": "N.s/mm", "k1": "N/mm", "c1": "N.s/mm", "kb": "N/mm", "kc": "N/mm",
                  "mf": "N.s^2/mm", "cf": "N.s/mm", "ct": "N.s^2/mm^2", "gap": "mm", "kd": "N/mm"},
    # the free plate's: as the hydraulic mount's, with k3*x^3 a force (N/mm^3); the plate's balance
    # P - (kb + kc)*u = kd*u + kcage*(|u| - gap) makes kd and kcage N/mm, gap a travel [mm]; the cage
    # engages over a travel of the plate, so the width is mm
    "hydraulic_free_decoupler": {"k0": "N/mm", "k3": "N/mm^3", "c0": "N.s/mm", "k1": "N/mm", "c1": "N.s/mm",
                                 "kb": "N/mm", "kc": "N/mm", "mf": "N.s^2/mm", "cf": "N.s/mm", "ct": "N.s^2/mm^2",
                                 "gap": "mm", "width": "mm", "kcage": "N/mm", "kd": "N/mm"},
}

MOUNTING_UNITS = {"offset": "mm", "preload": "N"}
"""Every FMU axis's mounting, F = model(x - offset) + preload: a length and a force (Kelvin-Voigt's
preload is its own parameter, the same force)."""


HOLDING_MODELS = ("asymmetric_bouc_wen", "single_bouc_wen")
"""The models whose friction element can hold a force at rest: their FMUs' axes take a held force
at the start, a force [N]."""


def fmu_parameter_units(model: str) -> dict[str, str]:
    """The parameters an FMU of ``model`` declares: the model's, then its mounting's (and the held
    force at rest of a model that can hold one)."""
    return {**PARAMETER_UNITS[model], **MOUNTING_UNITS, **({"held_force": "N"} if model in HOLDING_MODELS else {})}
