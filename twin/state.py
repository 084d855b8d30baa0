"""The one mutable object of a twin (MuJoCo's mjData role): preallocated float64 arrays."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from twin.kernels import layout as L
from twin.kernels.layout import MAX_DEFECTS
from twin.kernels.structures import StateArrays
from twin.model import BearingModel
from twin.vibration.defects import N_DEFECT_PARAMS
from twin.vibration.housing import N_HOUSING_DOF
from twin.vibration.signal import N_DD_HEADER, N_RS_HEADER

SAMPLE_RING_S = 2.0  # the accelerometer's sample ring holds this much signal [s]


@dataclass
class TwinState:
    """Structure-of-arrays state. Positions [m], velocities [m/s], angular velocities [rad/s];
    world frame with the bearing axis +z and the radial load along +x."""

    scalars: np.ndarray  # layout.X_*
    ball_position_m: np.ndarray  # (Z, 3)
    ball_velocity_m_s: np.ndarray
    ball_angular_velocity_rad_s: np.ndarray
    ball_acceleration: np.ndarray  # (Z, 3) [m/s^2]
    ball_angular_acceleration: np.ndarray  # (Z, 3) [rad/s^2]
    ring_position_m: np.ndarray  # inner ring centre (3,)
    ring_velocity_m_s: np.ndarray
    ring_acceleration: np.ndarray
    workspace: np.ndarray  # the kernel's `w` (layout.N_WORKSPACE): the lanes, then the defects
    lanes: np.ndarray  # flat per-contact lanes, row k of contact c at [k * CW + c] (a view)
    cage_load_n: np.ndarray  # (Z, 2) ball j against cage element ahead (0) and behind (1)
    # vibration (twin.vibration); all zero and unused with the rigid outer ring
    housing_displacement_m: np.ndarray  # (N_HOUSING_DOF,) outer ring x, y, z, sprung mass [m]
    housing_velocity_m_s: np.ndarray  # [m/s]
    housing_acceleration_m_s2: np.ndarray  # [m/s^2]
    ball_orientation: np.ndarray  # (Z, 4) unit quaternions (w, x, y, z), body -> world (workspace view)
    decimator_state: np.ndarray  # twin.vibration.signal direct-form decimator state
    sample_ring_m_s2: np.ndarray  # float32 ring of accelerometer samples [m/s^2]
    sample_ring_state: np.ndarray  # twin.vibration.signal RS_* counters
    defect_rows: np.ndarray  # (MAX_DEFECTS, N_DEFECT_PARAMS) workspace view, the first `defect_count` active

    @property
    def defect_count(self) -> int:
        """Active defect rows (scalars[X_DEFECT_COUNT])."""
        return int(self.scalars[L.X_DEFECT_COUNT])

    @defect_count.setter
    def defect_count(self, n: int) -> None:
        self.scalars[L.X_DEFECT_COUNT] = float(n)

    @property
    def inner_ring_offset_m(self) -> np.ndarray:
        """Inner ring centre relative to the outer ring's (the bearing's own deflection) [m] (3,);
        = ring_position_m with the rigid outer ring."""
        return self.ring_position_m - self.housing_displacement_m[:3]

    @property
    def ball_position_in_bearing_m(self) -> np.ndarray:
        """Ball centres relative to the outer ring's centre [m] (Z, 3); = ball_position_m with the
        rigid outer ring."""
        return self.ball_position_m - self.housing_displacement_m[:3]

    @property
    def ball_velocity_in_bearing_m_s(self) -> np.ndarray:
        """Ball velocities relative to the outer ring [m/s] (Z, 3)."""
        return self.ball_velocity_m_s - self.housing_velocity_m_s[:3]

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
        rows[L.T_XI0 : L.T_XI2 + 1] = 0.0
        # the spring's decay factor is read (xi * decay) before the first refresh sets it: a
        # value left from a diverged state (NaN) would poison the spring after a warm restart
        rows[L.C_XI_DECAY] = 1.0
        rows[L.C_LAMBDA] = -1.0
        rows[L.C_H_MIN] = -1.0
        rows[L.C_H_C] = -1.0
        rows[L.G_DEFECT_DROP] = 0.0
        rows[L.H_STAMP : L.H_SIN_ANGLE + 1] = 0.0  # no previous refresh to extrapolate from
        # the outer ring's velocity and spin in its contacts' lanes and in the pad lanes: 0,
        # which the gather leaves unwritten (twin.kernels.step.gather_lanes)
        rows[L.K_OVX : L.K_SPIN + 1, 1::2] = 0.0
        rows[L.K_OVX : L.K_SPIN + 1, 2 * self.ball_position_m.shape[0] :] = 0.0

    def copy(self) -> TwinState:
        """An independent copy: every array copied, plain numbers (the defect count) as they are."""
        return dataclasses.replace(
            self,
            **{
                f.name: (v.copy() if isinstance(v := getattr(self, f.name), np.ndarray) else v)
                for f in dataclasses.fields(self)
            },
        )

    def arrays(self) -> StateArrays:
        """The state's arrays as the kernels take them (`twin.kernels.structures.StateArrays`:
        the same array objects, written in place by `step_n`)."""
        return StateArrays(
            self.scalars,
            self.ball_position_m,
            self.ball_velocity_m_s,
            self.ball_angular_velocity_rad_s,
            self.ball_acceleration,
            self.ball_angular_acceleration,
            self.ring_position_m,
            self.ring_velocity_m_s,
            self.ring_acceleration,
            self.workspace,
            self.cage_load_n,
            self.housing_displacement_m,
            self.housing_velocity_m_s,
            self.housing_acceleration_m_s2,
            self.decimator_state,
            self.sample_ring_m_s2,
            self.sample_ring_state,
        )


def make_state(model: BearingModel) -> TwinState:
    """Zeroed state sized for the model (positions are set by the warm start)."""
    if 2 * model.ball_count > L.CW:
        raise ValueError(f"ball_count = {model.ball_count}: at most {L.CW // 2} balls")
    z = model.ball_count
    workspace = np.zeros(L.N_WORKSPACE)
    lanes = workspace[: L.N_ROWS * L.CW]
    rows = lanes.reshape(L.N_ROWS, L.CW)
    for r in range(2):
        rows[L.M_GROOVE_CENTRE_RADIUS, r : 2 * z : 2] = model.race_params[r, L.R_GROOVE_CENTRE_RADIUS]
        rows[L.M_GROOVE_CENTRE_Z, r : 2 * z : 2] = model.race_params[r, L.R_GROOVE_CENTRE_Z]
        rows[L.M_GROOVE_CLEARANCE, r : 2 * z : 2] = model.race_params[r, L.R_GROOVE_RADIUS] - model.ball_radius_m
        rows[L.M_STIFFNESS, r : 2 * z : 2] = model.race_params[r, L.R_STIFFNESS]
    dec = model.decimator
    ring = int(round(SAMPLE_RING_S * dec.output_rate_hz)) if dec is not None else 1
    orientation = workspace[L.W_ORIENTATION : L.W_ORIENTATION + 4 * z].reshape(z, 4)
    orientation[:, 0] = 1.0
    # pad lanes (layout.LANE_BLOCK): outer-race constants, like the last contact they copy
    rows[L.M_GROOVE_CENTRE_RADIUS : L.M_STIFFNESS + 1, 2 * z : L.padded_lane_count(2 * z)] = rows[
        L.M_GROOVE_CENTRE_RADIUS : L.M_STIFFNESS + 1, 2 * z - 1 : 2 * z
    ]
    return TwinState(
        housing_displacement_m=np.zeros(N_HOUSING_DOF),
        housing_velocity_m_s=np.zeros(N_HOUSING_DOF),
        housing_acceleration_m_s2=np.zeros(N_HOUSING_DOF),
        ball_orientation=orientation,
        decimator_state=dec.new_direct_state() if dec is not None else np.zeros(N_DD_HEADER + 2),
        sample_ring_m_s2=np.zeros(ring, dtype=np.float32),
        sample_ring_state=np.zeros(N_RS_HEADER),
        defect_rows=workspace[L.W_DEFECTS : L.W_DEFECTS + MAX_DEFECTS * N_DEFECT_PARAMS].reshape(
            MAX_DEFECTS, N_DEFECT_PARAMS
        ),
        workspace=workspace,
        scalars=np.zeros(L.N_SCALARS),
        ball_position_m=np.zeros((z, 3)),
        ball_velocity_m_s=np.zeros((z, 3)),
        ball_angular_velocity_rad_s=np.zeros((z, 3)),
        ball_acceleration=np.zeros((z, 3)),
        ball_angular_acceleration=np.zeros((z, 3)),
        ring_position_m=np.zeros(3),
        ring_velocity_m_s=np.zeros(3),
        ring_acceleration=np.zeros(3),
        lanes=lanes,
        cage_load_n=np.zeros((z, 2)),
    )
