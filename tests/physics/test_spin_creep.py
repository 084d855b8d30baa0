"""The spin-sliding relaxation constant of the tangential spring (twin.kernels.step.
SPIN_CREEP_FACTOR): a Hertz ellipse spinning at w_s relative to its race slides everywhere
(Coulomb traction mu p v/|v|); a small extra slip v then adds the force
F = -(mu Q / (|w_s| sqrt(a b))) M v. M follows from integrating the linearised traction over the
Hertz pressure (for a circle M = 3 pi / 8; Johnson, Contact Mechanics, ch. 8, full-slip spin)."""

import math

import pytest
from scipy import integrate

from twin.kernels.step import SPIN_CREEP_FACTOR


def _tensor(k):
    """M for an ellipse a = sqrt(k) (across, y), b = 1/sqrt(k) (rolling, x): (M_xx, M_yy)."""
    a, b = math.sqrt(k), 1.0 / math.sqrt(k)

    def term(i):
        def f(s, t):
            x, y = b * s * math.cos(t), a * s * math.sin(t)
            r = math.hypot(x, y)
            tangent = (-y / r, x / r)
            # d(v/|v|)/dv at v = w x r: (I - t t^T) / (w r), Hertz pressure weight 3/(2 pi) sqrt(1 - s^2)
            return 1.5 / math.pi * math.sqrt(1.0 - s * s) * (1.0 - tangent[i] ** 2) / r * s

        return integrate.dblquad(f, 0.0, 2.0 * math.pi, 0.0, 1.0)[0]

    return term(0), term(1)


def test_circle_is_three_pi_over_eight():
    mxx, myy = _tensor(1.0)
    assert mxx == pytest.approx(3 * math.pi / 8, rel=1e-6)
    assert myy == pytest.approx(3 * math.pi / 8, rel=1e-6)


def test_factor_lies_in_the_across_range_of_bearing_contacts():
    # ball-raceway contacts have k = 4-15; across the major axis (the lateral direction in which a
    # ball moves to a new contact angle) M = 1.20-1.38, along the rolling direction 0.39-0.72
    across = [_tensor(k)[1] for k in (4.0, 7.0, 9.4, 15.0)]
    assert min(across) > 1.19 and max(across) < 1.39
    assert min(across) <= SPIN_CREEP_FACTOR <= max(across)


def test_linearisation_against_the_full_coulomb_integral():
    # a lateral slip of 1 % of w_s sqrt(a b) on a k = 9.4 ellipse: the exact mu p v/|v| integral
    # against the linear law with M_yy
    k = 9.4
    a, b = math.sqrt(k), 1.0 / math.sqrt(k)
    v = 0.01

    def f(s, t):
        x, y = b * s * math.cos(t), a * s * math.sin(t)
        vx, vy = -y, x + v  # w_s = 1 about the normal, extra slip v across (y)
        return 1.5 / math.pi * math.sqrt(1.0 - s * s) * vy / math.hypot(vx, vy) * s

    force = integrate.dblquad(f, 0.0, 2.0 * math.pi, 0.0, 1.0, epsabs=1e-10)[0]
    assert force == pytest.approx(_tensor(k)[1] * v, rel=0.02)
