"""Build-to-build comparison of the step's outputs: a speed change must not change them.

`dump` runs a few short cases (the twin `serve` runs at its auto step and at 1 us, the 7208 under
Fr = Fa = 3000 N, the centre-point friction laws, the 6208 at 1700 rad/s and 7500 N, the outer ring
on the housing with a spall, 5 A shaft current with inlet shear heating) from their warm starts
and saves, at the end of each run, every contact's load, Lambda, h_min, h_c, mu, RC, force,
torque, tangential spring and cached damping and relaxation constants, the state scalars (cage
speed and angle, friction torque, ...), the balls' positions and spins and the cage loads. Run it
on each build, then `compare` the two files: per array, max |a - b| over max |a|.

    PYTHONPATH=<build A> python -m twin.validation.step_compare dump /tmp/a.npz
    PYTHONPATH=<build B> python -m twin.validation.step_compare dump /tmp/b.npz
    python -m twin.validation.step_compare compare /tmp/a.npz /tmp/b.npz

A change that only reorders floating-point operations shows up as last-bit differences that
the trajectory amplifies (1e-11 after 0.05 s has been seen); a model change moves these figures
by 1e-4 or more. tests/engine/test_step_reference.py holds the same guarantee as a test against
the engine before its speed optimisation (window means, tolerance 1e-6).
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from twin import catalog
from twin.engine import Twin
from twin.kernels import layout as L
from twin.setpoint import Setpoint
from twin.spec import BearingSpec, ModelOptions
from twin.validation.vibration_simulation import defect_for

# id: (designation, time step, simulated seconds, extra setpoint / option / spec fields). Every case
# states its inlet: isothermal (seed 000's Hamrock-Dowson film, as its 6208 operating point is
# solved) except the shear-heated one, so a file dumped by one build compares with another's
# whatever the spec's default of Thermal.shear_heating.
CASES: dict[str, tuple[str, float | str, float, dict[str, Any]]] = {
    "6208-auto": ("6208", "auto", 0.1, {"shear_heating": False}),
    "6208-1us": ("6208", 1e-6, 0.05, {"shear_heating": False}),
    "7208-combined-auto": ("7208", "auto", 0.05, {"axial_load_n": 3000.0, "shear_heating": False}),
    "6208-stribeck-auto": ("6208", "auto", 0.05, {"friction_model": "stribeck_line", "shear_heating": False}),
    "6208-asperity-1700rad-7.5kN": (
        "6208",
        "auto",
        0.05,
        {
            "friction_model": "asperity_share",
            "shear_heating": False,
            "shaft_speed_rad_s": 1700.0,
            "radial_load_n": 7500.0,
        },
    ),
    "6208-housing-outer-spall": ("6208", "auto", 0.03, {"housing": True, "defect": "outer", "shear_heating": False}),
    "6208-5A-shear-heating": ("6208", "auto", 0.05, {"shaft_current_a": 5.0, "shear_heating": True}),
}

ROWS = {
    "load": L.C_LOAD,
    "lambda": L.C_LAMBDA,
    "h_min": L.C_H_MIN,
    "h_c": L.C_H_C,
    "mu": L.C_MU,
    "capacitance": L.C_CAPACITANCE,
    "resistance": L.C_RESISTANCE,
    "force_x": L.O_FX,
    "force_z": L.O_FZ,
    "torque_z": L.O_TZ,
    "spring_x": L.T_XI0,
    "spring_decay": L.C_XI_DECAY,
    "rolling_per_speed": L.C_ROLLING_PER_SPEED,
    "tangent_damping": L.C_TANGENT_DAMPING,
}


def run_case(designation: str, time_step_s, seconds: float, extra: dict) -> dict:
    """One case from its warm start: the arrays of the module docstring, by name."""
    spec = catalog.bearing(designation)
    if extra.get("housing"):
        spec = BearingSpec.model_validate(
            {**spec.model_dump(), "housing": {**spec.housing.model_dump(), "enabled": True}}
        )
    spec = BearingSpec.model_validate(
        {**spec.model_dump(), "thermal": {**spec.thermal.model_dump(), "shear_heating": bool(extra["shear_heating"])}}
    )
    options = {"time_step_s": time_step_s}
    if "friction_model" in extra:
        options["friction_model"] = extra["friction_model"]
    twin = Twin(
        spec,
        options=ModelOptions(**options),
        setpoint=Setpoint(
            shaft_speed_rad_s=extra.get("shaft_speed_rad_s", 500.0),
            radial_load_n=extra.get("radial_load_n", 3000.0),
            axial_load_n=extra.get("axial_load_n", 0.0),
            shaft_current_a=extra.get("shaft_current_a", 0.0),
        ),
    )
    if extra.get("defect"):
        twin.set_defects([defect_for(extra["defect"], spec.geometry)])
    twin.advance(seconds)
    s = twin.state
    contacts = s.contacts
    out = {name: contacts[row].copy() for name, row in ROWS.items()}
    out.update(
        scalars=s.scalars.copy(),
        ball_position=s.ball_position_m.copy(),
        ball_spin=s.ball_angular_velocity_rad_s.copy(),
        cage_load=s.cage_load_n.copy(),
        status=np.array([0.0 if twin.status == "ok" else 1.0]),
    )
    return out


def dump(path: str) -> None:
    arrays = {}
    for case, (designation, dt, seconds, extra) in CASES.items():
        for name, value in run_case(designation, dt, seconds, extra).items():
            arrays[f"{case}/{name}"] = value
        print(
            case,
            "cage speed",
            arrays[f"{case}/scalars"][L.X_CAGE_SPEED],
            "rad/s, torque",
            arrays[f"{case}/scalars"][L.X_DRIVE_TORQUE],
            "N m",
            flush=True,
        )
    np.savez(path, **arrays)


def compare(path_a: str, path_b: str) -> float:
    """Prints every array that differs (max |a - b| / max |a|) and returns the largest."""
    a, b = np.load(path_a), np.load(path_b)
    worst = 0.0
    for key in a.files:
        x, y = a[key], b[key]
        d = float(np.max(np.abs(x - y)) / max(float(np.max(np.abs(x))), 1e-300)) if x.size else 0.0
        worst = max(worst, d)
        if d > 0.0:
            print(f"{key:40s} {d:.2e}")
    print(f"largest relative difference {worst:.2e} over {len(a.files)} arrays")
    return worst


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "dump":
        dump(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        compare(sys.argv[2], sys.argv[3])
    else:
        sys.exit("usage: python -m twin.validation.step_compare dump OUT.npz | compare A.npz B.npz")
