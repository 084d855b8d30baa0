"""Index layout of the flat float64 vectors the kernels share (model, setpoint, state scalars,
per-contact outputs). Module-level ints are compile-time constants for numba."""

from twin.vibration.defects import N_DEFECT_PARAMS
from twin.vibration.surface import PROFILE_POINTS  # points of a race profile over its circumference

# ---- model parameter vector (immutable, built by twin.model) --------------------------------
P_DT = 0
P_BALL_RADIUS = 1
P_BALL_MASS = 2
P_BALL_INERTIA = 3
P_RING_MASS = 4
P_CAGE_INERTIA = 5
P_CAGE_RADIUS = 6  # radius of the circle carrying the cage elements [m]
P_CAGE_CONTACT_DISTANCE = 7  # ball-centre to cage-element-centre distance at first touch [m]
P_CAGE_STIFFNESS = 8  # eq. 3 K [N/m^1.5]
P_CAGE_REDUCED_MASS = 9  # ball / cage-at-pitch reduced mass [kg]
P_E_PRIME = 10
P_G_PARAM = 11  # xi E'
P_ROUGHNESS = 12  # 1.25 sqrt(s1^2 + s2^2)
P_KT_RATIO = 13
P_CT_RATIO = 14
P_ALPHA_E = 15
P_RAMP = 16
P_FILM_FORMULA = 17  # 0 Hamrock-Dowson, 1 Masjedi-Khonsari
P_FRICTION_MODEL = 18  # FRICTION_STRIBECK_LINE, FRICTION_ASPERITY_SHARE or FRICTION_ELLIPSE
P_SUBSTEPS = 19
P_ROLLING = 20  # 1: seed 001 rolling resistance on
P_BALL_REDUCED_TANGENT_MASS = 21  # m / (1 + m Rb^2 / I) [kg]
P_MAX_PENETRATION = 22  # status threshold [m]
P_OIL_PERMITTIVITY = 23  # relative permittivity of the oil at ambient pressure [-]
P_GAP_LIMIT = 24  # gap limit of the outer-zone capacitance, inner race [m] (outer: P_GAP_LIMIT_OUTER)
P_ASPERITY_RESISTANCE = 25  # resistance of a fully metallic contact [ohm]
P_OIL_RESISTIVITY = 26  # [ohm m]
# friction over the contact ellipse (twin.kernels.traction)
P_TRACTION_STRIPS = 27  # strips across the major axis [-]
P_TRACTION_EVERY = 28  # tribology refreshes between two strip integrations [-]
P_EYRING_STRESS = 29  # tau0 [Pa]
P_LIMITING_SHEAR = 30  # gamma = tau_L / p [-]
P_PRESSURE_VISCOSITY = 31  # Barus alpha [1/Pa]
P_ASPERITY_SLIP = 32  # regularisation slip of the asperity friction [m/s]
P_DEFORMED_RADIUS = 33  # contact-surface radius across the groove, inner (33) and outer (34) [m]
P_GAP_LIMIT_OUTER = 35  # gap limit of the outer-zone capacitance, outer race [m]
P_STRIP_TABLE = 36  # MAX_STRIPS rows of 4: mean t, mean t^2, load share, mean pressure / p_h
MAX_STRIPS = 32
# vibration (twin.vibration): the model's V_* vector (end of this file) at p[P_VIB + V_*]
P_VIB = P_STRIP_TABLE + 4 * MAX_STRIPS
N_VIB_PARAMS = 10
P_LN_ROUGHNESS = P_VIB + N_VIB_PARAMS  # ln(P_ROUGHNESS / 1 m): ln Lambda = ln h_min - this
P_CAGE_STEP_COS = P_LN_ROUGHNESS + 1  # cos(2 pi / Z): turns one cage element's unit vector to the next
P_CAGE_STEP_SIN = P_LN_ROUGHNESS + 2  # sin(2 pi / Z)
P_CENTRED_REFRESH = (
    P_LN_ROUGHNESS + 3
)  # 1: the tribology refresh's inputs centred on its period (twin.kernels.step.centred_inputs)
# the healthy bearing's excitation (twin.vibration.surface): race profiles and ball sizes
P_PROFILE_ON = P_CENTRED_REFRESH + 1  # 1: the profiles and ball sizes open / close the contacts
P_BALL_SIZE = P_PROFILE_ON + 1  # 16 ball radius offsets [m] (Geometry.ball_count <= 16)
P_PROFILE_INNER = P_BALL_SIZE + 16  # inner race profile heights [m], angle on the ring from its mark
P_PROFILE_OUTER = P_PROFILE_INNER + PROFILE_POINTS  # outer race profile heights [m], azimuth from +x
N_PARAMS = P_PROFILE_OUTER + PROFILE_POINTS

# ---- per-race parameter rows: race_params[r, :], r = 0 inner, 1 outer -------------------------
R_GROOVE_CENTRE_RADIUS = 0  # radius of the groove-curvature-centre circle [m]
R_GROOVE_CENTRE_Z = 1  # its axial position relative to the ring centre [m]
R_GROOVE_RADIUS = 2  # groove curvature radius [m]
R_STIFFNESS = 3  # Hertz K [N/m^1.5]
R_RX = 4
R_RY = 5
R_K_ELLIPTICITY = 6
R_SEMI_MAJOR_COEF = 7  # a = coef * Q^(1/3)
R_SEMI_MINOR_COEF = 8  # b = coef * Q^(1/3)
N_RACE_PARAMS = 9

# ---- setpoint vector (what the kernel needs of the current setpoint) ------------------------
S_SHAFT_SPEED = 0  # target [rad/s]
S_RADIAL_LOAD = 1  # [N], applied on the inner ring along +x
S_AXIAL_LOAD = 2  # [N], along +z
S_VISCOSITY = 3  # dynamic viscosity at the oil temperature [Pa s]
S_STOP = 4  # nonzero: end the frame at the next step boundary (Twin.interrupt_frame) [-]
N_SETPOINT = 5

# ---- state scalars ---------------------------------------------------------------------------
X_TIME = 0
X_SHAFT_SPEED = 1  # current (ramped) shaft speed [rad/s]
X_SHAFT_ANGLE = 2
X_CAGE_ANGLE = 3
X_CAGE_SPEED = 4
X_CAGE_TORQUE = 5
X_STEP = 6  # steps since start (for the tribology sub-rate)
X_DRIVE_TORQUE = 7  # instantaneous torque the contacts apply to the inner ring about +z [N m]
X_TORQUE_SUM = 8  # sum of X_DRIVE_TORQUE over steps since the last reset
X_TORQUE_COUNT = 9
X_MAX_PENETRATION = 10  # largest ball-raceway penetration since the last reset [m]
X_DEFECT_COUNT = 11  # vibration: active local defects (rows at W_DEFECTS of the workspace)
N_SCALARS = 12

# ---- per-contact lanes ---------------------------------------------------------------------------
# Everything per ball-raceway contact (c = 2 ball + race, race 0 inner, 1 outer) lives in ONE flat
# float64 array, row k at [k * CW, k * CW + 2Z). The row stride CW is a compile-time constant: with
# it LLVM proves that rows never overlap and vectorises the geometry and force passes (measured
# 3x faster than 2-D arrays, whose runtime row stride blocks vectorisation). Z <= CW / 2 = 16.
CW = 32
# The lane passes run over the contacts padded to a whole number of LANE_BLOCK lanes (4 float64
# in a 256-bit vector), so that they have no scalar remainder (2 remainder lanes of the 6208's
# 18 cost as much as 4 vector lanes); the pad lanes hold a copy of the last contact's kinematics
# and the outer race's constants (twin.state.make_state), their results are never read.
LANE_BLOCK = 4


def padded_lane_count(nc):
    """Contacts nc rounded up to a whole number of LANE_BLOCK lanes (<= CW)."""
    return (nc + LANE_BLOCK - 1) // LANE_BLOCK * LANE_BLOCK


# persistent outputs and cached tribology (refreshed at the tribology sub-rate)
C_LOAD = 0  # elastic normal load [N]
C_ENTRAINMENT = 1  # [m/s]
C_SRR = 2  # slide-to-roll ratio [-]
C_H_MIN = 3  # [m]
C_H_C = 4  # [m]
C_LAMBDA = 5  # film parameter; -1 when the contact is open
C_REGIME = 6
C_MU = 7
C_FLUID_DAMPING = 8  # C_fluid [N s/m]
C_ROLLING_FORCE = 9  # seed 001 hydrodynamic + hysteresis rolling force [N]
C_SEMI_MAJOR = 10  # [m]
C_SEMI_MINOR = 11  # [m]
C_SPIN_MOMENT = 12  # seed 001 pivoting moment magnitude [N m]
C_ROLLING_PER_SPEED = 13  # rolling force / max(entrainment speed, 0.01 m/s) [N s/m]
C_TANGENT_DAMPING = 14  # tangential damping Ct [N s/m]
C_RESISTANCE = 15  # parallel-RC resistance of the contact [ohm] (inf: open circuit)
C_CAPACITANCE = 16  # parallel-RC capacitance of the contact [F]
N_CACHED = 17  # rows 0..N_CACHED-1 are zeroed when a contact opens
# tangential spring history [m]
T_XI0 = 17
T_XI1 = 18
T_XI2 = 19
# per-contact model constants, copied in when the state is made
M_GROOVE_CENTRE_RADIUS = 20  # radius of the groove-curvature-centre circle [m]
M_GROOVE_CENTRE_Z = 21  # its height relative to the ring centre [m]
M_GROOVE_CLEARANCE = 22  # groove radius - ball radius [m]
M_STIFFNESS = 23  # Hertz K [N/m^1.5]
# kinematics gathered every step
K_PX = 24  # ball centre relative to its ring's centre [m]
K_PY = 25
K_PZ = 26
K_BX = 27  # ball centre, world frame [m]
K_BY = 28
K_VX = 29  # ball centre velocity [m/s]
K_VY = 30
K_VZ = 31
K_WX = 32  # ball angular velocity [rad/s]
K_WY = 33
K_WZ = 34
K_OVX = 35  # ring centre velocity [m/s] (0 in the outer and pad lanes, never written there: step.gather_lanes)
K_OVY = 36
K_OVZ = 37
K_SPIN = 38  # ring spin about +z [rad/s]
K_ORBIT = 39  # angular speed of the ball centre about the axis [rad/s]
# geometry (every step)
G_DELTA = 40  # penetration [m], <= 0: open
G_NX = 41  # unit normal, groove-curvature centre -> ball centre
G_NY = 42
G_NZ = 43
G_SQRT_DELTA = 44
G_LOAD = 45  # K delta^1.5 [N], 0 when open
# force pass outputs (every step)
O_FX = 46  # force on the ball [N]
O_FY = 47
O_FZ = 48
O_TX = 49  # torque on the ball [N m]
O_TY = 50
O_TZ = 51
O_RING_TZ = 52  # torque on the ring about its axis [N m]
O_EX = 53  # entrainment velocity, tangential [m/s]
O_EY = 54
O_EZ = 55
O_SX = 56  # slip velocity ball minus ring, tangential [m/s]
O_SY = 57
O_SZ = 58
# tangential spring relaxation (refreshed with the tribology): xi <- decay (xi + v_slip dt)
C_XI_DECAY = 59  # 1 / (1 + r dt), r = u / L + spin sliding, L = sqrt(a b) the relaxation length [-]
# friction over the contact ellipse (twin.kernels.traction), refreshed with the strip integration
E_SLIP = 60  # centre slip s0 of the last strip solution (warm start) [m/s]
E_MOMENT_T2 = 61  # moment of the traction about the contact centre along t2 = n x t1 [N m]
E_SPIN_MOMENT = 62  # moment along n at the spin rate E_SPIN_RATE [N m]
E_SPIN_SLOPE = 63  # d(moment along n) / d(spin rate) [N m s]
E_SPIN_RATE = 64  # relative spin rate (ball minus ring) about n at the solution [rad/s]
E_SPIN_CAP = 65  # largest moment along n (every strip sliding) [N m]
E_M2X = 72  # E_MOMENT_T2 t2 in the world frame at the last solve [N m]
E_M2Y = 73
E_M2Z = 74
# per-strip scratch of the contact being solved (lanes 0..MAX_STRIPS-1)
E_SCRATCH_O = 66  # slip offset o_k of strip k [m/s]
E_SCRATCH_SE = 67  # Eyring slip scale h tau0 / eta(p_k) [m/s]
E_SCRATCH_SSAT = 68  # slip at which strip k reaches the limiting shear stress [m/s]
E_SCRATCH_EY = 69  # Eyring force coefficient (1 - Qa/Q) A_k tau0 [N]
E_SCRATCH_SPREAD = 70  # half the spread of the slip across strip k [m/s]
E_SCRATCH_SIGNED_HALF = 71  # half-width of strip k in t, signed like ds/dt across it [-]
# local defects and surface profiles (twin.kernels.vibration.apply_clearances, only while one is active)
G_DEFECT_DROP = 75  # extra radial clearance a defect opens at the contact, taken off G_DELTA [m]
O_NORMAL_RATE = 76  # d(delta)/dt of the force pass: ball minus ring centre velocity along n [m/s]
# the inputs of the contact's last tribology refresh as they were (not extrapolated), for the
# centred refresh (twin.kernels.step.refresh_contact): the next refresh extrapolates its inputs
# to the middle of its period from them; zeroed when the contact opens (TwinState.clear_contacts)
H_STAMP = 77  # 1 + the step index of that refresh; 0: none (the contact has just closed) [-]
H_LOAD = 78  # its elastic load q_el [N]
H_SPEED = 79  # its entrainment speed u [m/s]
H_SIN_ANGLE = 80  # its |sin(contact angle)| = |n_z|, within the angle table [-]
N_ROWS = 81

# ---- the kernel workspace `w`: the N_ROWS x CW contact lanes, then the local defects -----------
# The defect table and the balls' orientations ride in the workspace after the lanes, so that the
# force pass takes no further array argument (an array argument of a compiled call costs its
# reference counting, measured ~50 ns per array per step): `TwinState.lanes` is the first
# N_ROWS * CW of the workspace, `defect_rows` and `ball_orientation` views of the rest.
MAX_DEFECTS = 8  # defect rows a twin holds at once
W_DEFECTS = N_ROWS * CW  # MAX_DEFECTS rows of N_DEFECT_PARAMS (D_*), active first
W_ORIENTATION = W_DEFECTS + MAX_DEFECTS * N_DEFECT_PARAMS  # (CW // 2, 4) unit quaternions (w, x, y, z)
N_WORKSPACE = W_ORIENTATION + 4 * (CW // 2)

# ---- kernel status codes ----------------------------------------------------------------------
STATUS_OK = 0
STATUS_NOT_FINITE = 1
STATUS_PENETRATION = 2
STATUS_NAMES = ("ok", "diverged: non-finite state", "overloaded: excessive contact penetration")

# ---- contact-angle tables (twin.model: angle_table[r, i, :], r = 0 inner, 1 outer) ---------------
# Row i holds the Hertz and film constants of race r at sin(contact angle) = i * ANGLE_STEP
# (0 .. sin 60 deg), computed exactly at compile time; the tribology refresh interpolates them
# linearly at each contact's current |sin(alpha)| = |n_z| (tests/physics/test_contact_angle_table.py
# proves the grid).
ANGLE_POINTS = 49  # grid points
ANGLE_MAX_SIN = 0.8660254037844386  # sin(60 deg): the last grid point
ANGLE_STEP = ANGLE_MAX_SIN / (ANGLE_POINTS - 1)
ANGLE_INV_STEP = 1.0 / ANGLE_STEP
A_STIFFNESS = 0  # Hertz K [N/m^1.5]
A_TRIBOLOGY = 1  # first of the N_TRIBOLOGY coefficients of twin.kernels.tribology (T_* + 1)

# ---- vibration: housing, local defects, accelerometer (twin.vibration) --------------
# Model vector p[P_VIB + V_*] (twin.model; `BearingModel.vibration_params` is a view of it); the
# housing's own vector is twin.vibration.housing.H_*, a defect row twin.vibration.defects.D_*.
V_HOUSING_ON = 0  # 1: the outer ring rides on the housing model and the sensor is sampled
V_DECIMATION_RATIO = 1  # R: DEM steps per accelerometer sample (dt = 1 / (R f_s))
V_INNER_RACEWAY_RADIUS = 2  # raceway radius at the contact, for the arc length over a spall [m]
V_OUTER_RACEWAY_RADIUS = 3
V_INNER_GROOVE_RADIUS = 4  # [m]
V_OUTER_GROOVE_RADIUS = 5
V_INNER_RX = 6  # relative radius of curvature along the rolling direction [m]
V_OUTER_RX = 7
V_INNER_FOOTPRINT = 8  # semi-major axis of the contact ellipse per root deflection, a / sqrt(delta) [m^0.5]
V_OUTER_FOOTPRINT = 9

# codes of P_FRICTION_MODEL (twin.spec.ModelOptions.friction_model)
FRICTION_STRIBECK_LINE = 0  # seed 000 Table 2's line mu(Lambda)
FRICTION_ASPERITY_SHARE = 1  # seed 001's asperity share of the load
FRICTION_ELLIPSE = 2  # traction over the contact ellipse (twin.kernels.traction)
FRICTION_MODEL_CODES = {
    "stribeck_line": FRICTION_STRIBECK_LINE,
    "asperity_share": FRICTION_ASPERITY_SHARE,
    "ellipse_traction": FRICTION_ELLIPSE,
}
