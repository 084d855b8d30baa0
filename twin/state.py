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
    lanes: np.ndarray            # flat per-contact lanes, row k of contact c at [k * CW + c]
    cage_load_n: np.ndarray      # (Z, 2) ball j against cage element ahead (0) and behind (1)

    @property
    def contacts(self) -> np.ndarray:
        """(N_ROWS, 2Z) view of the contact lanes: contacts[layout.C_LOAD] is every contact's
        load, contacts[:, 2 * ball + race] one contact (race 0 inner, 1 outer)."""
        nc = 2 * self.ball_position_m.shape[0]
        return self.lanes.reshape(L.N_ROWS, L.CW)[:, :nc]

    def clear_contacts(self) -> None:
        """Forget every contact's history (spring, cached tribology): all contacts open."""
        rows = self.lanes.reshape(L.N_ROWS, L.CW)
        rows[: L.N_CACHED] = 0.0
        rows[L.T_XI0:L.T_XI2 + 1] = 0.0
        # the spring's decay factor is read (xi * decay) before the first refresh sets it: a
        # value left from a diverged state (NaN) would poison the spring after a warm restart
        rows[L.C_XI_DECAY] = 1.0
        rows[L.C_LAMBDA] = -1.0
        rows[L.C_H_MIN] = -1.0
        rows[L.C_H_C] = -1.0

    def kernel_args(self) -> tuple:
        """The state arrays in `step_n` order."""
        return (self.scalars, self.ball_position_m, self.ball_velocity_m_s,
                self.ball_angular_velocity_rad_s, self.ball_acceleration,
                self.ball_angular_acceleration, self.ring_position_m, self.ring_velocity_m_s,
                self.ring_acceleration, self.lanes, self.cage_load_n)


def make_state(model: BearingModel) -> TwinState:
    """Zeroed state sized for the model (positions are set by the warm start)."""
    if 2 * model.ball_count > L.CW:
        raise ValueError(f"ball_count = {model.ball_count}: at most {L.CW // 2} balls")
    z = model.ball_count
    lanes = np.zeros(L.N_ROWS * L.CW)
    rows = lanes.reshape(L.N_ROWS, L.CW)
    for r in range(2):
        rows[L.M_GROOVE_CENTRE_RADIUS, r:2 * z:2] = model.race_params[r, L.R_GROOVE_CENTRE_RADIUS]
        rows[L.M_GROOVE_CENTRE_Z, r:2 * z:2] = model.race_params[r, L.R_GROOVE_CENTRE_Z]
        rows[L.M_GROOVE_CLEARANCE, r:2 * z:2] = (model.race_params[r, L.R_GROOVE_RADIUS]
                                                  - model.ball_radius_m)
        rows[L.M_STIFFNESS, r:2 * z:2] = model.race_params[r, L.R_STIFFNESS]
    # pad lanes (layout.LANE_BLOCK): outer-race constants, like the last contact they copy
    rows[L.M_GROOVE_CENTRE_RADIUS:L.M_STIFFNESS + 1, 2 * z:L.padded_lane_count(2 * z)] = \
        rows[L.M_GROOVE_CENTRE_RADIUS:L.M_STIFFNESS + 1, 2 * z - 1:2 * z]
    return TwinState(
        scalars=np.zeros(L.N_SCALARS),
        ball_position_m=np.zeros((z, 3)), ball_velocity_m_s=np.zeros((z, 3)),
        ball_angular_velocity_rad_s=np.zeros((z, 3)), ball_acceleration=np.zeros((z, 3)),
        ball_angular_acceleration=np.zeros((z, 3)), ring_position_m=np.zeros(3),
        ring_velocity_m_s=np.zeros(3), ring_acceleration=np.zeros(3),
        lanes=lanes, cage_load_n=np.zeros((z, 2)))
