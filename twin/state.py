"""The one mutable object of a twin (MuJoCo's mjData role): preallocated float64 arrays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.model import BearingModel


@dataclass
class TwinState:
    """Structure-of-arrays state. Positions [m], velocities [m/s], angular velocities [rad/s];
    world frame with the bearing axis +z and the radial load along +x."""

    scalars: np.ndarray          # layout.X_*
    ball_position_m: np.ndarray  # (Z, 3)
    ball_velocity_m_s: np.ndarray
    ball_angular_velocity_rad_s: np.ndarray
    ball_acceleration: np.ndarray        # (Z, 3) [m/s^2]
    ball_angular_acceleration: np.ndarray  # (Z, 3) [rad/s^2]
    ring_position_m: np.ndarray  # inner ring centre (3,)
    ring_velocity_m_s: np.ndarray
    ring_acceleration: np.ndarray
    tangential_spring_m: np.ndarray  # (3, 2Z) tangential displacement history of contact c = 2 ball + race
    contacts: np.ndarray         # (layout.N_CONTACT, 2Z) per-contact outputs, field-major
    cage_load_n: np.ndarray      # (Z, 2) ball j against cage element ahead (0) and behind (1)

    def kernel_args(self) -> tuple:
        """The state arrays in `step_n` order."""
        return (self.scalars, self.ball_position_m, self.ball_velocity_m_s,
                self.ball_angular_velocity_rad_s, self.ball_acceleration,
                self.ball_angular_acceleration, self.ring_position_m, self.ring_velocity_m_s,
                self.ring_acceleration, self.tangential_spring_m, self.contacts, self.cage_load_n)


def make_state(model: BearingModel) -> TwinState:
    """Zeroed state sized for the model (positions are set by the warm start)."""
    z = model.ball_count
    contacts = np.zeros((L.N_CONTACT, 2 * z))
    contacts[L.C_LAMBDA] = -1.0
    return TwinState(
        scalars=np.zeros(L.N_SCALARS),
        ball_position_m=np.zeros((z, 3)), ball_velocity_m_s=np.zeros((z, 3)),
        ball_angular_velocity_rad_s=np.zeros((z, 3)), ball_acceleration=np.zeros((z, 3)),
        ball_angular_acceleration=np.zeros((z, 3)), ring_position_m=np.zeros(3),
        ring_velocity_m_s=np.zeros(3), ring_acceleration=np.zeros(3),
        tangential_spring_m=np.zeros((3, 2 * z)), contacts=contacts,
        cage_load_n=np.zeros((z, 2)))
