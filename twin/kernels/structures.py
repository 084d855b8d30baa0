"""The named array structures the step takes: `step_n(model, state, setpoint, n)`.

MuJoCo's split, in numba's terms: `ModelArrays` is what a compiled `twin.model.BearingModel`
hands the kernels (never written by them), `StateArrays` the one mutable state
(`twin.state.TwinState`'s arrays, shared, not copied), and the setpoint is the float64 vector
laid out by `twin.kernels.layout.S_*`. Both are `typing.NamedTuple`s of arrays: numba passes them
as tuples of array views, the kernel reads a field by name at no cost, and the Python side builds
them once per frame (about 2 us of dispatch per call, against the frame's hundreds of steps).
"""

from typing import NamedTuple

import numpy as np


class ModelArrays(NamedTuple):
    """The model's constants, as the kernels read them."""

    params: np.ndarray  # layout.P_* vector of scalar constants (SI)
    angle_table: np.ndarray  # (race, angle row, layout.A_*) contact constants per contact angle
    housing_params: np.ndarray  # twin.vibration.housing H_* vector (housing, sprung mass, sensor path)
    decimator_taps: np.ndarray  # anti-aliasing FIR taps of the accelerometer's decimator


class StateArrays(NamedTuple):
    """The state's arrays (`twin.state.TwinState` of the same names; units there)."""

    scalars: np.ndarray
    ball_position_m: np.ndarray
    ball_velocity_m_s: np.ndarray
    ball_angular_velocity_rad_s: np.ndarray
    ball_acceleration: np.ndarray
    ball_angular_acceleration: np.ndarray
    ring_position_m: np.ndarray
    ring_velocity_m_s: np.ndarray
    ring_acceleration: np.ndarray
    workspace: np.ndarray
    cage_load_n: np.ndarray
    housing_displacement_m: np.ndarray
    housing_velocity_m_s: np.ndarray
    housing_acceleration_m_s2: np.ndarray
    decimator_state: np.ndarray
    sample_ring_m_s2: np.ndarray
    sample_ring_state: np.ndarray
