"""The bearing's lumped thermal network: nodes, heat capacities and conductances.

Nodes (NODE_NAMES): shaft, inner ring, balls, outer ring, housing, oil. Each node has a heat
capacity C_i = m_i c_p [J/K]; nodes i, j exchange G_ij (T_j - T_i) [W]; node i loses
G_i,amb (T_i - T_amb) to the surroundings (scaled by the dissipation factor the estimator
corrects) and G_i,sup (T_i - T_sup) to a circulating oil supply. The structure is the lumped
network of a bearing, its shaft and housing of Harris and Kotzalas (Advanced Concepts of Bearing
Technology, 2007, ch. 7 'friction heat generation and dissipation'), with six nodes.

The ring dimensions the `BearingSpec` does not carry (bore d, outside diameter D) are estimated
from the pitch diameter d_m and the ball diameter D_w of a series-02 deep-groove bearing:
D - d = D_w / 0.3 (catalogue 62xx: 0.29-0.31), d_m = (d + D) / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from twin.thermal.correlations import (
    churchill_chu_cylinder_w_m2_k,
    cylindrical_shell_w_k,
    flat_plate_laminar_w_m2_k,
    hertz_constriction_w_k,
    iso_15312_dissipation_w_k,
    radiation_w_m2_k,
    rotating_cylinder_w_m2_k,
)
from twin.thermal.materials import (
    OIL_CONDUCTIVITY_W_M_K,
    OIL_SPECIFIC_HEAT_J_KG_K,
    STEEL_CONDUCTIVITY_W_M_K,
    STEEL_SPECIFIC_HEAT_J_KG_K,
)
from twin.thermal.settings import ThermalNetworkSettings

NODE_NAMES = ("shaft", "inner_ring", "balls", "outer_ring", "housing", "oil")
SHAFT, INNER_RING, BALLS, OUTER_RING, HOUSING, OIL = range(6)
N_NODES = 6
RING_SPAN_OVER_BALL = 1.0 / 0.3  # (D - d) / D_w of series-02 deep-groove bearings [-]
CAST_IRON_DENSITY_KG_M3 = 7200.0
CAST_IRON_SPECIFIC_HEAT_J_KG_K = 460.0  # grey cast iron (Incropera and DeWitt Table A.1)


def _series(*conductances: float) -> float:
    return 1.0 / sum(1.0 / g for g in conductances)


@dataclass(frozen=True)
class NetworkGeometry:
    """Dimensions [m], areas [m^2] and heat capacities [J/K] of the nodes (constant per twin)."""

    bore_m: float
    outside_diameter_m: float
    width_m: float
    pitch_diameter_m: float
    ball_diameter_m: float
    ball_count: int
    inner_raceway_radius_m: float
    outer_raceway_radius_m: float
    inner_shoulder_radius_m: float
    outer_shoulder_radius_m: float
    shaft_length_m: float
    housing_diameter_m: float
    housing_width_m: float
    oil_volume_m3: float
    oil_density_kg_m3: float
    capacity_j_k: np.ndarray  # per node, times the settings' heat_capacity_scale

    @property
    def iso_15312_dissipation_w_k(self) -> float:
        """The standard's dissipation conductance of this bearing [W/K] (ISO 15312 clauses 4-5)."""
        return iso_15312_dissipation_w_k(self.bore_m * 1e3, self.outside_diameter_m * 1e3, self.width_m * 1e3)


def network_geometry(spec, settings: ThermalNetworkSettings) -> NetworkGeometry:
    """Dimensions and heat capacities of the nodes of a `twin.spec.BearingSpec`."""
    g = spec.geometry
    dw = 2.0 * g.ball_radius_m
    dm = 2.0 * g.pitch_radius_m
    span = RING_SPAN_OVER_BALL * dw
    bore, od = dm - 0.5 * span, dm + 0.5 * span
    width = g.ring_width_m or 0.25 * span + 0.5 * dw  # ISO 15 series 02: B ~ (D - d) / 4 + D_w / 2
    shoulder = g.shoulder_depth_or_typical_m
    r_i, r_o = g.inner_raceway_radius_m, g.outer_raceway_radius_m
    r_is, r_os = min(r_i + shoulder, g.pitch_radius_m), max(r_o - shoulder, g.pitch_radius_m)
    rho = spec.material.density_kg_m3
    v_inner = math.pi * width * (r_is**2 - (0.5 * bore) ** 2)
    v_outer = math.pi * width * ((0.5 * od) ** 2 - r_os**2)
    v_balls = g.ball_count * math.pi / 6.0 * dw**3
    shaft_len = settings.shaft_length_m or 4.0 * width
    v_shaft = math.pi * (0.5 * bore) ** 2 * (width + 2.0 * shaft_len)
    h_d, h_w = 2.0 * od, 2.0 * width
    m_housing = settings.housing_mass_kg or CAST_IRON_DENSITY_KG_M3 * math.pi * h_w * (
        (0.5 * h_d) ** 2 - (0.5 * od) ** 2
    )
    free = math.pi * width * (r_os**2 - r_is**2) - v_balls
    oil_volume = settings.oil_volume_m3 or 3.0 * max(free, 0.0)
    oil_rho = spec.lubricant.density_15c_kg_m3
    scale = settings.heat_capacity_scale
    cap = np.array(
        [
            v_shaft * rho * STEEL_SPECIFIC_HEAT_J_KG_K,
            v_inner * rho * STEEL_SPECIFIC_HEAT_J_KG_K,
            v_balls * rho * STEEL_SPECIFIC_HEAT_J_KG_K,
            v_outer * rho * STEEL_SPECIFIC_HEAT_J_KG_K,
            m_housing * CAST_IRON_SPECIFIC_HEAT_J_KG_K,
            oil_volume * oil_rho * OIL_SPECIFIC_HEAT_J_KG_K,
        ]
    )
    return NetworkGeometry(
        bore,
        od,
        width,
        dm,
        dw,
        g.ball_count,
        r_i,
        r_o,
        r_is,
        r_os,
        shaft_len,
        h_d,
        h_w,
        oil_volume,
        oil_rho,
        cap * scale,
    )


@dataclass(frozen=True)
class Operating:
    """What the conductances depend on at one network step."""

    shaft_speed_rad_s: float
    cage_speed_rad_s: float
    ball_spin_rad_s: float
    inner_contact_semi_axes_m: np.ndarray  # (n, 2): a, b of the loaded inner contacts
    outer_contact_semi_axes_m: np.ndarray
    temperature_c: np.ndarray  # node temperatures the film properties are taken at
    ambient_c: float
    oil_kinematic_viscosity_m2_s: float


@dataclass(frozen=True)
class Network:
    """dC T/dt = -K T + G_amb s T_amb + G_sup T_sup + q, K = L + diag(G_amb s + G_sup), L the
    Laplacian of the node-to-node conductances, s the dissipation factor."""

    capacity_j_k: np.ndarray  # (n,) [J/K]
    coupling_w_k: np.ndarray  # (n, n) symmetric node-to-node conductances, zero diagonal [W/K]
    ambient_w_k: np.ndarray  # (n,) to the surroundings, before the dissipation factor [W/K]
    supply_w_k: np.ndarray  # (n,) to the circulating oil supply [W/K]

    def stiffness(self, dissipation_factor: float) -> np.ndarray:
        """K [W/K] at a dissipation factor s."""
        k = -self.coupling_w_k.copy()
        k[np.diag_indices_from(k)] = (
            self.coupling_w_k.sum(axis=1) + self.ambient_w_k * dissipation_factor + self.supply_w_k
        )
        return k

    def time_constants_s(self, dissipation_factor: float = 1.0) -> np.ndarray:
        """The network's time constants tau_i = 1 / lambda_i of C^-1 K, slowest first [s]."""
        lam = np.linalg.eigvals(self.stiffness(dissipation_factor) / self.capacity_j_k[:, None]).real
        return np.sort(1.0 / lam)[::-1]


def coupled_time_constants_s(
    net: Network,
    heat_slope_w_k: float,
    heat_share: np.ndarray,
    inlet_weights: np.ndarray,
    dissipation_factor: float = 1.0,
) -> np.ndarray:
    """Time constants of the network with the friction's feedback, slowest first [s]: the heat
    q = P(T_in) p, P the friction power, p its share per node, T_in = w . T the inlet
    temperature; linearised, C dT/dt = -(K - dP/dT_in p w^T) T + ... A heat falling with the
    temperature (thinner oil, dP/dT_in < 0) shortens them."""
    a = net.stiffness(dissipation_factor) - heat_slope_w_k * np.outer(heat_share, inlet_weights)
    lam = np.linalg.eigvals(a / net.capacity_j_k[:, None]).real
    return np.sort(1.0 / lam)[::-1]


def _link(k: np.ndarray, i: int, j: int, g: float) -> None:
    k[i, j] += g
    k[j, i] += g


def assemble(geo: NetworkGeometry, op: Operating, spec, settings: ThermalNetworkSettings) -> Network:
    """The network's conductances at an operating point (Harris and Kotzalas ch. 7 structure;
    each conductance from twin.thermal.correlations)."""
    coupling = np.zeros((N_NODES, N_NODES))
    ambient = np.zeros(N_NODES)
    supply = np.zeros(N_NODES)
    t = op.temperature_c
    k_s, b = STEEL_CONDUCTIVITY_W_M_K, geo.width_m
    r_bore, r_od = 0.5 * geo.bore_m, 0.5 * geo.outside_diameter_m
    # ring bodies: half a ring's radial shell from its seat to its centre, in series with the fit
    fit_inner = settings.fit_conductance_w_m2_k * 2.0 * math.pi * r_bore * b
    fit_outer = settings.fit_conductance_w_m2_k * 2.0 * math.pi * r_od * b
    mid_inner = 0.5 * (r_bore + geo.inner_shoulder_radius_m)
    mid_outer = 0.5 * (r_od + geo.outer_shoulder_radius_m)
    _link(coupling, SHAFT, INNER_RING, _series(fit_inner, cylindrical_shell_w_k(r_bore, mid_inner, b, k_s)))
    _link(coupling, OUTER_RING, HOUSING, _series(fit_outer, cylindrical_shell_w_k(mid_outer, r_od, b, k_s)))
    # ball-raceway contacts: Hertz constriction of every loaded contact
    g_in = sum(hertz_constriction_w_k(a, bb, k_s) for a, bb in op.inner_contact_semi_axes_m)
    g_out = sum(hertz_constriction_w_k(a, bb, k_s) for a, bb in op.outer_contact_semi_axes_m)
    _link(coupling, INNER_RING, BALLS, g_in)
    _link(coupling, BALLS, OUTER_RING, g_out)
    # surfaces swept by the oil, which turns with the cage (flat-plate analogy, Harris and Kotzalas ch. 7)
    nu = max(op.oil_kinematic_viscosity_m2_s, 1e-7)
    pr = nu * geo.oil_density_kg_m3 * OIL_SPECIFIC_HEAT_J_KG_K / OIL_CONDUCTIVITY_W_M_K
    dm = geo.pitch_diameter_m

    def oil_h(speed_m_s: float, length_m: float) -> float:
        return flat_plate_laminar_w_m2_k(max(abs(speed_m_s), 1e-3), length_m, OIL_CONDUCTIVITY_W_M_K, nu, pr)

    circ = math.pi * dm
    u_inner = (op.shaft_speed_rad_s - op.cage_speed_rad_s) * geo.inner_raceway_radius_m
    u_outer = op.cage_speed_rad_s * geo.outer_raceway_radius_m
    _link(coupling, INNER_RING, OIL, oil_h(u_inner, circ) * 2.0 * math.pi * geo.inner_shoulder_radius_m * b)
    _link(coupling, OUTER_RING, OIL, oil_h(u_outer, circ) * 2.0 * math.pi * geo.outer_shoulder_radius_m * b)
    dw = geo.ball_diameter_m
    _link(coupling, BALLS, OIL, oil_h(0.5 * op.ball_spin_rad_s * dw, math.pi * dw) * geo.ball_count * math.pi * dw * dw)
    # the sump's walls: the housing bore and sides, swept by the oil the cage drags
    sump_area = 2.0 * math.pi * r_od * b + 2.0 * math.pi * (r_od**2 - geo.outer_shoulder_radius_m**2)
    _link(coupling, OIL, HOUSING, oil_h(0.5 * u_outer, circ) * sump_area)
    if settings.oil_supply == "circulating":
        supply[OIL] = geo.oil_density_kg_m3 * OIL_SPECIFIC_HEAT_J_KG_K * settings.oil_flow_m3_s
    amb = op.ambient_c
    if settings.dissipation == "iso_15312":
        g_iso = geo.iso_15312_dissipation_w_k
        ambient[OUTER_RING] = g_iso * geo.outside_diameter_m / (geo.outside_diameter_m + geo.bore_m)
        ambient[INNER_RING] = g_iso * geo.bore_m / (geo.outside_diameter_m + geo.bore_m)
    else:
        h_d, h_w = geo.housing_diameter_m, geo.housing_width_m
        h_area = math.pi * h_d * h_w + 2.0 * math.pi * 0.25 * (h_d**2 - geo.outside_diameter_m**2)
        h_h = churchill_chu_cylinder_w_m2_k(h_d, t[HOUSING], amb) + radiation_w_m2_k(
            settings.housing_emissivity, t[HOUSING], amb
        )
        ambient[HOUSING] = h_h * h_area + settings.housing_frame_conductance_w_k
        s_area = 2.0 * math.pi * geo.bore_m * geo.shaft_length_m
        s_h = max(
            rotating_cylinder_w_m2_k(geo.bore_m, op.shaft_speed_rad_s),
            churchill_chu_cylinder_w_m2_k(geo.bore_m, t[SHAFT], amb),
        )
        ambient[SHAFT] = s_h * s_area + settings.shaft_frame_conductance_w_k
    return Network(geo.capacity_j_k, coupling, ambient, supply)
