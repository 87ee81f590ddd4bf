"""nystrom.smoluchowski and nystrom.thermal from Python, against closed forms: the Ornstein-Uhlenbeck transition
density, the Boltzmann density of the double well, the harmonic oscillator's primitive-approximation partition
function Z_N = 1 / (2 sinh(N asinh(beta / 2N))) and its exact Z = 1 / (2 sinh(beta / 2)); the same defaults and
refusals as the command line."""
import doctest
import math

import numpy as np
import pytest

import nystrom

pytestmark = pytest.mark.skipif(not hasattr(nystrom._core, "smoluchowski"), reason="module built without FFTW")


def test_ornstein_uhlenbeck_moments_and_order():
    errors = []
    for n in (4, 8, 16):
        res = nystrom.smoluchowski("harmonic", grid=128, box=12.0, beta=2.0, diffusion=0.5, x0=1.0, width=0.3,
                                   method="M4", dt=1.0 / n, steps=n)
        errors.append(res.exact_error)
    decay = math.exp(-1.0)
    assert res.exact_solution == "Ornstein-Uhlenbeck"
    assert abs(res.mean[0] - decay) < 1e-6
    assert abs(res.variance[0] - (0.09 * decay ** 2 + (1 - decay ** 2) / 2)) < 1e-6
    assert 3.6 < math.log2(errors[-2] / errors[-1]) < 4.4
    assert res.density.shape == (128,) and res.density.dtype == np.float64


def test_double_well_density_relaxes_to_boltzmann():
    res = nystrom.smoluchowski(x0=-1.0, width=0.2, dt=0.01, steps=4000)
    x = -3.0 + np.arange(64) * (6.0 / 64)
    rb = np.exp(-(x * x - 1) ** 2)
    rb /= rb.sum() * (6.0 / 64)
    assert np.abs(res.density - rb).sum() * (6.0 / 64) < 1e-7
    assert np.allclose(res.boltzmann, rb, atol=1e-14)
    assert abs(res.mass - 1) < 1e-7


def test_defaults_are_the_command_lines():
    res = nystrom.smoluchowski()
    assert res.method == "M8" and res.dt == 0.01 and res.steps == 100
    assert res.density.shape == (64,)
    assert math.isfinite(res.kramers_rate) and len(res.rates) == 0
    th = nystrom.thermal()
    assert list(th.beads) == [4, 8, 16] and th.order == 6 and th.beta == 1.0


def test_user_density_and_potential_values():
    x = -3.0 + np.arange(64) * (6.0 / 64)
    rho0 = np.exp(-(x + 1) ** 2 / (2 * 0.2 ** 2))
    a = nystrom.smoluchowski(x0=-1.0, width=0.2, steps=20)
    b = nystrom.smoluchowski(rho0=3 * rho0, potential_values=(x * x - 1) ** 2, steps=20)
    assert abs(a.mean[0] - b.mean[0]) < 1e-9
    assert math.isnan(b.kramers_rate)


@pytest.mark.parametrize("kwargs,words", [
    ({"method": "FR"}, "M4..M16"),
    ({"method": "KL8"}, "not positive"),
    ({"beta": 0.0}, "beta"),
    ({"potential": "morse"}, "unknown potential"),
    ({"width": 5.0}, "does not resolve"),
    ({"rho0": -np.ones(64)}, "not negative"),
])
def test_refusals_are_one_line_value_errors(kwargs, words):
    with pytest.raises(ValueError) as e:
        nystrom.smoluchowski(**kwargs)
    assert words in str(e.value) and "\n" not in str(e.value)


def test_thermal_closed_forms_and_order():
    res = nystrom.thermal("harmonic", beta=2.0, beads=[2, 4, 8, 16], extrapolate=[1, 2])
    n = res.beads.astype(float)
    z_primitive = 1 / (2 * np.sinh(n * np.arcsinh(1 / n)))
    assert np.allclose(res.z_primitive, z_primitive, rtol=1e-12, atol=0)
    assert abs(res.z_exact * 2 * math.sinh(1.0) - 1) < 1e-12
    err = np.abs(res.z_extrapolated / res.z_exact - 1)
    assert 3.7 < math.log2(err[-2] / err[-1]) < 4.3
    assert res.order == 4


@pytest.mark.parametrize("kwargs", [{"beta": -1.0}, {"beads": [0]}, {"extrapolate": [2, 2]}, {"grid": 2000},
                                    {"potential": "nowhere"}])
def test_thermal_refusals(kwargs):
    with pytest.raises(ValueError):
        nystrom.thermal(**kwargs)


def test_docstring_examples():
    import nystrom._diffusion as module
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted >= 3
