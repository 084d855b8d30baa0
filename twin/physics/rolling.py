"""Hydrodynamic rolling force, rolling-resistance moments and mixed-film sliding friction of a
lubricated ball-race contact (seed 001, Biboulet-Houpert laws as used by Balan/Houpert/Olaru).

All functions are scalar, SI in and SI out, and return 0.0 (never NaN) for a zero, negative or
NaN speed or load. Speeds are magnitudes: the caller applies the sign of the rolling direction.

Notation of seed 001 (read with docs/physics.md, "Readings of garbled seed formulas", seed 001 bullet):
  E*  equivalent modulus of the pair, 2.3e11 Pa for steel on steel (seed 001 below eq. 7; it is
      E' = E / (1 - nu^2), the same modulus as seed 000's E');
  Rx  equivalent radius in the rolling direction, Ry transverse;
  k   the RADII RATIO Ry/Rx (seed 001 below eq. 7). Careful: this is NOT the ellipticity
      (Ry/Rx)^(2/pi) that twin.physics.hertz.brewe_hamrock_ellipticity returns; every argument
      named `k_radii_ratio` below wants Ry/Rx itself;
  U = eta0 u / (E* Rx) (eq. 6), W = Q / (E* Rx^2) (eq. 7), u = (v1 + v2)/2 the mean entrainment
      speed of the two surfaces relative to the contact.
"""

import math

from numba import njit

from twin.jit import JIT

_M_SCALE = 6.6  # the 6.6 of seed 001 eqs. 3 and 5
_PIVOT_LARGE_K = 3.0 / 8.0  # seed 001 eq. 10 (long ellipse)
_PIVOT_CIRCLE = 3.0 * math.pi / 16.0  # seed 001 eq. 11 at k = 1 (circular contact)

# Seed 001 eq. A2, Qa/Q = 1 - 1.21 L^0.64 / (1 + 0.37 L^1.26): d(Qa/Q)/dL = 0 where
# 0.64 (1 + 0.37 L^1.26) = 1.26 * 0.37 L^1.26, i.e. L^1.26 = 0.64 / (0.37 (1.26 - 0.64)).
LAMBDA_ASPERITY_FIT_MIN = (0.64 / (0.37 * (1.26 - 0.64))) ** (1.0 / 1.26)  # = 2.2576...


@njit(**JIT)
def speed_parameter_u(eta_pa_s, entrainment_speed_m_s, e_star_pa, rx_m):
    """Dimensionless speed U = eta0 u / (E* Rx) [-] (seed 001 eq. 6, docs/physics.md seed 001 reading).

    eta_pa_s: dynamic viscosity at the contact inlet [Pa s]; entrainment_speed_m_s: u = (v1+v2)/2
    [m/s]; e_star_pa: E* [Pa]; rx_m: Rx [m]. Returns 0.0 if any input is <= 0 or NaN.
    """
    if not (eta_pa_s > 0.0 and entrainment_speed_m_s > 0.0 and e_star_pa > 0.0 and rx_m > 0.0):
        return 0.0
    return eta_pa_s * entrainment_speed_m_s / (e_star_pa * rx_m)


@njit(**JIT)
def load_parameter_w(load_n, e_star_pa, rx_m):
    """Dimensionless load W = Q / (E* Rx^2) [-] (seed 001 eq. 7, docs/physics.md seed 001 reading).

    load_n: normal load Q of the contact [N]. Returns 0.0 if any input is <= 0 or NaN.
    """
    if not (load_n > 0.0 and e_star_pa > 0.0 and rx_m > 0.0):
        return 0.0
    return load_n / (e_star_pa * rx_m * rx_m)


@njit(**JIT)
def rolling_force_ivr_n(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s):
    """Isoviscous-rigid (IVR) hydrodynamic rolling force of one contact [N], fully flooded
    (meniscus at -d/2):  FR_IVR = 2.9766 E* Rx^2 k^0.3316 W^(1/3) U^(2/3)
    (seed 001 eq. 1, Biboulet-Houpert; docs/physics.md seed 001 reading). k = Ry/Rx.

    FR acts on BOTH surfaces of the contact, against their motion; the power it dissipates is
    2 FR u. Returns 0.0 for non-positive / NaN speed, load or properties.
    """
    u_dim = speed_parameter_u(eta_pa_s, entrainment_speed_m_s, e_star_pa, rx_m)
    w_dim = load_parameter_w(load_n, e_star_pa, rx_m)
    if u_dim <= 0.0 or w_dim <= 0.0 or not (k_radii_ratio > 0.0):
        return 0.0
    return 2.9766 * e_star_pa * rx_m * rx_m * k_radii_ratio**0.3316 * w_dim ** (1.0 / 3.0) * u_dim ** (2.0 / 3.0)


@njit(**JIT)
def rolling_force_ehl_n(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s):
    """Elastohydrodynamic (EHL) hydrodynamic rolling force of one contact [N], fully flooded
    (meniscus at about 10 b):  FR_EHL = 7.5826 E* Rx^2 k^0.4055 W^(1/3) U^(3/4)
    (seed 001 eq. 2, Biboulet-Houpert; docs/physics.md seed 001 reading). k = Ry/Rx.

    Returns 0.0 for non-positive / NaN speed, load or properties.
    """
    u_dim = speed_parameter_u(eta_pa_s, entrainment_speed_m_s, e_star_pa, rx_m)
    w_dim = load_parameter_w(load_n, e_star_pa, rx_m)
    if u_dim <= 0.0 or w_dim <= 0.0 or not (k_radii_ratio > 0.0):
        return 0.0
    return 7.5826 * e_star_pa * rx_m * rx_m * k_radii_ratio**0.4055 * w_dim ** (1.0 / 3.0) * u_dim**0.75


@njit(**JIT)
def ehl_parameter_m(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s):
    """IVR-to-EHL transition parameter  M = 0.5549 k^-0.6029 W U^-0.75  [-]
    (seed 001 eq. 4 with the NEGATIVE U exponent of the docs/physics.md reading: it reproduces the
    seed's EHL partitions, e.g. 20-40 % for d = 6.35 mm, Q = 0.125 N). k = Ry/Rx.

    M grows with load and falls with speed (large M = EHL dominated). As u -> 0, M -> infinity,
    but the rolling force itself vanishes there; per the package convention this function
    returns 0.0 for non-positive / NaN speed or load (the zero-speed share is not needed: every
    force it would weight is 0).
    """
    u_dim = speed_parameter_u(eta_pa_s, entrainment_speed_m_s, e_star_pa, rx_m)
    w_dim = load_parameter_w(load_n, e_star_pa, rx_m)
    if u_dim <= 0.0 or w_dim <= 0.0 or not (k_radii_ratio > 0.0):
        return 0.0
    return 0.5549 * k_radii_ratio**-0.6029 * w_dim * u_dim**-0.75


@njit(**JIT)
def ehl_share(m_parameter):
    """EHL partition (M/6.6) / (1 + M/6.6) in [0, 1] (seed 001 eq. 5 and Section 4.4; docs/physics.md).

    The IVR partition is 1 - share. Written as 1 / (1 + 6.6/M) so that M = inf gives 1.0.
    Returns 0.0 for M <= 0 or NaN.
    """
    if not (m_parameter > 0.0):
        return 0.0
    return 1.0 / (1.0 + _M_SCALE / m_parameter)


@njit(**JIT)
def rolling_force_transition_n(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s):
    """Biboulet-Houpert transition rolling force of one contact [N]:
    FR = [FR_IVR + (M/6.6) FR_EHL] / (1 + M/6.6) = (1 - s) FR_IVR + s FR_EHL, s = EHL share
    (seed 001 eqs. 3 and 5 with eqs. 1, 2, 4; docs/physics.md seed 001 reading). k = Ry/Rx.

    The seed recommends it when the EHL share exceeds 50 %; below that (very light load) the pure
    IVR force (eq. 1) matched its measurements better (Sections 4.4-4.5, conclusion).
    Returns 0.0 for non-positive / NaN speed or load.
    """
    f_ivr = rolling_force_ivr_n(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s)
    f_ehl = rolling_force_ehl_n(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s)
    s = ehl_share(ehl_parameter_m(e_star_pa, rx_m, k_radii_ratio, load_n, eta_pa_s, entrainment_speed_m_s))
    return (1.0 - s) * f_ivr + s * f_ehl


HYSTERESIS_LOAD_EXP = 1.33  # exponent of Q in seed 001 eq. 9 (twin.kernels.tribology compiles it)


@njit(**JIT)
def hysteresis_moment_n_m(ball_diameter_m, load_n, k_radii_ratio):
    """Elastic-hysteresis rolling-resistance moment of one ball-race contact [N m]:
    MER = 7.48e-7 (d/2)^0.33 Q^1.33 [1 - 3.519e-3 (k - 1)^0.8063]
    (seed 001 eq. 9, Houpert ref. [1]; docs/physics.md seed 001 reading). k = Ry/Rx >= 1.

    Units: the constant 7.48e-7 is SI -- d in m, Q in N, MER in N m -- so no conversion is
    applied. Evidence: (i) MER has the form of Johnson's hysteresis moment
    alpha (3/16) Q a with a = (3 Q R / (4 E*))^(1/3) ~ Q^(1/3) R^(1/3); for steel in SI the
    prefactor is alpha * 3.49e-5, so 7.48e-7 means a loss factor alpha ~ 0.02 (plausible),
    whereas mm / N mm would mean alpha ~ 2e-4 and mm / N m alpha ~ 2; (ii) with the SI reading the
    seed's Appendix A holds: for d = 3 mm, Q = 0.633 N, 6 r MER / d + 3 MP is a few % of the
    hydrodynamic torque (seed: 5.6 % to 2.6 %), while mm / N mm would make hysteresis ~1000x
    smaller and mm / N m make it a third of the total. For k < 1 the (k - 1) term is taken as 0.
    Returns 0.0 for non-positive / NaN diameter or load.
    """
    if not (ball_diameter_m > 0.0 and load_n > 0.0):
        return 0.0
    km1 = k_radii_ratio - 1.0
    if not (km1 > 0.0):
        km1 = 0.0
    return 7.48e-7 * (0.5 * ball_diameter_m) ** 0.33 * load_n**HYSTERESIS_LOAD_EXP * (1.0 - 3.519e-3 * km1**0.8063)


@njit(**JIT)
def pivoting_moment_n_m(mu_s, load_n, semi_major_axis_m, k_radii_ratio):
    """Pivoting (spin) friction moment of one ball-race contact about the contact normal [N m]:
    MP = [3/8 + (3 pi/16 - 3/8) k^-(0.945 + 0.016 ln k)] mu_s Q a_c
    (seed 001 eq. 11, Houpert ref. [1]; eq. 10 is its large-k limit 3/8 mu_s Q a_c).

    mu_s: mean sliding friction coefficient (e.g. sliding_friction_coefficient_asperity_share);
    load_n: Q [N]; semi_major_axis_m: a_c, MAJOR semi-axis of the Hertz ellipse [m];
    k_radii_ratio: Ry/Rx.
    Reading of the garbled exponent: both signs were lost in extraction; the factor must go from
    3 pi/16 at k = 1 to 3/8 at large k, so the exponent is negative, and -(0.945 + 0.016 ln k)
    reproduces the exact full-sliding result (3/8) E(1 - b^2/a^2) (E the complete elliptic
    integral of the 2nd kind) within 0.25 % for 1 <= k <= 100, against up to 1 % for
    -0.945 + 0.016 ln k. The coefficient depends only on the ellipse aspect, so k < 1 (major
    axis along the rolling direction) is mapped to 1/k. In the seed's tests MP is negligible
    (Appendix A); its torque on the bearing is 3 MP (eq. 14).
    Returns 0.0 for non-positive / NaN mu_s, load, a_c or k.
    """
    if not (mu_s > 0.0 and load_n > 0.0 and semi_major_axis_m > 0.0 and k_radii_ratio > 0.0):
        return 0.0
    k = k_radii_ratio
    if k < 1.0:
        k = 1.0 / k
    factor = _PIVOT_LARGE_K + (_PIVOT_CIRCLE - _PIVOT_LARGE_K) * k ** (-(0.945 + 0.016 * math.log(k)))
    return factor * mu_s * load_n * semi_major_axis_m


@njit(**JIT)
def asperity_load_share(film_parameter_lambda):
    """Share of the normal load carried by asperities, Qa/Q = 1 - 1.21 L^0.64 / (1 + 0.37 L^1.26),
    clipped to [0, 1] (seed 001 eq. A2, from its ref. [6]; docs/physics.md seed 001 reading).

    Validity: the fit is used for L (Lambda, film parameter) up to about 3 and must not be used
    past its minimum, where it rises again (0.013 at L = 3, 0.059 at L = 4, -> 1 as L -> inf,
    which is unphysical: thicker films carry more, not less, of the load). The minimum is at
    L* = (0.64 / (0.37 * 0.62))^(1/1.26) = 2.258 (the "near 3" of docs/physics.md), where the fit is
    -0.003, i.e. 0 after clipping; the fit already crosses 0 at L = 2.013. Choice: for L >= L*
    return 0.0. This is at once "hold the value at its minimum" (the clipped minimum IS 0) and
    "return 0", so the two options of the brief coincide; it keeps Qa/Q continuous and
    non-increasing in L and agrees with the full-film regime (L > 3, seed 000 Table 2).
    L <= 0 (no film) or NaN returns 1.0: the formula's own value at L = 0, all load on asperities.
    """
    lam = film_parameter_lambda
    if not (lam > 0.0):
        return 1.0
    if lam >= LAMBDA_ASPERITY_FIT_MIN:
        return 0.0
    return asperity_load_share_ln(lam, math.log(lam))


@njit(**JIT)
def asperity_load_share_ln(film_parameter_lambda, ln_lambda):
    """`asperity_load_share` (seed 001 eq. A2) given ln Lambda as well: the tribology refresh has
    it from the film's logarithm (twin.kernels.tribology), and saves the logarithm.
    Two exps: cheaper than two general powers."""
    lam = film_parameter_lambda
    if not (lam > 0.0):
        return 1.0
    if lam >= LAMBDA_ASPERITY_FIT_MIN:
        return 0.0
    share = 1.0 - 1.21 * math.exp(0.64 * ln_lambda) / (1.0 + 0.37 * math.exp(1.26 * ln_lambda))
    if share < 0.0:
        return 0.0
    if share > 1.0:
        return 1.0
    return share


@njit(**JIT)
def sliding_friction_coefficient_asperity_share(asperity_share, mu_ehl=0.03, mu_asperity=0.11):
    """Mixed-film sliding friction coefficient mu_s = mu_EHL (1 - Qa/Q) + mu_a Qa/Q [-]
    (seed 001 eq. A1; mu_EHL = 0.03 and mu_a = 0.11 from its ref. [6]; docs/physics.md seed 001 reading).

    asperity_share: Qa/Q from asperity_load_share, clipped to [0, 1]; NaN is treated as 0
    (full film), so the result is never NaN for finite coefficients.
    """
    s = asperity_share
    if not (s > 0.0):
        s = 0.0
    elif s > 1.0:
        s = 1.0
    return mu_ehl * (1.0 - s) + mu_asperity * s
