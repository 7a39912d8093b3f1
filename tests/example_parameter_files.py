"""Parameter files that tests in several folders build FMUs from: the illustrative six axes with
coupled groups (``six_axis_file``) and a derived model with every option (``derived_parameter_file``).
Units: the paper's N-mm-s (N.mm and rad on the rotational axes)."""
from __future__ import annotations

import copy
import json
from pathlib import Path

from conftest import DATA
from fmu_src.model.registry import get_model
from fmu_src.parameter_files import read_parameter_set, save_parameters

SIX_AXIS_DEFAULT = DATA / "params_six_axis_illustrative.json"
ROTATIONAL_BERG = {"k0": 3e5, "k3": 1e6, "Ff_max": 2e3, "x2": 0.004, "k1": 1e5, "c1": 1e4, "k2": 5e4, "c2": 100.0}
"""Berg on a rotational axis [N.mm, rad]."""
LIMITS = dict(limit_gap_pos=1.0, limit_gap_neg=0.5, limit_k_pos=300.0, limit_k_neg=500.0, limit_exponent_pos=2.0,
              limit_exponent_neg=1.5, limit_c_pos=2.0, limit_c_neg=1.0, limit_depth_pos=0.3, limit_depth_neg=0.2,
              limit_width=0.05)
BACKBONE = dict(backbone_x1=-3.0, backbone_x2=-1.0, backbone_x3=0.5, backbone_x4=3.0,
                backbone_F1=-900.0, backbone_F2=-200.0, backbone_F3=50.0, backbone_F4=1200.0)


def defaults(name: str) -> dict[str, float]:
    """The model's default parameter set (its file under data/)."""
    return dict(read_parameter_set(DATA / get_model(name).default_file, name).parameters)


def six_axis_file(tmp_path, coupling, **changes):
    """The illustrative six axes with x's set on y and z, Berg on rx and ry, and ``coupling``;
    ``changes``: AXIS__NAME=value."""
    document = json.loads(SIX_AXIS_DEFAULT.read_text())
    for axis in ("y", "z"):
        document["axes"][axis] = copy.deepcopy(document["axes"]["x"])
    for axis in ("rx", "ry"):
        document["axes"][axis] = {"model": "BergBushing", "parameters": dict(ROTATIONAL_BERG)}
    document["coupling"] = coupling
    for key, value in changes.items():
        axis, name = key.split("__")
        document["axes"][axis]["parameters"][name] = value
    path = tmp_path / f"six_{abs(hash(json.dumps(coupling, sort_keys=True)))}.json"
    path.write_text(json.dumps(document))
    return path


def derived_parameter_file(folder) -> Path:
    """``folder/params.json``: single_bouc_wen with a backbone, travel limits and a Maxwell element."""
    params = {name: value for name, value in defaults("single_bouc_wen").items() if name != "k0"}
    params.update({k: v for k, v in BACKBONE.items()}, **LIMITS, maxwell_k=200.0, maxwell_c=2.0)
    return save_parameters(Path(folder) / "params.json", params, "single_bouc_wen+backbone4+limits+maxwell")
