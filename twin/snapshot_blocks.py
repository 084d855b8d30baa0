"""The snapshot's per-ball, per-contact and electrical blocks (twin.snapshot), read from the
state's lanes, the electrical network and the inlet film at one instant.

The balls and their contacts are captured at once into arrays (`BallArrays`: numpy over the
contact lanes, no Python object per ball); the pydantic tree (`BallState`, `ContactState`) is
built from them only for a consumer that reads it (`ball_states`), and the state message's
`balls` JSON is written straight from them (`balls_json`: one typed pydantic serialisation of
every number, then a fixed template), the same text the tree serialises to.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass
from typing import Final

import numpy as np
from numba import njit
from pydantic import TypeAdapter

from twin.electrical_network import ElectricalNetwork
from twin.inlet_film import InletFilm
from twin.jit import JIT
from twin.kernels import layout as L
from twin.model import BearingModel
from twin.physics.friction import REGIME_NAMES, REGIME_NO_CONTACT
from twin.physics.hertz import max_pressure_pa
from twin.snapshot import LAMBDA_KEY, BallState, ContactState, ElectricalState
from twin.state import TwinState
from twin.state_measures import ball_azimuths_rad

CONTACT_FIELDS: Final = (
    "load_n",
    "h_min_m",
    "h_c_m",
    LAMBDA_KEY,
    "mu",
    "entrainment_speed_m_s",
    "slide_roll_ratio",
    "contact_angle_rad",
    "max_pressure_pa",
    "resistance_ohm",
    "capacitance_f",
)
"""Columns of `BallArrays.contacts`, in the contract's order of `ContactState` (its `regime` is
`BallArrays.regimes`)."""
K_LOAD, K_H_MIN, K_H_C, K_LAMBDA, K_MU, K_ENTRAINMENT, K_SRR, K_ANGLE, K_P_MAX, K_R, K_C = range(len(CONTACT_FIELDS))
BALL_FIELDS: Final = (
    "azimuth_rad",
    "spin_rad_s",
    "orbital_speed_rad_s",
    "cage_load_n",
    "resistance_ohm",
    "capacitance_f",
)
"""Columns of `BallArrays.balls`, in the contract's order of `BallState`."""
B_AZIMUTH, B_SPIN, B_ORBITAL, B_CAGE, B_R, B_C = range(len(BALL_FIELDS))

_FLOATS = TypeAdapter(list[float])  # NaN and inf serialise as null (pydantic's default)


def finite_or_none(value: float) -> float | None:
    """The value as a float, or None when it is inf or NaN (the snapshot's JSON has neither)."""
    return float(value) if math.isfinite(value) else None


@dataclass(frozen=True, slots=True, eq=False)
class BallArrays:
    """Every ball and contact of one snapshot as numbers: `contacts` (2Z, CONTACT_FIELDS) with
    contact k = 2j inner and 2j + 1 outer of ball j, `regimes` (2Z,) the index of each contact's
    regime in REGIME_NAMES (0: no_contact), `balls` (Z, BALL_FIELDS). NaN stands for null (the
    film of an unloaded contact, an open circuit's resistance); every other value is finite. Read
    only: the arrays are the snapshot's own."""

    contacts: np.ndarray
    regimes: np.ndarray
    balls: np.ndarray

    @property
    def ball_count(self) -> int:
        return int(self.balls.shape[0])


@njit(**JIT)
def capture_contacts(contacts, loaded_mu_scale, out, regimes):
    """Write every contact's published numbers (CONTACT_FIELDS but the network's R and C) into
    `out` (2Z, CONTACT_FIELDS) and its regime index into `regimes` (2Z,) from the contact lanes
    `contacts` (lanes, 2Z). `loaded_mu_scale` > 0: mu is the effective |F_t| / Q of the ellipse
    friction, with the tangential stiffness loaded_mu_scale x M_STIFFNESS x G_SQRT_DELTA
    (loaded_mu_scale: the tangential stiffness ratio x 1.5); <= 0: the lane's Coulomb coefficient.
    An unloaded contact's film
    is NaN (null), its mu, speeds and angle 0, its regime 0 (no_contact). p_max = 3 Q / (2 pi a b)
    (twin.physics.hertz.max_pressure_pa)."""
    for k in range(contacts.shape[1]):
        load = contacts[L.C_LOAD, k]
        out[k, K_LOAD] = load
        if load > 0.0:
            out[k, K_H_MIN] = contacts[L.C_H_MIN, k]
            out[k, K_H_C] = contacts[L.C_H_C, k]
            out[k, K_LAMBDA] = contacts[L.C_LAMBDA, k]
            if loaded_mu_scale > 0.0:
                kt = loaded_mu_scale * contacts[L.M_STIFFNESS, k] * contacts[L.G_SQRT_DELTA, k]
                x0, x1, x2 = contacts[L.T_XI0, k], contacts[L.T_XI1, k], contacts[L.T_XI2, k]
                out[k, K_MU] = kt * math.sqrt(x0 * x0 + x1 * x1 + x2 * x2) / load
            else:
                out[k, K_MU] = contacts[L.C_MU, k]
            out[k, K_ENTRAINMENT] = contacts[L.C_ENTRAINMENT, k]
            out[k, K_SRR] = contacts[L.C_SRR, k]
            out[k, K_ANGLE] = math.asin(min(1.0, max(-1.0, contacts[L.G_NZ, k])))
            regimes[k] = int(contacts[L.C_REGIME, k])
        else:
            out[k, K_H_MIN] = np.nan
            out[k, K_H_C] = np.nan
            out[k, K_LAMBDA] = np.nan
            out[k, K_MU] = 0.0
            out[k, K_ENTRAINMENT] = 0.0
            out[k, K_SRR] = 0.0
            out[k, K_ANGLE] = 0.0
            regimes[k] = REGIME_NO_CONTACT
        a, b = contacts[L.C_SEMI_MAJOR, k], contacts[L.C_SEMI_MINOR, k]
        out[k, K_P_MAX] = max_pressure_pa(load, a, b)


@njit(**JIT)
def capture_balls(position, velocity, angular_velocity, cage_load, out):
    """Write every ball's spin |omega|, orbital speed (x v_y - y v_x) / (x^2 + y^2) about the
    bearing axis and largest cage load into `out` (Z, BALL_FIELDS)."""
    for j in range(position.shape[0]):
        w0, w1, w2 = angular_velocity[j, 0], angular_velocity[j, 1], angular_velocity[j, 2]
        out[j, B_SPIN] = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        x, y = position[j, 0], position[j, 1]
        out[j, B_ORBITAL] = (x * velocity[j, 1] - y * velocity[j, 0]) / (x * x + y * y)
        largest = cage_load[j, 0]
        for i in range(1, cage_load.shape[1]):
            largest = max(largest, cage_load[j, i])
        out[j, B_CAGE] = largest


def ball_arrays(model: BearingModel, state: TwinState, net: ElectricalNetwork, effective_mu: bool) -> BallArrays:
    """Capture every ball's block: azimuth, spin, orbital speed about the bearing axis, cage load,
    its inner and outer contacts (`capture_contacts`: one compiled pass over the lanes) and their
    series RC. Published mu: with the ellipse friction (`effective_mu`) the effective coefficient
    |F_t| / Q (the tangential spring's elastic force, which the strips transmit, over the normal
    load); with the centre-point laws their Coulomb coefficient. ValueError naming the field when
    a value that may not be null is not finite."""
    s = state
    z = model.ball_count
    out = np.empty((2 * z, len(CONTACT_FIELDS)))
    regimes = np.empty(2 * z, dtype=np.int8)
    scale = model.options.tangential_stiffness_ratio * 1.5 if effective_mu else 0.0
    capture_contacts(s.contacts, scale, out, regimes)
    balls = np.empty((z, len(BALL_FIELDS)))
    balls[:, B_AZIMUTH] = ball_azimuths_rad(s)
    capture_balls(
        s.ball_position_in_bearing_m,
        s.ball_velocity_in_bearing_m_s,
        s.ball_angular_velocity_rad_s,
        s.cage_load_n,
        balls,
    )
    bad = attach_network(
        out,
        balls,
        net.contact_resistance_ohm,
        net.contact_capacitance_f,
        net.ball_resistance_ohm,
        net.ball_capacitance_f,
    )
    if bad >= 0:
        _raise_not_finite(out, balls, bad)
    return BallArrays(out, regimes, balls)


@njit(**JIT)
def attach_network(out, balls, r_contact, c_contact, r_ball, c_ball):
    """Write the network's series R and C into the contacts' (`out`) and the balls' (`balls`)
    columns, null (NaN) every non-finite value of a nullable column (an open circuit's infinite
    resistance, an unloaded contact's film: the contacts' h_min, h_c, Lambda and R, the balls'
    R), and return the flat index of the first non-finite value of a column that may not be null:
    contacts first (row-major), then the balls offset by out.size; -1 when every such value is
    finite."""
    for k in range(out.shape[0]):
        out[k, K_R] = r_contact[k]
        out[k, K_C] = c_contact[k]
    for j in range(balls.shape[0]):
        balls[j, B_R] = r_ball[j]
        balls[j, B_C] = c_ball[j]
    first = -1
    for k in range(out.shape[0]):
        for i in range(out.shape[1]):
            if not math.isfinite(out[k, i]):
                if i == K_H_MIN or i == K_H_C or i == K_LAMBDA or i == K_R:
                    out[k, i] = np.nan
                elif first < 0:
                    first = k * out.shape[1] + i
    for j in range(balls.shape[0]):
        for i in range(balls.shape[1]):
            if not math.isfinite(balls[j, i]):
                if i == B_R:
                    balls[j, i] = np.nan
                elif first < 0:
                    first = out.size + j * balls.shape[1] + i
    return first


def _raise_not_finite(out: np.ndarray, balls: np.ndarray, flat: int) -> None:
    """The ValueError naming the value `attach_network` found not finite (its flat index)."""
    values, names, what = (out, CONTACT_FIELDS, "contact") if flat < out.size else (balls, BALL_FIELDS, "ball")
    row, col = divmod(flat if flat < out.size else flat - out.size, values.shape[1])
    raise ValueError(f"snapshot: {what} {row} {names[col]} = {values[row, col]!r} is not finite")


def _value(v: float) -> float | None:
    return None if v != v else v  # NaN: null


def ball_states(arrays: BallArrays) -> tuple[BallState, ...]:
    """The balls' pydantic tree (`BallState` with its `ContactState`s) from the captured arrays."""
    rows = arrays.contacts.tolist()
    codes = arrays.regimes.tolist()

    def contact(k: int) -> ContactState:
        values = {name: _value(v) for name, v in zip(CONTACT_FIELDS, rows[k], strict=True)}
        return ContactState.model_validate({**values, "regime": REGIME_NAMES[codes[k]]})

    return tuple(
        BallState.model_validate(
            {
                "index": j,
                **{name: _value(v) for name, v in zip(BALL_FIELDS, ball, strict=True)},
                "inner": contact(2 * j),
                "outer": contact(2 * j + 1),
            }
        )
        for j, ball in enumerate(arrays.balls.tolist())
    )


class _Template:
    """JSON text with holes: `render(values)` joins the literal pieces with `values[i]` for each
    hole i, in one join (a `str.format` of the same text parses its fields on every call: three
    times slower)."""

    def __init__(self, pieces: list[str | int]):
        literals: list[str] = [""]
        holes: list[int] = []
        for piece in pieces:
            if isinstance(piece, int):
                holes.append(piece)
                literals.append("")
            else:
                literals[-1] += piece
        self.literals = literals
        self.pick = operator.itemgetter(*holes)
        self.size = 2 * len(holes) + 1

    def render(self, values: list[str]) -> str:
        parts: list = [None] * self.size
        parts[0::2] = self.literals
        parts[1::2] = self.pick(values)
        return "".join(parts)


def _ball_pieces(z: int, j: int) -> list[str | int]:
    """Ball j's JSON block as literal pieces and value indices: its numbers are values
    28 j ... 28 j + 27 (its first four fields, the inner then the outer contact's numbers, its R
    and C: the order of `_numbers_in_order`), its contacts' regime names values 28 z + 2 j and
    28 z + 2 j + 1."""
    n = 4 + 2 * len(CONTACT_FIELDS) + 2
    fields = iter(range(n * j, n * (j + 1)))
    pieces: list[str | int] = [f'{{"index":{j}']

    def numbers(names: tuple[str, ...], first: str = ",") -> None:
        for k, name in enumerate(names):
            pieces.extend((f'{first if k == 0 else ","}"{name}":', next(fields)))

    numbers(BALL_FIELDS[:4])
    for side, key in enumerate(("inner", "outer")):
        pieces.append(f',"{key}":{{')
        numbers(CONTACT_FIELDS[:4], first="")
        pieces.extend((',"regime":"', n * z + 2 * j + side, '"'))
        numbers(CONTACT_FIELDS[4:])
        pieces.append("}")
    numbers(BALL_FIELDS[4:])
    pieces.append("}")
    return pieces


_TEMPLATES: dict[int, tuple[list[_Template], _Template]] = {}


def _templates(z: int) -> tuple[list[_Template], _Template]:
    """(each ball's template, the balls array's template) for z balls, made once."""
    found = _TEMPLATES.get(z)
    if found is None:
        balls = [_ball_pieces(z, j) for j in range(z)]
        whole: list[str | int] = ["["]
        for j, pieces in enumerate(balls):
            whole.extend(([","] if j else []) + pieces)
        whole.append("]")
        found = _TEMPLATES[z] = ([_Template(b) for b in balls], _Template(whole))
    return found


def _numbers_in_order(arrays: BallArrays) -> list[str]:
    """Every number of the balls' blocks as JSON text, in the templates' order: pydantic's
    serialiser (one typed call for all of them, null for NaN), then the regime names."""
    b, c = arrays.balls, arrays.contacts
    table = np.concatenate((b[:, :4], c[0::2], c[1::2], b[:, 4:]), axis=1)
    tokens = _FLOATS.dump_json(table.ravel().tolist()).decode()[1:-1].split(",")
    return tokens + [REGIME_NAMES[k] for k in arrays.regimes.tolist()]


def ball_json_items(arrays: BallArrays) -> list[str]:
    """Each ball's block of the state message (JSON text), as `ball_states` serialises it."""
    values = _numbers_in_order(arrays)
    return [t.render(values) for t in _templates(arrays.ball_count)[0]]


def balls_json(arrays: BallArrays) -> str:
    """The `balls` array of the state message (JSON text), as `ball_states` serialises it."""
    return _templates(arrays.ball_count)[1].render(_numbers_in_order(arrays))


def electrical_state(net: ElectricalNetwork, inlet: InletFilm) -> ElectricalState:
    """The bearing's electrical block: the network's impedance and discharge indicators, and the
    inlet's current and shear heating with the film factor they give."""
    return ElectricalState(
        resistance_ohm=finite_or_none(net.resistance_ohm),
        capacitance_f=net.capacitance_f,
        capacitance_reason=net.capacitance_reason,
        impedance_ohm=net.impedance_ohm,
        phase_rad=net.phase_rad,
        frequency_hz=net.frequency_hz,
        shaft_voltage_v=net.shaft_voltage_v,
        shaft_current_a=net.shaft_current_a,
        max_film_field_v_m=net.max_film_field_v_m,
        current_density_a_m2=net.current_density_a_m2,
        discharge_risk=net.discharge_risk,
        reason=net.reason,
        contact_temperature_rise_k=float(inlet.current_heating_k + inlet.shear_heating_k),
        current_temperature_rise_k=float(inlet.current_heating_k),
        shear_temperature_rise_k=float(inlet.shear_heating_k),
        film_thermal_factor=float(inlet.film_thermal_factor),
    )
