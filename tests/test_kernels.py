"""Closed-form element integrals of the log and sign kernels against adaptive quadrature."""

import numpy as np
import pytest
from scipy.integrate import quad

from rolling_cli.model.kernels import log_moments, sign_moments

POINTS = [-7.5, -2.0001, -2.0, -1.0, -2 / 3, -0.3, 0.0, 2 / 3, 1.0, 1.5, 2.0001, 40.0]


@pytest.mark.parametrize("c", POINTS)
def test_log_moments(c):
    got = log_moments(np.array([c]))[0]
    for m in range(3):
        breaks = [c] if -1.0 < c < 1.0 else None
        ref, err = quad(lambda x: x**m * np.log(abs(x - c)) if x != c else 0.0, -1, 1, points=breaks, limit=400)
        # quad's own error estimate plus round-off of O(1) terms
        assert got[m] == pytest.approx(ref, abs=max(10 * err, 1e-13))


@pytest.mark.parametrize("c", POINTS)
def test_sign_moments(c):
    got = sign_moments(np.array([c]))[0]
    for m in range(3):
        ref = quad(lambda x: x**m * np.sign(c - x), -1, 1, points=[c] if -1 < c < 1 else None)[0]
        assert got[m] == pytest.approx(ref, abs=1e-13)
