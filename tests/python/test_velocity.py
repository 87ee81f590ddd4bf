"""Velocity-dependent forces force(t, q, v) and first-order systems (nystrom.solve_ivp): GBS and the general RKN
pairs (DOP853, Fine's) against exact solutions (positions and velocities, both directions), the Arenstorf orbit, events and dense output on a
first-order system, and the one-line refusal of the other methods (the C++ solve()'s text)."""
import math

import numpy as np
import pytest

import nystrom

MU = 0.012277471
Q0 = [0.994, 0.0]
V0 = [0.0, -2.00158510637908252240537862224]
T_ARENSTORF = 17.0652165601579625588917206249

W0, GAMMA, F, W = 2.0, 0.15, 0.7, 1.3


def arenstorf(t, q, v):
    d1 = ((q[0] + MU) ** 2 + q[1] ** 2) ** 1.5
    d2 = ((q[0] - 1 + MU) ** 2 + q[1] ** 2) ** 1.5
    return np.array([q[0] + 2 * v[1] - (1 - MU) * (q[0] + MU) / d1 - MU * (q[0] - 1 + MU) / d2,
                     q[1] - 2 * v[0] - (1 - MU) * q[1] / d1 - MU * q[1] / d2])


def damped(t, q, v):
    return F * math.cos(W * t) - 2 * GAMMA * v - W0 ** 2 * q


def damped_exact(q0, v0, t):
    w2, g2w = W0 ** 2 - W ** 2, 2 * GAMMA * W
    d = w2 ** 2 + g2w ** 2
    a, b = F * w2 / d, F * g2w / d
    wd = math.sqrt(W0 ** 2 - GAMMA ** 2)
    c1 = q0 - a
    c2 = (v0 - b * W + GAMMA * c1) / wd
    e, c, s = math.exp(-GAMMA * t), math.cos(wd * t), math.sin(wd * t)
    q = a * math.cos(W * t) + b * math.sin(W * t) + e * (c1 * c + c2 * s)
    v = -a * W * math.sin(W * t) + b * W * math.cos(W * t) + e * (-GAMMA * (c1 * c + c2 * s) + wd * (-c1 * s + c2 * c))
    return q, v


def test_damped_oscillator_matches_the_exact_solution_both_directions():
    res = nystrom.solve(damped, [1.0], [0.0], t_span=(0, 8), method="GBS", rtol=1e-11)
    q, v = damped_exact(1.0, 0.0, 8.0)
    assert abs(res.q[-1][0] - q) < 1e-9
    assert abs(res.v[-1][0] - v) < 1e-9
    back = nystrom.solve(damped, [q], [v], t_span=(8, 0), method="GBS", rtol=1e-11)
    assert back.t[-1] == 0
    assert abs(back.q[-1][0] - 1.0) < 1e-8
    assert abs(back.v[-1][0]) < 1e-8


def test_arenstorf_closes_after_one_period():
    res = nystrom.solve(arenstorf, Q0, V0, t_span=(0, T_ARENSTORF), method="GBS", rtol=1e-12)
    assert np.hypot(res.q[-1][0] - Q0[0], res.q[-1][1]) < 1e-8
    assert res.force_evals > 0


@pytest.mark.parametrize("method", ["DOP853", "Fine5-adaptive", "mpe-midpoint-adaptive:1,2,3,4"])
def test_adaptive_pairs_both_directions_and_on_a_first_order_system(method):
    res = nystrom.solve(damped, [1.0], [0.0], t_span=(0, 8), method=method, rtol=1e-11)
    q, v = damped_exact(1.0, 0.0, 8.0)
    assert abs(res.q[-1][0] - q) < 1e-9
    assert abs(res.v[-1][0] - v) < 1e-9
    back = nystrom.solve(damped, [q], [v], t_span=(8, 0), method=method, rtol=1e-11)
    assert back.t[-1] == 0
    assert abs(back.q[-1][0] - 1.0) < 1e-8
    assert abs(back.v[-1][0]) < 1e-8
    info = nystrom.method_info(method)
    assert info["velocity"] and info["adaptive"]
    # y' = -y + cos t as a first-order system (scipy's convention), against its exact solution.
    r = nystrom.solve_ivp(lambda t, y: -y + np.cos(t), (0, 5), [1.0], method=method, rtol=1e-10, atol=1e-10)
    exact = 0.5 * (np.cos(5.0) + np.sin(5.0)) + 0.5 * np.exp(-5.0)
    assert r.success
    assert abs(r.y[0, -1] - exact) < 1e-8


def test_a_tolerance_selects_the_adaptive_midpoint_expansion():
    res = nystrom.solve(damped, [1.0], [0.0], t_span=(0, 8), method="mpe-midpoint:1,2,3", rtol=1e-10)
    assert res.method == "mpe-midpoint-adaptive:1,2,3" and res.h is None
    q, v = damped_exact(1.0, 0.0, 8.0)
    assert abs(res.q[-1][0] - q) < 1e-8 and abs(res.v[-1][0] - v) < 1e-8
    # Without a tolerance it runs with fixed steps, and needs them.
    fixed = nystrom.solve(damped, [1.0], [0.0], t_span=(0, 8), method="mpe-midpoint:1,2,3", steps=80)
    assert fixed.method == "mpe-midpoint:1,2,3" and fixed.force_evals == 80 * 10


def test_other_methods_are_refused_with_the_libraries_line():
    for method, kw in (("M8", dict(steps=100)), ("DP12-adaptive", dict(rtol=1e-8))):
        name = nystrom.method_info(method)["name"]
        with pytest.raises(ValueError) as e:
            nystrom.solve(arenstorf, Q0, V0, t_span=(0, 1), method=method, **kw)
        assert str(e.value) == (f"method '{name}' does not support velocity-dependent forces a(t, q, v); "
                                "methods that do: DOP853-adaptive, Fine4-adaptive, Fine5-adaptive, GBS, "
                                "mpe-midpoint:K1,K2,..., mpe-midpoint-adaptive:K1,K2,...")


def test_solve_ivp_dense_output_and_events():
    def fun(t, y):  # y1'' + y1 = cos t: y1 = cos t + t sin t / 2
        return np.array([y[1], -y[0] + math.cos(t)])

    def crossing(t, y):
        return y[0]

    crossing.direction = -1
    res = nystrom.solve_ivp(fun, (0, 9), [1.0, 0.0], rtol=1e-11, dense_output=True, events=crossing)
    assert res.success and res.y.shape == (2, len(res.t))
    exact = lambda t: np.array([math.cos(t) + t * math.sin(t) / 2, -math.sin(t) / 2 + t * math.cos(t) / 2])
    assert np.max(np.abs(res.y[:, -1] - exact(9.0))) < 1e-9
    for t in (0.4, 3.3, 7.7):
        assert np.max(np.abs(res.sol(t) - exact(t))) < 1e-9
    assert len(res.t_events[0]) >= 1
    for t in res.t_events[0]:
        assert abs(exact(t)[0]) < 1e-8  # a zero of y1, falling
        assert exact(t)[1] < 0
    assert res.nfev > 0


def test_solve_ivp_van_der_pol_period():
    def vdp(t, y):
        return np.array([y[1], (1 - y[0] ** 2) * y[1] - y[0]])

    def top(t, y):
        return y[1]

    top.direction = -1
    with np.errstate(over="ignore"):  # GBS's first trial step spans the whole interval: its rows overflow
        res = nystrom.solve_ivp(vdp, (0, 60), [2.0, 0.0], rtol=1e-12, events=[top])
    ts = res.t_events[0]
    assert abs((ts[-1] - ts[-2]) - 6.6632868593231301896996820305) < 1e-8


def test_solve_ivp_refuses_other_methods():
    with pytest.raises(ValueError, match="^method 'M8' does not integrate first-order systems y' = f\\(t, y\\); "
                                         "methods that do: DOP853-adaptive, Fine4-adaptive, Fine5-adaptive, "
                                         "GBS, mpe-midpoint:K1,K2,..., mpe-midpoint-adaptive:K1,K2,...$"):
        nystrom.solve_ivp(lambda t, y: -y, (0, 1), [1.0], method="M8")
