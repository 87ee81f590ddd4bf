"""Bad input gets ValueError/TypeError with a one-line message; exceptions of the force propagate unchanged."""
import math

import numpy as np
import pytest

import nystrom
from nystrom.problems import Kepler, NBody


def f(t, q):
    return -q


def one_line(exc):
    msg = str(exc.value)
    assert msg and "\n" not in msg
    return msg


@pytest.mark.parametrize("kwargs,exc,match", [
    (dict(q0=[1.0, 0.0], v0=[0.0]), ValueError, "shape"),
    (dict(q0=[1.0, np.nan], v0=[0.0, 1.0]), ValueError, "NaN"),
    (dict(q0=[1.0, 0.0], v0=[0.0, np.inf]), ValueError, "NaN or infinite"),
    (dict(q0=[], v0=[]), ValueError, "empty"),
    (dict(q0=["a"], v0=[0.0]), TypeError, "real numbers"),
    (dict(q0=[1j], v0=[0.0]), TypeError, "real numbers"),
    (dict(method="NoSuchMethod"), ValueError, "unknown method"),
    (dict(method=3), TypeError, "method"),
    (dict(rtol=-1.0, method="M8"), ValueError, "rtol"),
    (dict(rtol=math.nan, method="M8"), ValueError, "rtol"),
    (dict(atol=-1.0, method="M8"), ValueError, "atol"),
    (dict(atol=math.nan, method="M8"), ValueError, "atol"),
    (dict(rtol=0.0, method="M8"), ValueError, "rtol"),
    (dict(rtol=0.0, atol=0.0, method="M8"), ValueError, "must not both be 0"),
    (dict(rtol="x", method="M8"), TypeError, "rtol"),
    (dict(h=0.1, steps=10), ValueError, "either h or steps"),
    (dict(h=-0.1), ValueError, "h must be positive"),
    (dict(steps=0), ValueError, "steps"),
    (dict(steps=10, rtol=1e-8), ValueError, "exclude"),
    (dict(method="FR"), ValueError, "fixed steps"),
    (dict(method="FR", rtol=1e-8), ValueError, ""),
    (dict(t_span=(0.0, math.inf)), ValueError, "finite"),
    (dict(t_span=5), ValueError, "pair"),
    (dict(t_eval=[0.5, 0.2]), ValueError, "increasing"),
    (dict(t_eval=[2.0]), ValueError, "inside t_span"),
    (dict(t_span=(1.0, 0.0), t_eval=[0.2, 0.5]), ValueError, "decreasing"),
    (dict(method="DP12-adaptive"), ValueError, "tolerance"),
    (dict(precision="dd"), ValueError, "built-in problems"),
    (dict(method="Chambers", rtol=1e-8), ValueError, "real coefficients"),
    (dict(progress="yes"), TypeError, "progress"),
])
def test_bad_arguments(kwargs, exc, match):
    args = dict(q0=[1.0, 0.0], v0=[0.0, 1.0], t_span=(0.0, 1.0), method="M8", steps=10)
    if "rtol" in kwargs or "atol" in kwargs or "h" in kwargs:
        args.pop("steps")
    if kwargs.get("method") == "FR" and "rtol" not in kwargs:
        args.pop("steps")
    args.update(kwargs)
    with pytest.raises(exc, match=match) as e:
        nystrom.solve(f, **args)
    one_line(e)


def test_force_returning_the_wrong_shape_or_type():
    with pytest.raises(ValueError, match=r"shape \(3,\) for q of shape \(2,\)") as e:
        nystrom.solve(lambda t, q: np.zeros(3), [1.0, 0.0], [0.0, 1.0], t_span=(0, 1), steps=10)
    one_line(e)
    with pytest.raises(TypeError, match="array of numbers"):
        nystrom.solve(lambda t, q: None, [1.0, 0.0], [0.0, 1.0], t_span=(0, 1), steps=10)
    with pytest.raises((TypeError, ValueError)):
        nystrom.solve(lambda t, q: "ab", [1.0, 0.0], [0.0, 1.0], t_span=(0, 1), steps=10)


class Boom(Exception):
    pass


def test_force_exception_propagates_unchanged():
    calls = [0]
    err = Boom("from the force")

    def force(t, q):
        calls[0] += 1
        if calls[0] == 7:
            raise err
        return -q

    for kw in (dict(steps=100), dict(rtol=1e-8)):
        calls[0] = 0
        with pytest.raises(Boom) as e:
            nystrom.solve(force, [1.0], [0.0], t_span=(0, 1), method="M8", **kw)
        assert e.value is err
        assert calls[0] == 7


def blow_up(t, q):
    with np.errstate(over="ignore", invalid="ignore"):
        return q ** 3


def test_nan_during_the_integration_is_reported_with_the_states_before_it():
    # a = q^3 blows up in finite time (near t = 1.3 from q = v = 1): the run stops with status -1 and a message,
    # no garbage; the states saved before the failure are those of a run that stops earlier (the same steps).
    res = nystrom.solve(blow_up, [1.0], [1.0], t_span=(0, 10.0), method="FR", steps=1000)
    assert res.status == -1 and not res.success
    assert "NaN" in res.message
    k = len(res.t)
    assert k >= 50 and res.q.shape == (k, 1) and res.v.shape == (k, 1)
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.v)) and res.t[-1] < 10.0
    assert np.allclose(res.t, 0.01 * np.arange(k), rtol=0, atol=1e-12)
    ok = nystrom.solve(blow_up, [1.0], [1.0], t_span=(0, res.t[-1]), method="FR", steps=k - 1)
    assert ok.success and np.allclose(ok.q, res.q, rtol=1e-12, atol=0) and np.allclose(ok.v, res.v, rtol=1e-12, atol=0)


def test_adaptive_failure_is_reported_in_status_with_the_states_before_it():
    # An orbit that falls into the centre (zero angular momentum): the step size underflows; the states
    # returned fall in towards the centre until then.
    res = nystrom.solve(Kepler(0.0), q0=[1.0, 0.0], v0=[0.0, 0.0], t_span=(0, 10.0), method="DP12-adaptive",
                        rtol=1e-12)
    assert res.status == -1 and "underflow" in res.message
    r = np.linalg.norm(res.q, axis=1)
    assert len(res.t) > 2 and r[0] == 1.0 and np.all(np.diff(r) < 0) and np.all(np.diff(res.t) > 0)
    # radial infall from rest at r = 1 reaches the centre at t = pi / (2 sqrt 2) (Kepler's third law)
    assert res.t[-1] <= math.pi / (2 * math.sqrt(2))
    assert np.all(np.isfinite(res.q)) and np.all(np.isfinite(res.v))


def test_too_many_steps_returns_the_prefix_of_the_full_run():
    prob = Kepler(0.5)
    full = nystrom.solve(prob, t_span=(0, 20.0), method="DP12-adaptive", rtol=1e-10)
    cut = nystrom.solve(prob, t_span=(0, 20.0), method="DP12-adaptive", rtol=1e-10, max_steps=20)
    assert full.success and cut.status == -1 and "steps" in cut.message
    k = len(cut.t)
    assert 2 <= k <= 21 and k < len(full.t)
    assert np.array_equal(cut.t, full.t[:k]) and np.array_equal(cut.q, full.q[:k]) and np.array_equal(cut.v, full.v[:k])
    assert cut.sol is None and cut.q_str == []


def test_problem_arguments():
    with pytest.raises(ValueError, match="eccentricity"):
        Kepler(1.0)
    with pytest.raises(TypeError):
        Kepler("0.5")
    sim = NBody()
    with pytest.raises(ValueError, match="no particles"):
        nystrom.solve(sim, t_span=(0, 1), steps=10)
    with pytest.raises(ValueError, match="mass"):
        sim.add(m=-1.0)
    with pytest.raises(ValueError, match="shape"):
        nystrom.solve(Kepler(0.5), q0=[1.0, 0.0, 0.0], t_span=(0, 1), steps=10)
    with pytest.raises(ValueError, match="double only"):
        nystrom.solve(NBody(masses=[1.0, 1.0]), t_span=(0, 1), steps=10, precision="dd")
    with pytest.raises(ValueError, match="double only"):
        nystrom.solve(Kepler(0.5), t_span=(0, 1), steps=10, method="Chambers", precision="dd")
    with pytest.raises(ValueError, match="unknown precision"):
        nystrom.solve(Kepler(0.5), t_span=(0, 1), steps=10, precision="octuple")
    with pytest.raises(TypeError, match="force must be"):
        nystrom.solve(42, [1.0], [0.0], t_span=(0, 1), steps=10)


def test_coeffs_errors():
    with pytest.raises(ValueError, match="unknown method"):
        nystrom.coeffs("NoSuchMethod")
    with pytest.raises(ValueError):
        nystrom.coeffs("VV", seq=[1, 2])


@pytest.mark.parametrize("force,got", [
    (lambda t, q: -q.T, "(3, 2)"),             # the transpose: the right size, coordinates mixed up
    (lambda t, q: -q.reshape(-1), "(6,)"),     # flattened
    (lambda t, q: -q[None], "(1, 2, 3)"),
])
def test_force_returning_another_shape_of_the_same_size_is_refused(force, got):
    q0 = np.arange(1.0, 7.0).reshape(2, 3)
    with pytest.raises(ValueError) as e:
        nystrom.solve(force, q0, np.zeros((2, 3)), t_span=(0, 1), method="M4", steps=10)
    assert one_line(e) == (f"force(t, q) returned an array of shape {got} for q of shape (2, 3): it must return "
                           "q's shape")


@pytest.mark.parametrize("method", ["M8", "FR", "DP12", "KL8", "mpe:1,2,3", "Chambers"])
@pytest.mark.parametrize("built_in", [False, True])
def test_fixed_step_method_without_h_or_steps_is_refused(method, built_in):
    # never switched silently to an adaptive form: the C++ solve()'s error, with the method's name
    args = (Kepler(0.5),) if built_in else (f, [1.0, 0.0], [0.0, 1.0])
    with pytest.raises(ValueError) as e:
        nystrom.solve(*args, t_span=(0, 1), method=method)
    msg = one_line(e)
    assert msg.endswith("runs with fixed steps: a fixed-step method needs a positive step size h or a number of "
                        "steps")
    assert msg.startswith("method '")


def test_a_tolerance_still_selects_the_adaptive_form_of_a_multi_product_method():
    res = nystrom.solve(Kepler(0.5), t_span=(0, 1), method="M8", rtol=1e-10)
    assert res.method == "M8-adaptive" and res.h is None
    res = nystrom.solve(Kepler(0.5), t_span=(0, 1), method="DP12-adaptive")  # adaptive: default rtol
    assert res.success


@pytest.mark.parametrize("kw", [dict(steps=10**9), dict(h=1e-9)])
def test_every_step_output_that_cannot_fit_in_memory_is_refused_up_front(kw):
    import time

    start = time.monotonic()
    with pytest.raises(ValueError, match="GB, more than this machine's") as e:
        nystrom.solve(Kepler(0.5), t_span=(0, 1), method="M8", **kw)
    one_line(e)
    assert time.monotonic() - start < 5  # refused before the run, not after allocating
    # with output times only, the same run needs no such memory: it is not refused up front
    nystrom.solve(Kepler(0.5), t_span=(0, 1e-6), method="VV", steps=10, t_eval=[1e-6])


def test_catalog_arguments_out_of_range_get_one_line_errors():
    with pytest.raises(ValueError, match="MPE sequence member too large: 10+$") as e:
        nystrom.coeffs("mpe", seq=[10**30])
    one_line(e)
    with pytest.raises(ValueError, match="positive") as e:
        nystrom.coeffs("mpe", seq=[-(10**30)])
    with pytest.raises(TypeError, match="sequence of integers") as e:
        nystrom.coeffs("mpe", seq="123")  # a string is not read as [1, 2, 3]
    one_line(e)
    with pytest.raises(TypeError, match="sequence of integers"):
        nystrom.coeffs("mpe", seq=[1.5, 2])
    with pytest.raises(ValueError, match=r"degree must be between 1 and \d+, got 1099511627776") as e:
        nystrom.bch("FR", degree=2**40)
    one_line(e)
    with pytest.raises(ValueError, match="bits must be between 64 and 4096") as e:
        nystrom.bch("FR", bits=2**70)
    with pytest.raises(ValueError, match="digits must be between 1 and 1000"):
        nystrom.coeffs("FR", digits=10**20)
    with pytest.raises(ValueError, match="n must be between"):
        nystrom.coeffs("mpe", n=2**40, sum=10)
    for call in (lambda: nystrom.coeffs("mpe", seq=[10**30]), lambda: nystrom.bch("FR", degree=2**40)):
        with pytest.raises(Exception) as e:
            call()
        assert "Invoked with" not in str(e.value) and "incompatible" not in str(e.value)
