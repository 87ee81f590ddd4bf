"""nystrom.solve with Python forces and built-in problems: orders, adaptivity, output times, dense output,
events, extended precision."""
import math

import numpy as np
import pytest

import nystrom
from nystrom.problems import HarmonicOscillator, HenonHeiles, Kepler

E = 0.5
T_END = 3.7  # not a multiple of the period (whole periods can show one order more, see the order test)


def kepler_force(t, q):
    return -q / np.dot(q, q) ** 1.5


def kepler_error(res, prob):
    qx, _ = prob.exact(res.t[-1])
    return float(np.linalg.norm(res.q[-1] - qx))


def observed_order(method, n1, force=None, precision="double"):
    prob = Kepler(E)
    errs = []
    if precision != "double":  # the reference: M16 in quad-double with small steps (error far below dd's)
        from decimal import Decimal, getcontext

        getcontext().prec = 80
        ref = nystrom.solve(prob, t_span=(0, T_END), method="M16", steps=400, precision="qd", t_eval=[T_END])
        ref = [Decimal(x) for x in ref.q_str]
    for n in (n1, 2 * n1):
        if force is None:
            res = nystrom.solve(prob, t_span=(0, T_END), method=method, steps=n, t_eval=[T_END], precision=precision)
        else:
            res = nystrom.solve(force, prob.q0, prob.v0, t_span=(0, T_END), method=method, steps=n, t_eval=[T_END])
        assert res.success
        if precision == "double":
            errs.append(kepler_error(res, prob))
        else:
            errs.append(float(max(abs(Decimal(a) - b) for a, b in zip(res.q_str, ref))))
    return math.log2(errs[0] / errs[1]), errs


# (method, declared order, steps of the coarser run): one or two methods of each family, step counts in the
# asymptotic range of Kepler at e = 0.5 over t = 3.7, and errors well above rounding.
ORDER_CASES = [
    ("VV", 2, 200),
    ("FR", 4, 200),
    ("Yoshida6", 6, 100),
    ("N4", 4, 100),
    ("A6", 6, 100),
    ("M4", 4, 100),
    ("M8", 8, 40),
]


@pytest.mark.parametrize("method,order,n1", ORDER_CASES)
def test_observed_order_with_a_python_force(method, order, n1):
    p, errs = observed_order(method, n1, kepler_force)
    assert abs(p - order) <= 0.35, f"{method}: observed order {p:.2f} (errors {errs})"


# The tenth- and twelfth-order RKN methods reach their asymptotic range only below double's rounding: measured
# in double-double.
@pytest.mark.parametrize("method,order,n1,precision", [("FR", 4, 200, "double"), ("M6", 6, 60, "double"),
                                                       ("DP10", 10, 64, "dd"), ("DP12", 12, 64, "dd")])
def test_observed_order_with_the_built_in_force(method, order, n1, precision):
    p, errs = observed_order(method, n1, precision=precision)
    assert abs(p - order) <= 0.35, f"{method}: observed order {p:.2f} (errors {errs})"


def test_python_and_built_in_forces_agree():
    prob = Kepler(0.7)
    a = nystrom.solve(prob, t_span=(0, 10.0), method="M8", steps=500)
    b = nystrom.solve(kepler_force, prob.q0, prob.v0, t_span=(0, 10.0), method="M8", steps=500)
    assert a.force_evals == b.force_evals
    # M8 on position Verlet: 1 + 2 + 3 + 4 = 10 forces per step.
    assert a.force_evals == 10 * 500
    assert np.allclose(a.q, b.q, rtol=0, atol=1e-11)
    assert a.t.shape == (501,) and a.q.shape == (501, 2) and a.v.shape == (501, 2)
    assert a.t[-1] == 10.0


def test_force_evaluation_count_equals_python_calls():
    calls = [0]

    def f(t, q):
        calls[0] += 1
        return -q

    res = nystrom.solve(f, [1.0], [0.0], t_span=(0, 1.0), method="FR", steps=50, t_eval=[1.0])
    assert res.force_evals == calls[0]


def test_complex_coefficient_method_from_python():
    prob = HarmonicOscillator()
    res = nystrom.solve(lambda t, q: -q, prob.q0, prob.v0, t_span=(0, 2.0), method="Chambers", steps=400,
                        t_eval=[2.0])
    qx, _ = prob.exact(2.0)
    assert abs(res.q[-1, 0] - qx[0]) < 1e-6


@pytest.mark.parametrize("method", ["AC1", "Chambers"])
@pytest.mark.parametrize("t1", [7.0, -7.0])
def test_complex_coefficient_method_on_a_time_dependent_force_keeps_its_order(method, t1):
    # q'' = -q + cos(2t), q(0) = 1, v(0) = 0: q = (4/3) cos t - (1/3) cos 2t. The force gets the complex times
    # of the method's stages (with their real parts alone the method would show order 2). Complex methods show
    # their order or one more (an imaginary leading error term), as in the catalog's order test.
    times = []

    def force(t, q):
        times.append(t)
        return -q + np.cos(2 * t)

    order = nystrom.method_info(method)["order"]
    errs = []
    for steps in (40, 80):
        res = nystrom.solve(force, [1.0], [0.0], t_span=(0, t1), method=method, steps=steps, t_eval=[t1])
        q, v = res.q[-1, 0], res.v[-1, 0]
        errs.append((abs(q - (4 / 3 * math.cos(t1) - math.cos(2 * t1) / 3)),
                     abs(v - (-4 / 3 * math.sin(t1) + 2 / 3 * math.sin(2 * t1)))))
    assert any(isinstance(t, complex) and t.imag != 0 for t in times)
    for k in range(2):  # positions, velocities
        assert order - 0.35 < math.log2(errs[0][k] / errs[1][k]) < order + 1.35, errs


def test_adaptive_methods_reach_their_tolerance():
    prob = Kepler(0.9)
    t1 = 2 * math.pi * 3 + 1.0
    for method, tol in (("DP12-adaptive", 1e-10), ("M10", 1e-10)):
        res = nystrom.solve(prob, t_span=(0, t1), method=method, rtol=tol, t_eval=[t1])
        assert res.success and res.steps > 10
        err = kepler_error(res, prob)
        assert err < 1e4 * tol, (method, err)
        tighter = nystrom.solve(prob, t_span=(0, t1), method=method, rtol=tol * 1e-3, t_eval=[t1])
        assert kepler_error(tighter, prob) < err
        assert tighter.force_evals > res.force_evals


@pytest.mark.parametrize("method", ["M12-adaptive", "M16-adaptive"])
def test_precise_products_are_reported_from_the_methods_calibration(method):
    # The products of an adaptive multi-product run in double carry their own rounding when the controlled
    # tolerance anchor (tol / anchor)^gamma is at most 1e4 eps: up to the user tolerance
    # tol* = anchor (1e4 eps / anchor)^(1/gamma) from the method's calibration. Both time directions; never in long
    # double (no compensation), for an RKN pair or with fixed steps.
    info = nystrom.method_info(method)
    anchor, gamma = info["tolerance_anchor"], info["tolerance_exponent"]
    tstar = anchor * (1e4 * np.finfo(float).eps / anchor) ** (1 / gamma)
    prob = Kepler(0.5)
    for t1 in (2.0, -2.0):
        below = nystrom.solve(prob, t_span=(0, t1), method=method, rtol=0.99 * tstar, t_eval=[t1])
        above = nystrom.solve(prob, t_span=(0, t1), method=method, rtol=1.01 * tstar, t_eval=[t1])
        assert below.precise_products is True and above.precise_products is False, (t1, tstar)
        wide = nystrom.solve(prob, t_span=(0, t1), method=method, rtol=0.99 * tstar, precision="long-double")
        assert wide.precise_products is False
    assert nystrom.solve(prob, t_span=(0, 2), method="DP12-adaptive", rtol=1e-13).precise_products is False
    assert nystrom.solve(prob, t_span=(0, 2), method="M12", steps=20).precise_products is False


def test_t_eval_lands_on_each_time():
    prob = Kepler(0.3)
    te = np.linspace(0.5, 9.5, 7)
    for kw in (dict(h=0.01), dict(rtol=1e-11)):
        res = nystrom.solve(prob, t_span=(0, 10.0), method="M10", t_eval=te, **kw)
        assert np.array_equal(res.t, te)
        qx, vx = prob.exact(te)
        assert np.max(np.abs(res.q - qx)) < 1e-8
        assert np.max(np.abs(res.v - vx)) < 1e-8


def test_dense_output_has_the_accuracy_of_the_method():
    # sol(t) continues from the step end before t by a partial step of the method: between the steps its
    # error is that of the method (M8: eighth order), far below a sixth-order interpolant's.
    prob = HarmonicOscillator()
    errs = []
    for n in (20, 40):
        res = nystrom.solve(lambda t, q: -q, prob.q0, prob.v0, t_span=(0, 4.0), method="M8", steps=n,
                            dense_output=True)
        end_err = np.max(np.abs(res.q - prob.exact(res.t)[0]))
        mids = 0.5 * (res.t[:-1] + res.t[1:])
        q, v = res.sol(mids)
        qx, vx = prob.exact(mids)
        errs.append(np.max(np.abs(q - qx)))
        assert errs[-1] < 2 * end_err and np.max(np.abs(v - vx)) < 2 * end_err
        assert res.output_force_evals == n + 1  # one force per step end (and the start)
    p = math.log2(errs[0] / errs[1])
    assert abs(p - 8) <= 0.5, (p, errs)
    q, v = res.sol(1.234)
    assert q.shape == (1,) and v.shape == (1,)
    with pytest.raises(ValueError, match="outside"):
        res.sol(5.0)


def test_terminal_event_at_pericentre():
    # From apocentre (1+e, 0) moving counter-clockwise, y falls through zero at pericentre, t = pi.
    prob = Kepler(E)

    def y_falls(t, q, v):
        return q[1]

    y_falls.terminal = True
    y_falls.direction = -1
    for kw in (dict(h=0.01), dict(rtol=1e-12)):
        res = nystrom.solve(prob, t_span=(0, 10.0), method="M8", events=y_falls, **kw)
        assert res.status == 1
        assert res.t_events[0][0] == pytest.approx(math.pi, abs=1e-9)
        assert res.t[-1] == res.t_events[0][0]
        assert np.allclose(res.q_events[0][0], [-(1 - E), 0.0], atol=1e-9)


def test_non_terminal_events_count_crossings():
    prob = Kepler(E)

    def y_zero(t, q, v):
        return q[1]

    res = nystrom.solve(kepler_force, prob.q0, prob.v0, t_span=(0, 4 * math.pi + 1.0), method="M8", h=0.02,
                        events=[y_zero])
    assert res.status == 0
    # Zeros of y at t = pi, 2 pi, 3 pi, 4 pi (t = 0 itself is the start, not a crossing).
    assert np.allclose(res.t_events[0], [math.pi, 2 * math.pi, 3 * math.pi, 4 * math.pi], atol=1e-9)


def test_energy_of_henon_heiles_is_conserved_by_a_symplectic_method():
    prob = HenonHeiles()
    res = nystrom.solve(prob, t_span=(0, 200.0), method="Yoshida6", h=0.05)
    E0 = prob.energy(prob.q0, prob.v0)
    drift = np.max(np.abs(prob.energy(res.q, res.v) - E0))
    assert drift < 1e-7


def test_nbody_two_body_orbit_matches_kepler():
    # Two bodies of mass 1/2 with relative orbit = Kepler(e): their separation follows the Kepler solution.
    e = 0.4
    k = Kepler(e)
    sim = nystrom.problems.NBody(G=1.0)
    rx, vy = k.q0[0], k.v0[1]
    sim.add(m=0.5, x=-rx / 2, vy=-vy / 2)
    sim.add(m=0.5, x=rx / 2, vy=vy / 2)
    res = nystrom.solve(sim, t_span=(0, T_END), method="M8", steps=400, t_eval=[T_END])
    rel = res.q[-1, 1, :2] - res.q[-1, 0, :2]
    qx, _ = k.exact(T_END)
    assert np.linalg.norm(rel - qx) < 1e-10
    assert res.q.shape == (1, 2, 3)


def test_plummer_sphere_energy():
    p = nystrom.problems.Plummer(32, seed=7, eps=0.0)
    assert p.N == 32
    # Standard units: E = -1/4 (the sample is rescaled to it), total mass 1.
    assert p.energy(p.q0, p.v0) == pytest.approx(-0.25, rel=1e-12)
    assert sum(p.masses) == pytest.approx(1.0)
    soft = nystrom.problems.Plummer(32, seed=7)
    res = nystrom.solve(soft, t_span=(0, 0.5), method="M6", h=1e-3, t_eval=[0.5])
    assert abs(soft.energy(res.q[-1], res.v[-1]) / soft.energy(soft.q0, soft.v0) - 1) < 1e-9


def test_extended_precision_beyond_double():
    prob = Kepler(0.2)
    runs = {p: nystrom.solve(prob, t_span=(0, 1.0), method="M16", steps=64, precision=p, t_eval=[1.0])
            for p in ("double", "long-double", "dd", "qd", "float128")}
    from decimal import Decimal, getcontext

    getcontext().prec = 80
    dd = [Decimal(s) for s in runs["dd"].q_str]
    qd = [Decimal(s) for s in runs["qd"].q_str]
    f128 = [Decimal(s) for s in runs["float128"].q_str]
    # M16 at h = 1/64 on a smooth orbit: truncation error far below 1e-26; dd (106 bits), float128 (113)
    # and qd (212) agree to their rounding level; double does not.
    assert max(abs(a - b) for a, b in zip(dd, qd)) < Decimal("1e-26")
    assert max(abs(a - b) for a, b in zip(f128, qd)) < Decimal("1e-27")
    assert len(runs["qd"].q_str[0].replace("-", "").replace(".", "")) > 50
    ld = [Decimal(s) for s in runs["long-double"].q_str]
    dbl = [Decimal(s) for s in runs["double"].q_str]
    # long double (64 bits) lands between double (53) and dd.
    assert max(abs(a - b) for a, b in zip(ld, qd)) < Decimal("1e-16")
    assert max(abs(a - b) for a, b in zip(ld, qd)) < max(abs(a - b) for a, b in zip(dbl, qd)) / 8
    assert np.allclose(runs["double"].q, runs["qd"].q, atol=1e-14)


def forced_oscillator(t, q):
    return -q + np.cos(2 * t)


def forced_exact(t):
    # q'' + q = cos 2t, q(0) = 1, q'(0) = 0: q = (4/3) cos t - (1/3) cos 2t.
    return 4 / 3 * np.cos(t) - np.cos(2 * t) / 3


@pytest.mark.parametrize("method,order,n1", [("FR", 4, 100), ("M6", 6, 40), ("A6", 6, 40)])
def test_time_dependent_force_gets_the_stage_time(method, order, n1):
    errs = []
    for n in (n1, 2 * n1):
        res = nystrom.solve(forced_oscillator, [1.0], [0.0], t_span=(0, 3.0), method=method, steps=n, t_eval=[3.0])
        errs.append(abs(res.q[-1, 0] - forced_exact(3.0)))
    p = math.log2(errs[0] / errs[1])
    assert abs(p - order) <= 0.35, (method, p, errs)


def test_time_dependent_force_adaptive_and_dense():
    res = nystrom.solve(forced_oscillator, [1.0], [0.0], t_span=(0, 3.0), method="DP12-adaptive", rtol=1e-12,
                        dense_output=True)
    assert abs(res.q[-1, 0] - forced_exact(3.0)) < 1e-9
    # At the steps the interpolant is the computed solution; between them its error is O(h^6), large for
    # the long steps of a twelfth-order method, small for short fixed steps.
    q, _ = res.sol(res.t)
    assert np.array_equal(q, res.q)
    q, _ = res.sol(1.2345)
    assert abs(q[0] - forced_exact(1.2345)) < 1e-4
    fixed = nystrom.solve(forced_oscillator, [1.0], [0.0], t_span=(0, 3.0), method="M8", h=0.05, dense_output=True)
    q, _ = fixed.sol(1.2345)
    assert abs(q[0] - forced_exact(1.2345)) < 1e-8
    assert len(res.q_str) == 1 and float(res.q_str[0]) == pytest.approx(res.q[-1, 0], rel=1e-15)


def cos_sin_decimal(t, prec=80):
    """cos t and sin t to prec digits by their Taylor series (exact reference for the oscillator)."""
    from decimal import Decimal, getcontext

    getcontext().prec = prec
    x = Decimal(repr(t))
    c, s, term, k = Decimal(0), Decimal(0), Decimal(1), 0
    while abs(term) > Decimal(10) ** (-prec - 5) or k < 4:
        if k % 4 == 0:
            c += term
        elif k % 4 == 1:
            s += term
        elif k % 4 == 2:
            c -= term
        else:
            s -= term
        k += 1
        term = term * x / k
    return c, s


def oscillator_error(res):
    from decimal import Decimal

    c, s = cos_sin_decimal(float(res.t[-1]))
    return float(max(abs(Decimal(res.q_str[0]) - c), abs(Decimal(res.v_str[0]) + s)))


def test_extended_precisions_of_the_oscillator_beat_double():
    # M16 at h = 1/64 on q'' = -q over t = 1: truncation error near 1e-30, so what remains is rounding:
    # long double and double-double land below what double can reach.
    runs = {p: nystrom.solve(HarmonicOscillator(), t_span=(0, 1.0), method="M16", steps=64, precision=p,
                             t_eval=[1.0]) for p in ("double", "long-double", "dd", "float128")}
    err = {p: oscillator_error(r) for p, r in runs.items()}
    assert err["double"] > 1e-17
    assert err["long-double"] < err["double"] / 8
    assert err["dd"] < 1e-26 and err["float128"] < 1e-27, err
    assert np.allclose(runs["dd"].q, runs["double"].q, atol=1e-14)


def test_mpfr_precision_with_bits():
    # M20 at h = 1/100 in 256-bit MPFR: truncation and rounding far below any fixed-width type.
    res = nystrom.solve(HarmonicOscillator(), t_span=(0, 1.0), method="M20", steps=100, precision="mpfr", bits=256,
                        t_eval=[1.0])
    assert res.precision == "mpfr:256"
    assert oscillator_error(res) < 1e-38
    assert len(res.q_str[0].split("e")[0].replace("-", "").replace(".", "")) > 70
    assert res.q[-1, 0] == pytest.approx(math.cos(1.0), abs=1e-15)
    with pytest.raises(ValueError, match="bits"):
        nystrom.solve(HarmonicOscillator(), t_span=(0, 1.0), steps=10, precision="dd", bits=256)
    with pytest.raises(ValueError, match="MPFR precision"):
        nystrom.solve(HarmonicOscillator(), t_span=(0, 1.0), steps=10, precision="mpfr", bits=8)


def test_henon_heiles_in_double_double_beats_double():
    # Reference: quad-double with half the step; a dd run's error is far below the double run's.
    prob = HenonHeiles()
    kw = dict(t_span=(0, 5.0), method="M16", t_eval=[5.0])
    from decimal import Decimal, getcontext

    getcontext().prec = 80
    ref = [Decimal(x) for x in nystrom.solve(prob, steps=200, precision="qd", **kw).q_str]

    def err(p):
        r = nystrom.solve(prob, steps=100, precision=p, **kw)
        return float(max(abs(Decimal(a) - b) for a, b in zip(r.q_str, ref)))

    assert err("dd") < 1e-25 and err("dd") < err("double") / 1e6


@pytest.mark.parametrize("python_force", [False, True])
@pytest.mark.parametrize("kw", [dict(steps=400), dict(rtol=1e-12), dict(method="GBS", rtol=1e-12)])
def test_backward_integration(python_force, kw):
    # t1 < t0 integrates backward: from apocentre to t = -3.7 matches Kepler's solution there.
    prob = Kepler(E)
    kw = dict(dict(method="M8"), **kw)
    if python_force:
        res = nystrom.solve(kepler_force, prob.q0, prob.v0, t_span=(0, -T_END), t_eval=[-1.0, -T_END], **kw)
    else:
        res = nystrom.solve(prob, t_span=(0, -T_END), t_eval=[-1.0, -T_END], **kw)
    assert res.success and list(res.t) == [-1.0, -T_END]
    qx, vx = prob.exact(res.t)
    assert np.max(np.abs(res.q - qx)) < 1e-9 and np.max(np.abs(res.v - vx)) < 1e-9


def test_backward_event_and_dense_output():
    # Backward from apocentre, y rises through zero at the pericentre t = -pi (the orbit run in reverse).
    prob = Kepler(E)

    def y_zero(t, q, v):
        return q[1]

    y_zero.terminal = True
    res = nystrom.solve(prob, t_span=(0, -10.0), method="M8", h=0.01, events=y_zero, dense_output=True)
    assert res.status == 1 and res.t_events[0][0] == pytest.approx(-math.pi, abs=1e-9)
    assert np.all(np.diff(res.t) < 0)
    q, _ = res.sol(-1.5)
    assert np.allclose(q, prob.exact(-1.5)[0], atol=1e-9)


def test_event_direction_is_in_t_in_both_time_directions_and_an_event_costs_about_one_step():
    # y = q[1] falls through zero at the pericentres t = pi, 3 pi (forward, from the apocentre) and, run
    # backward, at t = -pi, -3 pi: direction=-1 selects the zeros where y falls with t, whichever the
    # direction of integration; direction=+1 the others (t = +-2 pi, at the apocentre).
    prob = Kepler(E)

    def y_falls(t, q, v):
        return q[1]

    def y_rises(t, q, v):
        return q[1]

    y_falls.direction = -1
    y_rises.direction = +1
    for sign in (1, -1):
        res = nystrom.solve(prob, t_span=(0, sign * (3 * math.pi + 0.5)), method="M8", h=0.01,
                            events=[y_falls, y_rises])
        falls = [sign * math.pi, sign * 3 * math.pi]
        rises = [sign * 2 * math.pi]
        assert np.allclose(res.t_events[0], falls, atol=1e-9), res.t_events
        assert np.allclose(res.t_events[1], rises, atol=1e-9), res.t_events
        # Velocities at the events: (0, -v_peri) at the pericentre, (0, +v_apo) at the apocentre, run in
        # either direction (velocities are those of the orbit, not of the direction of integration).
        vp = math.sqrt((1 + E) / (1 - E))
        assert np.allclose(res.v_events[0], [[0.0, -vp]] * 2, atol=1e-8)
        # Three events: the forces at the two ends of each event's step, one M8 step (10 forces) and
        # the force at the estimate; without dense output nothing else is evaluated for output.
        assert 3 * 3 <= res.output_force_evals <= 3 * 13, res.output_force_evals


def test_gbs_reaches_its_tolerance():
    prob = Kepler(E)
    res = nystrom.solve(kepler_force, prob.q0, prob.v0, t_span=(0, T_END), method="GBS", rtol=1e-11,
                        t_eval=[T_END])
    assert res.method == "GBS" and res.steps > 3
    assert kepler_error(res, prob) < 1e-8


def test_rtol_and_atol_reach_the_driver_separately():
    # GBS scales its error by atol + rtol |y|: with a tiny rtol, atol alone sets the accuracy.
    prob = Kepler(E)
    runs = [nystrom.solve(prob, t_span=(0, T_END), method="GBS", rtol=1e-14, atol=a, t_eval=[T_END])
            for a in (1e-5, 1e-11)]
    assert runs[1].force_evals > runs[0].force_evals
    assert kepler_error(runs[1], prob) < kepler_error(runs[0], prob)
    assert kepler_error(runs[1], prob) < 1e-9


def test_absolute_tolerance_alone_with_rtol_zero():
    # rtol = 0 with atol > 0: the error of every component is measured against atol alone.
    prob = Kepler(E)
    runs = [nystrom.solve(prob, t_span=(0, T_END), method="DP12-adaptive", rtol=0.0, atol=a, t_eval=[T_END])
            for a in (1e-6, 1e-12)]
    assert all(r.success for r in runs)
    assert runs[1].force_evals > runs[0].force_evals
    assert kepler_error(runs[1], prob) < kepler_error(runs[0], prob)
    assert kepler_error(runs[1], prob) < 1e-9


# ---- checkpoints ---------------------------------------------------------------------------------------

CHECKPOINT_RUNS = [dict(method="M8", steps=2000), dict(method="DP12-adaptive", rtol=1e-11),
                   dict(method="M10-adaptive", rtol=1e-11), dict(method="GBS", rtol=1e-11)]


@pytest.mark.parametrize("python_force", [False, True])
@pytest.mark.parametrize("kw", CHECKPOINT_RUNS)
def test_restart_from_a_checkpoint_is_bitwise_the_uninterrupted_run(tmp_path, kw, python_force):
    prob = Kepler(E)
    args = (kepler_force, prob.q0, prob.v0) if python_force else (prob,)
    path = tmp_path / "run.checkpoint"
    full = nystrom.solve(*args, t_span=(0, 20.0), checkpoint=path, checkpoint_at=7.0, **kw)
    assert full.success and 7.0 <= full.checkpoint_t < 20.0 and path.exists()
    again = nystrom.solve(*args, t_span=(0, 20.0), restart=path, **kw)
    assert again.success and again.t[0] == full.checkpoint_t
    k = int(np.searchsorted(full.t, full.checkpoint_t))
    assert np.array_equal(again.t, full.t[k:])
    assert np.array_equal(again.q, full.q[k:]) and np.array_equal(again.v, full.v[k:])
    assert again.q_str == full.q_str and again.v_str == full.v_str


def test_restarted_run_takes_output_times_from_the_checkpoint_on(tmp_path):
    prob = Kepler(E)
    path = tmp_path / "run.checkpoint"
    full = nystrom.solve(prob, t_span=(0, 20.0), method="M8", steps=2000, checkpoint=path, checkpoint_at=7.0)
    again = nystrom.solve(prob, t_span=(0, 20.0), method="M8", steps=2000, restart=path,
                          t_eval=[full.checkpoint_t, 20.0])
    assert again.t.tolist() == [full.checkpoint_t, 20.0]
    assert np.array_equal(again.q[-1], full.q[-1]) and np.array_equal(again.v[-1], full.v[-1])
    # the resumed run has no state before the checkpoint
    with pytest.raises(ValueError, match="output time 0 lies before the checkpoint's time"):
        nystrom.solve(prob, t_span=(0, 20.0), method="M8", steps=2000, restart=path, t_eval=[0.0, 20.0])


def test_checkpoint_mismatches_and_bad_files_are_refused(tmp_path):
    prob = Kepler(E)
    path = tmp_path / "run.checkpoint"
    nystrom.solve(prob, t_span=(0, 20.0), method="M8", steps=2000, checkpoint=path, checkpoint_at=7.0)
    cases = [
        (dict(method="M6", steps=2000, restart=path), "method"),
        (dict(method="M8", steps=1000, restart=path), "another problem"),
        (dict(method="M8", steps=2000, restart=tmp_path / "missing"), "cannot read"),
        (dict(method="M8", steps=2000, checkpoint=path), "go together"),
        (dict(method="M8", steps=2000, checkpoint=tmp_path / "no" / "dir", checkpoint_at=1.0), "cannot write"),
        (dict(method="M8", steps=2000, checkpoint=path, checkpoint_at=25.0), "checkpoint_at"),
        (dict(method="M8", steps=2000, checkpoint=path, checkpoint_at=1.0, restart=path), "same file"),
        (dict(method="M8", steps=2000, checkpoint=tmp_path / "dd", checkpoint_at=1.0, precision="dd"),
         "double and long double"),
    ]
    for kw, match in cases:
        with pytest.raises(ValueError, match=match):
            nystrom.solve(prob, t_span=(0, 20.0), **kw)
    with pytest.raises(ValueError, match="another problem"):
        nystrom.solve(Kepler(0.3), t_span=(0, 20.0), method="M8", steps=2000, restart=path)


@pytest.mark.parametrize("built_in", [False, True])
def test_an_event_that_never_fires_gives_empty_arrays_of_the_state_shape(built_in):
    prob = Kepler(E)

    def never(t, q, v):
        return 1.0

    def y_zero(t, q, v):
        return q[1]

    args = (prob,) if built_in else (kepler_force, prob.q0, prob.v0)
    res = nystrom.solve(*args, t_span=(0, 4.0), method="M8", h=0.02, events=[never, y_zero])
    assert res.success
    assert res.t_events[0].shape == (0,)
    assert res.q_events[0].shape == (0, 2) and res.v_events[0].shape == (0, 2)
    assert res.t_events[1] == pytest.approx([math.pi], abs=1e-9)  # the other event of the list still counts
    assert res.q_events[1].shape == (1, 2)
    res = nystrom.solve(*args, t_span=(0, 1.0), method="M8", h=0.02, events=never)
    assert [a.shape for a in (res.t_events[0], res.q_events[0], res.v_events[0])] == [(0,), (0, 2), (0, 2)]


def test_every_step_output_is_built_in_bulk(monkeypatch):
    # no per-state conversion (a Python call per saved state would cost more than the C++ run itself)
    calls = [0]
    original = Kepler._from_flat

    def counting(self, x):
        calls[0] += 1
        return original(self, x)

    monkeypatch.setattr(Kepler, "_from_flat", counting)
    res = nystrom.solve(Kepler(E), t_span=(0, 10.0), method="M8", steps=20000)
    assert res.q.shape == (20001, 2) and res.v.shape == (20001, 2)
    assert calls[0] <= 2
    assert np.array_equal(res.q[0], Kepler(E).q0)


def test_nbody_states_in_bulk_match_the_layout_of_one_state():
    from nystrom.problems import NBody

    sim = NBody(G=1.0)
    sim.add(m=1.0)
    sim.add(m=1e-3, x=1.0, vy=1.0)
    sim.add(m=1e-4, x=-2.0, y=0.5, vy=-0.7, vz=0.1)
    res = nystrom.solve(sim, t_span=(0, 1.0), method="M6", steps=50, events=lambda t, q, v: q[1, 1] - 0.5)
    assert res.q.shape == (51, 3, 3)
    assert np.array_equal(res.q[0], sim.q0) and np.array_equal(res.v[0], sim.v0)
    flat = np.stack([sim._to_flat(x) for x in res.q])
    assert np.array_equal(sim._rows_from_flat(flat), res.q)
    assert np.array_equal(np.stack([sim._from_flat(x) for x in flat]), res.q)
    assert res.q_events[0].shape[1:] == (3, 3)
    assert res.q_events[0][0][1, 1] == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize("method, ratio, bound", [("DP12-adaptive", 0.4, 1.5e-13), ("M12-adaptive", 0.1, 5e-14)])
def test_kepler_compensated_force_goes_below_the_plain_floor(method, ratio, bound):
    # DP12-adaptive and M12-adaptive over 100 periods at e = 0.5: with Kepler(e, compensated=True) (the force in
    # double-word: DP12-adaptive's precise update takes it, M12-adaptive's products run in double-word) the tolerance
    # may go down to eps/2, which the plain force refuses with the tool's one-line error, and the runs end nearer the
    # orbit (the same initial state in double-double) than the plain force's at its tightest tolerances: rms over
    # four tolerances each, measured 5.6e-14 against 3.0e-13 (DP12-adaptive) and 1.5e-14 against 5.7e-12
    # (M12-adaptive, whose plain products' rounding the combination amplifies). Backward in time a run ends at the
    # mirror image of the orbit's end.
    from decimal import Decimal

    t1 = 200 * math.pi
    plain, comp = Kepler(0.5), Kepler(0.5, compensated=True)
    with pytest.raises(ValueError, match="eps / 2 with a compensated force"):
        nystrom.solve(plain, t_span=(0, t1), method=method, rtol=2e-16)
    ref = nystrom.solve(plain, t_span=(0, t1), method="DP12-adaptive", rtol=1e-26, precision="dd", t_eval=[t1])
    qx = np.array([float(Decimal(x)) for x in ref.q_str])
    vx = np.array([float(Decimal(x)) for x in ref.v_str])

    def errors(prob, tols):
        runs = [nystrom.solve(prob, t_span=(0, t1), method=method, rtol=tol) for tol in tols]
        assert all(r.success for r in runs)
        return (np.array([np.linalg.norm(r.q[-1] - qx) for r in runs]),
                np.array([np.linalg.norm(r.v[-1] - vx) for r in runs]))

    ep, _ = errors(plain, [2.5e-15, 3e-15, 4e-15, 5e-15])
    ec, evc = errors(comp, [1.5e-16, 2e-16, 3e-16, 4e-16])
    rms = lambda e: float(np.sqrt(np.mean(e**2)))
    assert rms(ec) < ratio * rms(ep), (ec, ep)
    assert ec.max() < bound and evc.max() < bound, (ec, evc)
    back = nystrom.solve(comp, t_span=(0, -t1), method=method, rtol=2e-16)
    assert np.linalg.norm(back.q[-1] * [1, -1] - qx) < bound
    assert np.linalg.norm(back.v[-1] * [-1, 1] - vx) < bound
    # M12-adaptive's products carry their rounding at every tolerance with this force (precise_products), even loose.
    loose = nystrom.solve(comp, t_span=(0, 2), method=method, rtol=1e-8)
    assert loose.precise_products is (method == "M12-adaptive")
    assert nystrom.solve(plain, t_span=(0, 2), method=method, rtol=1e-8).precise_products is False


def test_kepler_compensated_force_takes_fixed_step_splitting_to_the_rounding():
    # SS10 over t = 640 (about 102 periods) at e = 0.5 with fixed steps whose truncation lies below the rounding of the
    # result (steps of 2^-8 and 5 2^-10, exact, so that the run ends at 640 exactly): with Kepler(e,
    # compensated=True) the drifts and kicks run in double-word with the force's rounding error, and the final state
    # lies within a few 1e-16 of the orbit (double-double reference), where the plain force's rounding leaves about
    # 1e-13; same force evaluations; backward too.
    from decimal import Decimal

    t1 = 640.0
    plain, comp = Kepler(0.5), Kepler(0.5, compensated=True)
    ref = nystrom.solve(plain, t_span=(0, t1), method="DP12-adaptive", rtol=1e-26, precision="dd", t_eval=[t1])
    qx = np.array([float(Decimal(x)) for x in ref.q_str])
    vx = np.array([float(Decimal(x)) for x in ref.v_str])
    worst, worst_plain = 0.0, 0.0
    for steps in (131072, 163840):
        p = nystrom.solve(plain, t_span=(0, t1), method="SS10", steps=steps)
        c = nystrom.solve(comp, t_span=(0, t1), method="SS10", steps=steps)
        assert c.force_evals == p.force_evals
        worst_plain = max(worst_plain, np.linalg.norm(p.q[-1] - qx))
        worst = max(worst, np.linalg.norm(c.q[-1] - qx), np.linalg.norm(c.v[-1] - vx))
        back = nystrom.solve(comp, t_span=(0, -t1), method="SS10", steps=steps)
        worst = max(worst, np.linalg.norm(back.q[-1] * [1, -1] - qx), np.linalg.norm(back.v[-1] * [-1, 1] - vx))
    assert worst < 1e-15 and worst < 0.1 * worst_plain, (worst, worst_plain)


def test_nbody_compensated_force_on_the_two_body_problem():
    # Two equal masses whose relative orbit is Kepler(0.5) (G (m0 + m1) = 1), over t = 64 (about 10 periods) with SS10
    # and M8 in 16384 steps (2^-8, exact) whose truncation lies below the rounding: with NBody(compensated=True)
    # (CompensatedNBodyForce) the relative orbit ends within a few 1e-16 of the double-double reference where the
    # plain force's rounding leaves more; same force evaluations.
    from decimal import Decimal

    e, t1 = 0.5, 64.0
    v0 = math.sqrt((1 - e) / (1 + e))

    def system(compensated):
        sim = nystrom.problems.NBody(compensated=compensated)
        sim.add(m=0.5, x=-(1 + e) / 2, vy=-v0 / 2)
        sim.add(m=0.5, x=(1 + e) / 2, vy=v0 / 2)
        return sim

    ref = nystrom.solve(Kepler(e), t_span=(0, t1), method="DP12-adaptive", rtol=1e-26, precision="dd", t_eval=[t1])
    qx = np.array([float(Decimal(x)) for x in ref.q_str])
    for method, steps in (("SS10", 16384), ("M8", 16384)):
        p = nystrom.solve(system(False), t_span=(0, t1), method=method, steps=steps)
        c = nystrom.solve(system(True), t_span=(0, t1), method=method, steps=steps)
        assert c.force_evals == p.force_evals
        rel = lambda r: (r.q[-1][1] - r.q[-1][0])[:2]
        ep, ec = np.linalg.norm(rel(p) - qx), np.linalg.norm(rel(c) - qx)
        assert ec < 1e-15 and ec < 0.1 * ep, (method, ec, ep)
    with pytest.raises(ValueError, match="would ignore it"):
        nystrom.solve(system(True), t_span=(0, 1), method="DP12", steps=10)
    with pytest.raises(ValueError, match="runs in double precision"):
        nystrom.solve(system(True), t_span=(0, 1), method="SS10", steps=10, precision="dd")
    with pytest.raises(TypeError, match="compensated must be True or False"):
        nystrom.problems.NBody(compensated=1)


def test_kepler_compensated_force_refusals():
    comp = Kepler(0.5, compensated=True)
    with pytest.raises(ValueError, match="is used by the adaptive RKN pairs"):
        nystrom.solve(comp, t_span=(0, 1), method="DP12", steps=10)
    with pytest.raises(ValueError, match="is used by the adaptive RKN pairs"):
        nystrom.solve(comp, t_span=(0, 1), method="MPE-adaptive", rtol=1e-12)
    with pytest.raises(ValueError, match="runs in double precision"):
        nystrom.solve(comp, t_span=(0, 1), method="DP12-adaptive", rtol=1e-20, precision="dd")
    with pytest.raises(TypeError, match="compensated must be True or False"):
        Kepler(0.5, compensated="yes")
