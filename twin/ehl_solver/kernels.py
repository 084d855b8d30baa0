"""numba kernels of the point-contact EHL solver (dimensionless, Venner & Lubrecht form).

Reynolds (seed 003 eq. 1, X = x/ax, Y = y/ay, P = p/p_h, H = h Rx/ax^2, kappa = ax/ay):
    d/dX(eps dP/dX) + kappa^2 d/dY(eps dP/dY) - d(rho H)/dX = f,
    eps = rho H^3 / (eta lambda),  lambda = 12 eta0 u Rx^2 / (ax^3 p_h)  (seed 003 Psi),
with P = 0 on the boundary and P >= 0 inside (cavitation by the non-negative pressure condition:
a relaxed pressure that would go negative is set to zero). Second-order central Poiseuille
terms (eps averaged at half nodes), hybrid first/second-order upwind wedge term (wedge_weight).

Rheology: Roelands with temperature (seed 003 eq. 3) and Dowson-Higginson density with the
density-temperature term (seed 003 eq. 2). Temperature rise: seed 003 eq. 6 (shear and
compression heating, conduction across the film) plus the current term of eq. 10.

Relaxation (Venner 1991, Venner & Lubrecht 2000): Gauss-Seidel line relaxation along X where
eps/hx^2 >= 0.3 or a neighbour is cavitated (the Poiseuille terms dominate: inlet, outlet,
outside the contact), Jacobi distributive line relaxation elsewhere (the Hertzian zone, where
the equation behaves like the integral equation of dry contact and Gauss-Seidel is unstable),
in zebra order. The line systems keep the influence coefficients within two nodes
(pentadiagonal, solved without pivoting; the Jacobi distributive lines lump the rest of the line
onto the band edges, see relax_jd); changes are under-relaxed and limited per sweep.

Kernels never raise: they return counts (non-finite values, zero pivots) for the driver to check.
"""

import math

import numpy as np
from numba import njit

from twin.jit import JIT
from twin.physics.electrical import dowson_higginson_density_ratio
from twin.physics.thermal import ROELANDS_LN_ETA_INF, ROELANDS_PRESSURE_PA_INV, ROELANDS_T_K

LN_ETA_CAP = 690.0  # exp(690) ~ 1e300: viscosity ratio cap, never reached at physical pressures
# Relaxation keeps 0 <= P <= P_CAP (P = p / p_hertz): a safety net against a transient blow-up on
# a coarse grid; a solution touching it is rejected by the driver.
P_CAP = 20.0


@njit(**JIT)
def roelands_ln_eta_ratio(p_pa, dtheta_k, ln_eta0, z, s0, theta_i_k):
    """ln(eta / eta0) of seed 003 eq. 3:
    (ln eta0 + 9.67) [-1 + (1 + 5.1e-9 p)^z ((theta - 138) / (theta_i - 138))^-S0],
    theta = theta_i + dtheta [K]."""
    p_pa = max(p_pa, 0.0)
    tfac = ((theta_i_k + dtheta_k - ROELANDS_T_K) / (theta_i_k - ROELANDS_T_K)) ** (-s0)
    val = (ln_eta0 + ROELANDS_LN_ETA_INF) * (-1.0 + (1.0 + ROELANDS_PRESSURE_PA_INV * p_pa) ** z * tfac)
    val = min(val, LN_ETA_CAP)
    return val


@njit(**JIT)
def dowson_higginson_rho_bar(p_pa, dtheta_k, dt_rel):
    """rho / rho0 of seed 003 eq. 2: 1 + 0.6e-9 p / (1 + 1.7e-9 p) - (Dt / rho0) dtheta
    (twin.physics.electrical.dowson_higginson_density_ratio, then the thermal term)."""
    return dowson_higginson_density_ratio(p_pa) - dt_rel * dtheta_k


@njit(**JIT)
def shear_temperature_rise_k(h_m, p_pa, u_m_s, theta_i_k, alpha_t, b_m, eta0, k_oil, cap_k):
    """Seed 003 eq. 6: dtheta = [u theta_i alpha' h p + 2 b eta0 u^2 / h] / [b k' / h - u alpha' h p].

    Returns cap_k where the denominator is not positive (conduction cannot carry the heat: the
    linear-profile model has no solution; the driver flags it) or h <= 0."""
    p_pa = max(p_pa, 0.0)
    if h_m <= 0.0:
        return cap_k
    num = u_m_s * theta_i_k * alpha_t * h_m * p_pa + 2.0 * b_m * eta0 * u_m_s * u_m_s / h_m
    den = b_m * k_oil / h_m - u_m_s * alpha_t * h_m * p_pa
    if den <= 0.0:
        return cap_k
    val = num / den
    if val > cap_k:
        return cap_k
    return val


@njit(**JIT)
def temperature_field(p, h, dtheta, p_h, h_scale, u_m_s, theta_i_k, alpha_t, b_m, eta0, k_oil, current_rise_k, cap_k):
    """dtheta[i, j] = eq. 6 (local h, p) + eq. 10 (uniform); returns the number of capped nodes."""
    nx, ny = p.shape
    capped = 0
    for i in range(nx):
        for j in range(ny):
            t = shear_temperature_rise_k(
                h[i, j] * h_scale, p[i, j] * p_h, u_m_s, theta_i_k, alpha_t, b_m, eta0, k_oil, cap_k
            )
            if t >= cap_k:
                capped += 1
            dtheta[i, j] = t + current_rise_k
    return capped


@njit(**JIT)
def update_fields(
    p, h, dtheta, eta, rho, eps, p_h, lam, ln_eta0, z, s0, theta_i_k, dt_rel, barus_alpha, incompressible
):
    """eta_bar, rho_bar and eps = rho H^3 / (eta lambda) on every node; returns #non-finite.
    barus_alpha > 0 replaces Roelands by Barus exp(alpha p) and incompressible=True sets rho_bar = 1
    (the rheology of the Moes/Nijenbanning film formula, used to validate the solver)."""
    nx, ny = p.shape
    bad = 0
    for i in range(nx):
        for j in range(ny):
            pp = p[i, j] * p_h
            if barus_alpha > 0.0:
                lne = min(barus_alpha * max(pp, 0.0), LN_ETA_CAP)
            else:
                lne = roelands_ln_eta_ratio(pp, dtheta[i, j], ln_eta0, z, s0, theta_i_k)
            eta[i, j] = math.exp(lne)
            if incompressible:
                r = 1.0
            else:
                r = dowson_higginson_rho_bar(pp, dtheta[i, j], dt_rel)
            rho[i, j] = r
            hh = h[i, j]
            hh = max(hh, 0.0)
            e = r * hh * hh * hh / (eta[i, j] * lam)
            eps[i, j] = e
            if not (math.isfinite(e) and math.isfinite(hh)):
                bad += 1
    return bad


@njit(**JIT)
def _half(a, b):
    """eps at a half node: arithmetic mean of the two nodes (Venner & Lubrecht)."""
    return 0.5 * (a + b)


@njit(**JIT)
def wedge_weight(eps_node, rx2, xi0, i):
    """Weight w of the second-order upwind part of the wedge term at a node:
    w = xi / (xi + xi0), xi = eps / hx^2 (the ratio of Poiseuille to wedge coefficients, an inverse
    cell Peclet number). xi0 < 0: first-order upwind everywhere; xi0 = 0: second order everywhere.
    The film is formed in the inlet, where xi is large: there the scheme is second-order upwind;
    in the Hertzian zone and at the exit spike (xi -> 0) it falls back to first-order upwind,
    which keeps the relaxation stable and the spike free of wiggles (hybrid scheme)."""
    if xi0 < 0.0 or i < 2:
        return 0.0
    if xi0 == 0.0:
        return 1.0
    xi = eps_node * rx2
    return xi / (xi + xi0)


@njit(**JIT)
def _wedge(rho, h, i, j, rx1, w):
    """d(rho H)/dX at node i: [(1 + w/2) F_i - (1 + w) F_i-1 + (w/2) F_i-2] / hx, F = rho H
    (w = 0 first-order upwind, w = 1 second-order upwind)."""
    val = (1.0 + 0.5 * w) * rho[i, j] * h[i, j] - (1.0 + w) * rho[i - 1, j] * h[i - 1, j]
    if w != 0.0:
        val += 0.5 * w * rho[i - 2, j] * h[i - 2, j]
    return val * rx1


@njit(**JIT)
def _faces(eps, i, j):
    """eps at the four half nodes around node (i, j): (x-, x+, y-, y+), by _half."""
    e = eps[i, j]
    return _half(eps[i - 1, j], e), _half(eps[i + 1, j], e), _half(eps[i, j - 1], e), _half(eps[i, j + 1], e)


@njit(**JIT)
def _operator(p, h, rho, i, j, exm, exp_, eym, eyp, rx2, ry2, rx1, w):
    """L(P) at node (i, j): the discrete Reynolds operator of seed 003 eq. 1 (Poiseuille terms
    with the face coefficients minus the wedge term)."""
    return (
        (exm * (p[i - 1, j] - p[i, j]) + exp_ * (p[i + 1, j] - p[i, j])) * rx2
        + (eym * (p[i, j - 1] - p[i, j]) + eyp * (p[i, j + 1] - p[i, j])) * ry2
        - _wedge(rho, h, i, j, rx1, w)
    )


@njit(**JIT)
def residual(p, h, rho, eps, f, hx, hy, kappa2, xi0, r):
    """r = f - L(P) on interior nodes (0 on the boundary); returns sum |r| over nodes with P > 0."""
    nx, ny = p.shape
    rx2 = 1.0 / (hx * hx)
    ry2 = kappa2 / (hy * hy)
    rx1 = 1.0 / hx
    total = 0.0
    for i in range(nx):
        r[i, 0] = 0.0
        r[i, ny - 1] = 0.0
    for j in range(ny):
        r[0, j] = 0.0
        r[nx - 1, j] = 0.0
    for i in range(1, nx - 1):
        for j in range(1, ny - 1):
            exm, exp_, eym, eyp = _faces(eps, i, j)
            w = wedge_weight(eps[i, j], rx2, xi0, i)
            lp = _operator(p, h, rho, i, j, exm, exp_, eym, eyp, rx2, ry2, rx1, w)
            r[i, j] = f[i, j] - lp
            if p[i, j] > 0.0:
                total += abs(r[i, j])
    return total


@njit(**JIT)
def _band_solve(a, rhs, x, n):
    """Solve a pentadiagonal system in place (a[k, 2 + c - k] = A[k, c]); no pivoting.
    Returns the number of (near-)zero pivots, whose unknowns are set to 0."""
    zero = 0
    for k in range(n):
        piv = a[k, 2]
        if abs(piv) < 1e-300:
            zero += 1
            a[k, 2] = 1.0
            a[k, 3] = 0.0
            a[k, 4] = 0.0
            rhs[k] = 0.0
            piv = 1.0
        for r in range(k + 1, min(k + 3, n)):
            fac = a[r, 2 + k - r] / piv
            if fac != 0.0:
                for c in range(k, min(k + 3, n)):
                    a[r, 2 + c - r] -= fac * a[k, 2 + c - k]
                rhs[r] -= fac * rhs[k]
    for k in range(n - 1, -1, -1):
        s = rhs[k]
        for c in range(k + 1, min(k + 3, n)):
            s -= a[k, 2 + c - k] * x[c]
        x[k] = s / a[k, 2]
    return zero


@njit(**JIT)
def classify(p, eps, hx, xi_lim, kind):
    """kind[i, j] = 1 (Gauss-Seidel) where eps/hx^2 >= xi_lim or a neighbour is cavitated
    (P = 0: a distributive change there would be clipped), 2 (Jacobi distributive) elsewhere;
    0 on the boundary."""
    nx, ny = p.shape
    rx2 = 1.0 / (hx * hx)
    for i in range(nx):
        for j in range(ny):
            kind[i, j] = 0
    for i in range(1, nx - 1):
        for j in range(1, ny - 1):
            e = min(eps[i - 1, j], eps[i, j], eps[i + 1, j])
            gs = 0.5 * (e + eps[i, j]) * rx2 >= xi_lim
            if not gs and (
                p[i, j] <= 0.0 or p[i - 1, j] <= 0.0 or p[i + 1, j] <= 0.0 or p[i, j - 1] <= 0.0 or p[i, j + 1] <= 0.0
            ):
                gs = True
            kind[i, j] = 1 if gs else 2


@njit(**JIT)
def _wedge_jacobian(rho, i, j, rx1, w, kern, o):
    """d(wedge term at node i) / d(change at node i + o) through the film: the influence kernel
    `kern` (a function of the node offset, symmetric) weighted by the wedge stencil."""
    a0 = (1.0 + 0.5 * w) * rho[i, j]
    a1 = -(1.0 + w) * rho[i - 1, j]
    val = a0 * kern[abs(o)] + a1 * kern[abs(o + 1)]
    if w != 0.0:
        val += 0.5 * w * rho[i - 2, j] * kern[abs(o + 2)]
    return val * rx1


@njit(**JIT)
def _wedge_jacobian_lumped(rho, i, j, rx1, w, kern, tail, o):
    """_wedge_jacobian for a band limited to offsets |o| <= 2, with the influence of the changes
    beyond the band lumped onto its edges (o = +-2): tail[k] = sum_{m >= k} kern[m]. The row sum
    of the band is then that of the full line, so a change that is constant along the line gives
    the wedge response of the full operator, sum_o J(o) = (a0 + a1 + a2) sum_m kern: zero for
    constant rho, as d/dX of a uniform film change must be (see relax_jd)."""
    val = _wedge_jacobian(rho, i, j, rx1, w, kern, o)
    if o == 2 or o == -2:
        a0 = (1.0 + 0.5 * w) * rho[i, j]
        a1 = -(1.0 + w) * rho[i - 1, j]
        a2 = 0.5 * w * rho[i - 2, j] if w != 0.0 else 0.0
        if o == 2:  # offsets o >= 3: film at i, i-1, i-2 sees distances o, o+1, o+2
            val += (a0 * tail[3] + a1 * tail[4] + a2 * tail[5]) * rx1
        else:  # offsets o <= -3: distances -o, -o-1, -o-2
            val += (a0 * tail[3] + a1 * tail[2] + a2 * tail[1]) * rx1
    return val


@njit(**JIT)
def relax_gs(p, h, rho, eps, f, hx, hy, kappa2, kc, kind, xi0, omega, max_step, band, rhs, x):
    """One Gauss-Seidel line sweep (lines of constant Y, j = 1 .. ny-2, in order) over the nodes
    of kind 1; Newton linearisation with eps frozen, the film's dependence on the pressures of the
    same line kept within two nodes (pentadiagonal). Changes under-relaxed by omega, limited to
    max_step, P kept in [0, P_CAP]. band (nx, 5), rhs (nx), x (nx) are work arrays.
    Returns the number of zero pivots."""
    nx, ny = p.shape
    rx2 = 1.0 / (hx * hx)
    ry2 = kappa2 / (hy * hy)
    rx1 = 1.0 / hx
    kern = np.empty(6)
    for m in range(6):
        kern[m] = kc[m, 0]
    zero = 0
    n = nx - 2
    for j in range(1, ny - 1):
        any_gs = False
        for i in range(1, nx - 1):
            row = i - 1
            for c in range(5):
                band[row, c] = 0.0
            if kind[i, j] != 1:
                band[row, 2] = 1.0
                rhs[row] = 0.0
                continue
            any_gs = True
            exm, exp_, eym, eyp = _faces(eps, i, j)
            w = wedge_weight(eps[i, j], rx2, xi0, i)
            lp = _operator(p, h, rho, i, j, exm, exp_, eym, eyp, rx2, ry2, rx1, w)
            rhs[row] = f[i, j] - lp
            for o in range(-2, 3):
                k = i + o
                if k < 1 or k > nx - 2:
                    continue
                if o != 0 and kind[k, j] != 1:
                    continue
                if o == 0:
                    pois = -(exm + exp_) * rx2 - (eym + eyp) * ry2
                elif o == -1:
                    pois = exm * rx2
                elif o == 1:
                    pois = exp_ * rx2
                else:
                    pois = 0.0
                band[row, 2 + o] = pois - _wedge_jacobian(rho, i, j, rx1, w, kern, o)
        if not any_gs:
            continue
        zero += _band_solve(band, rhs, x, n)
        for i in range(1, nx - 1):
            d = x[i - 1]
            if d != 0.0:
                d *= omega
                if d > max_step:
                    d = max_step
                elif d < -max_step:
                    d = -max_step
                v = p[i, j] + d
                p[i, j] = min(max(v, 0.0), P_CAP)
    return zero


@njit(**JIT)
def relax_jd(p, h, rho, eps, f, hx, hy, kappa2, kc, kind, xi0, omega, max_step, band, rhs, x, delta, parity):
    """One Jacobi distributive line sweep over the nodes of kind 2: the change delta at (i, j) is
    applied as +delta there and -delta/4 at its four neighbours, which makes the film response
    local (the distributed influence kernel decays like 1/r^3): the smoother of Venner for the
    Hertzian zone. All line systems use the residuals of the same state; the changes are applied
    at the end, under-relaxed by omega and limited to max_step; P kept in [0, P_CAP].
    parity 0 / 1 relaxes only the even / odd lines (zebra ordering: the driver calls both with a
    film update in between, which damps the mode that alternates from line to line; plain line
    Jacobi amplifies it on fine grids), parity -1 all lines. Returns the number of zero pivots."""
    nx, ny = p.shape
    rx2 = 1.0 / (hx * hx)
    ry2 = kappa2 / (hy * hy)
    rx1 = 1.0 / hx
    # distributive kernel along the line: Kt(m) = K(m,0) - (K(m-1,0) + K(m+1,0) + 2 K(m,1)) / 4
    # Its tail beyond the pentadiagonal band is lumped onto the band edges (tail[k] = sum over
    # m >= k): truncated, the band's row sum is (Kt(2) - Kt(3)) / hx < 0 instead of 0, so for a
    # change constant along the line (theta_x -> 0) the line model has the opposite sign of the
    # Poiseuille terms that are the operator's only response there, and a mode smooth in X and
    # alternating from line to line grows wherever 0 < eps/hx^2 < ~5e-3 (the exit side of the
    # Hertzian zone on fine grids: local Fourier analysis, growth 1 + 4 omega xi hx^2 /
    # (hy^2 (Kt(3) - Kt(2)) / hx) per sweep). Lumped, that row sum is exact (0 at constant rho).
    nk = kc.shape[0] - 1
    kt = np.empty(nk)
    for m in range(nk):
        kt[m] = kc[m, 0] - 0.25 * (kc[abs(m - 1), 0] + kc[m + 1, 0] + 2.0 * kc[m, 1])
    tail = np.zeros(6)
    acc = 0.0
    for m in range(nk - 1, 0, -1):
        acc += kt[m]
        if m <= 5:
            tail[m] = acc
    zero = 0
    n = nx - 2
    for i in range(nx):
        for j in range(ny):
            delta[i, j] = 0.0
    for j in range(1, ny - 1):
        if parity >= 0 and j % 2 != parity:
            continue
        any_jd = False
        for i in range(1, nx - 1):
            row = i - 1
            for c in range(5):
                band[row, c] = 0.0
            if kind[i, j] != 2:
                band[row, 2] = 1.0
                rhs[row] = 0.0
                continue
            any_jd = True
            exm, exp_, eym, eyp = _faces(eps, i, j)
            s = (exm + exp_) * rx2 + (eym + eyp) * ry2
            w = wedge_weight(eps[i, j], rx2, xi0, i)
            lp = _operator(p, h, rho, i, j, exm, exp_, eym, eyp, rx2, ry2, rx1, w)
            rhs[row] = f[i, j] - lp
            for o in range(-2, 3):
                k = i + o
                if k < 1 or k > nx - 2:
                    continue
                if o != 0 and kind[k, j] != 2:
                    continue
                if o == 0:
                    pois = -1.25 * s
                elif o == -1:
                    pois = exm * rx2 + 0.25 * s
                elif o == 1:
                    pois = exp_ * rx2 + 0.25 * s
                elif o == -2:
                    pois = -0.25 * exm * rx2
                else:
                    pois = -0.25 * exp_ * rx2
                band[row, 2 + o] = pois - _wedge_jacobian_lumped(rho, i, j, rx1, w, kt, tail, o)
        if not any_jd:
            continue
        zero += _band_solve(band, rhs, x, n)
        for i in range(1, nx - 1):
            delta[i, j] = x[i - 1]
    for i in range(1, nx - 1):
        for j in range(1, ny - 1):
            d = delta[i, j]
            if d == 0.0:
                continue
            d *= omega
            if d > max_step:
                d = max_step
            elif d < -max_step:
                d = -max_step
            p[i, j] += d
            q = 0.25 * d
            if i - 1 >= 1:
                p[i - 1, j] -= q
            if i + 1 <= nx - 2:
                p[i + 1, j] -= q
            if j - 1 >= 1:
                p[i, j - 1] -= q
            if j + 1 <= ny - 2:
                p[i, j + 1] -= q
    for i in range(nx):
        for j in range(ny):
            if p[i, j] < 0.0:
                p[i, j] = 0.0
            elif p[i, j] > P_CAP:
                p[i, j] = P_CAP
    return zero


@njit(**JIT)
def natural_residual(p, h, rho, eps, r, hx, hy, kappa2, kc, xi0):
    """sum |max(0, P + r/d) - P| over interior nodes, d the diagonal of the first-order Jacobian:
    the pressure change one Newton step would make, with the cavitation condition respected.
    Scale-free (pressure units), unlike |r|, which is huge where eps/h^2 is huge."""
    nx, ny = p.shape
    rx2 = 1.0 / (hx * hx)
    ry2 = kappa2 / (hy * hy)
    rx1 = 1.0 / hx
    total = 0.0
    for i in range(1, nx - 1):
        for j in range(1, ny - 1):
            exm, exp_, eym, eyp = _faces(eps, i, j)
            w = wedge_weight(eps[i, j], rx2, xi0, i)
            d = (
                -(exm + exp_) * rx2
                - (eym + eyp) * ry2
                - (
                    (1.0 + 0.5 * w) * rho[i, j] * kc[0, 0]
                    - (1.0 + w) * rho[i - 1, j] * kc[1, 0]
                    + 0.5 * w * rho[i - 2, j] * kc[2, 0]
                )
                * rx1
            )
            if d == 0.0:
                continue
            q = p[i, j] + r[i, j] / d
            q = max(q, 0.0)
            total += abs(q - p[i, j])
    return total
