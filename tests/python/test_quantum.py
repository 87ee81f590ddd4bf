"""nystrom.quantum: the split-operator solver from Python, against exact results of the harmonic oscillator
(units hbar = m = 1, V = |x|^2/2: levels n + d/2, coherent states whose centre follows x0 cos t + p0 sin t)."""
import math
import os
import signal
import sys
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import nystrom

pytestmark = pytest.mark.skipif(not hasattr(nystrom._core, "quantum"), reason="module built without FFTW")

EPS = np.finfo(float).eps


@pytest.mark.parametrize("dims,x0", [(1, [1.0]), (2, [1.0, -0.5])])
def test_imaginary_time_relaxes_to_the_harmonic_ground_state_energy_d_over_2(dims, x0):
    dt, steps = 0.05, 200
    res = nystrom.quantum("harmonic", dims=dims, grid=64, box=20.0, method="M8", dt=dt, steps=steps,
                          imaginary_time=True, x0=x0)
    # Two errors bound E - d/2: the method's (the ground state of the order-p splitting's modified Hamiltonian
    # is O(dt^p) off, and <H> is quadratic in that: dt^(2p)) and the excited part of the start, a coherent
    # state of energy d/2 + |x0|^2/2 whose excess decays as exp(-2 tau) (tau = steps dt; factor 2 of margin).
    tau = dt * steps
    bound = dt ** (2 * res.order) + 2 * (np.dot(x0, x0) / 2) * math.exp(-2 * tau)
    assert res.order == 8
    assert abs(res.energy - dims / 2) <= bound
    assert abs(res.norm - 1) <= 1e-12
    assert res.psi.shape == (64,) * dims and res.psi.dtype == np.complex128
    # The final state is the Gaussian pi^(-d/4) exp(-|x|^2/2) (up to a global phase, here real and positive).
    x = -10.0 + np.arange(64) * (20.0 / 64)
    g1 = math.pi ** -0.25 * np.exp(-x * x / 2)
    exact = g1 if dims == 1 else np.outer(g1, g1)
    assert np.max(np.abs(res.psi - exact)) <= 1e-4
    assert np.allclose(res.mean_position, 0, atol=1e-4)


def test_imaginary_time_energy_error_of_a_second_order_splitting_falls_as_dt_to_the_fourth():
    # The position Verlet splitting (order 2): its fixed point is O(dt^2) off the ground state, so the energy is
    # O(dt^4) off d/2; the start x0 = 0 is the exact continuum ground state, relaxed for tau = 12.
    errs = []
    for dt in (0.2, 0.1):
        res = nystrom.quantum("harmonic", grid=128, box=20.0, method="PV", dt=dt, steps=round(12 / dt),
                              imaginary_time=True, x0=0.0)
        errs.append(abs(res.energy - 0.5))
    assert 3.7 <= math.log2(errs[0] / errs[1]) <= 4.3


def test_lowest_states_of_the_harmonic_oscillator_are_n_plus_one_half():
    res = nystrom.quantum("harmonic", grid=128, box=20.0, method="M8", dt=0.05, steps=300, imaginary_time=True,
                          states=3)
    # each level relaxes from its start as exp(-2 tau) (tau = 15) relative to the gap of 1
    assert np.allclose(res.energies, [0.5, 1.5, 2.5], rtol=0, atol=1e-11)
    assert res.energy == res.energies[0]


def test_real_time_norm_is_conserved_to_rounding_by_a_unitary_splitting():
    res = nystrom.quantum("harmonic", grid=256, box=20.0, method="Y6", dt=0.05, steps=200, x0=1.0, p0=0.5)
    # Every flow is a unitary phase or an FFT pair; the norm moves only by rounding, at most about eps log2(n)
    # per FFT (n = 256).
    assert abs(res.norm - 1) <= res.fft_count * EPS * math.log2(256)
    assert abs(res.norm_drift) <= res.fft_count * EPS * math.log2(256)
    assert res.fft_count > 0


def test_coherent_state_centre_follows_the_classical_orbit():
    x0, dt, steps = 1.0, 0.05, 200
    res = nystrom.quantum("harmonic", grid=128, box=20.0, method="M8", dt=dt, steps=steps, x0=x0, samples=20)
    assert np.allclose(res.times, np.arange(21) * (dt * steps / 20), rtol=0, atol=1e-12)
    assert np.allclose(res.sample_mean_position[:, 0], x0 * np.cos(res.times), rtol=0, atol=1e-9)
    assert np.allclose(res.sample_norms, 1, rtol=0, atol=1e-10)
    assert res.mean_position[0] == pytest.approx(x0 * math.cos(dt * steps), abs=1e-9)
    assert res.exact_solution == "harmonic coherent state" and res.exact_error <= 1e-8


def test_two_dimensional_coherent_state_with_momentum():
    x0, p0, t = np.array([1.0, 0.0]), np.array([0.0, -0.5]), 0.05 * 100
    res = nystrom.quantum("harmonic", dims=2, grid=64, box=20.0, method="M8", dt=0.05, steps=100, x0=x0, p0=p0)
    assert np.allclose(res.mean_position, x0 * math.cos(t) + p0 * math.sin(t), rtol=0, atol=1e-8)
    assert np.allclose(res.mean_momentum, p0 * math.cos(t) - x0 * math.sin(t), rtol=0, atol=1e-8)


def test_autocorrelation_of_the_ground_state_is_a_pure_phase():
    # psi(t) = exp(-i t/2) psi(0): C(t) = <psi(0)|psi(t)> = exp(-i t / 2) at every recorded time.
    res = nystrom.quantum("harmonic", grid=128, box=20.0, method="M8", dt=0.05, steps=40, x0=0.0,
                          autocorrelation=True)
    assert len(res.times) == 41 and res.autocorrelation.dtype == np.complex128
    assert np.allclose(res.autocorrelation, np.exp(-0.5j * res.times), rtol=0, atol=1e-12)
    assert res.final_autocorrelation == res.autocorrelation[-1]


def test_potential_values_on_the_grid():
    n, box = 128, 20.0
    x = -box / 2 + np.arange(n) * (box / n)
    # The harmonic potential's values, as the library samples it, give the named potential's run bit for bit.
    named = nystrom.quantum("harmonic", grid=n, box=box, method="M8", dt=0.05, steps=50)
    given = nystrom.quantum(potential_values=x * x / 2, grid=n, box=box, method="M8", dt=0.05, steps=50)
    assert np.array_equal(named.psi, given.psi)
    # V = x^2 (omega = sqrt 2): ground state omega / 2.
    res = nystrom.quantum(potential_values=x * x, grid=n, box=box, method="M8", dt=0.05, steps=300,
                          imaginary_time=True, x0=0.0)
    assert res.energy == pytest.approx(math.sqrt(2) / 2, abs=1e-9)
    assert math.isnan(res.exact_error) and res.exact_solution is None


def test_long_double_agrees_with_double():
    a = nystrom.quantum("harmonic", grid=64, method="M8", dt=0.05, steps=200, imaginary_time=True)
    b = nystrom.quantum("harmonic", grid=64, method="M8", dt=0.05, steps=200, imaginary_time=True,
                        precision="long-double")
    assert b.precision == "long-double"
    assert b.energy == pytest.approx(a.energy, abs=1e-12)


@pytest.mark.parametrize("kwargs,match", [
    (dict(grid=0), "grid must have at least 2 points"),
    (dict(box=-1.0), "box must be positive"),
    (dict(box=float("nan")), "box must be positive"),
    (dict(dt=float("nan")), "dt must be positive"),
    (dict(dt=0.0), "dt must be positive"),
    (dict(g=float("nan")), "g must be finite"),
    (dict(x0=[float("nan")]), "x0 and p0 must be finite"),
    (dict(x0=[1.0, 2.0]), "x0 has 2 components for 1 dimension"),
    (dict(dims=4), "dims must be 1, 2 or 3"),
    (dict(steps=-1), "steps must not be negative"),
    (dict(potential="nonsense"), "unknown potential 'nonsense'"),
    (dict(method="N4"), "Runge-Kutta-Nystrom tableau with consolidated forces"),
    (dict(method="M10-adaptive"), "is adaptive"),
    (dict(method="no-such-method"), "no-such-method"),
    (dict(states=2), "excited states need imaginary time"),
    (dict(precision="float128"), "precision must be 'double' or 'long-double'"),
    (dict(potential_values=np.zeros(10)), r"potential_values has shape \(10,\), expected \(256,\)"),
    (dict(potential_values=np.full(256, np.nan)), "the potential is not finite"),
    (dict(potential_values=np.zeros(256), method="4A"), "needs the potential as a function"),
    (dict(method="BC1", g=2.0), "on the Gross-Pitaevskii equation"),
    (dict(method="AC1", g=1.0, imaginary_time=True), "on the Gross-Pitaevskii equation"),
])
def test_bad_input_raises_value_error_with_the_library_message(kwargs, match):
    with pytest.raises(ValueError, match=match):
        nystrom.quantum(**kwargs)


def test_wrong_types_raise_type_error():
    with pytest.raises(TypeError):
        nystrom.quantum(grid=256.0)
    with pytest.raises(TypeError):
        nystrom.quantum(method=8)
    with pytest.raises(TypeError):
        nystrom.quantum(x0="1")


# A run long enough for several heartbeats (2^20 grid points each: 16 steps of 65536 points), cheap per step.
BIG = dict(potential="harmonic", grid=65536, box=40.0, method="PV", dt=0.01, steps=96)


def test_gil_is_released_two_threads_run_concurrently():
    reference = nystrom.quantum(**BIG)
    counter = [0]
    seen = [[], []]
    done = threading.Event()

    def run(k):
        # the progress callback notes how far the main thread's counter got: it moves between heartbeats only
        # if the propagation runs without the GIL
        return nystrom.quantum(**BIG, progress=lambda d, n: seen[k].append(counter[0]))

    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = [pool.submit(run, k) for k in range(2)]
        threading.Thread(target=lambda: ([f.result() for f in futures], done.set())).start()
        while not done.is_set():
            counter[0] += 1
        results = [f.result() for f in futures]
    for r in results:
        assert np.array_equal(r.psi, reference.psi) and r.fft_count == reference.fft_count
    for s in seen:
        assert len(s) == 96 // 16
        assert s[-1] > s[0]


def test_progress_reports_steps_done_up_to_the_total():
    seen = []
    nystrom.quantum(**BIG, progress=lambda d, n: seen.append((d, n)))
    assert [d for d, _ in seen] == list(range(16, 97, 16)) and all(n == 96 for _, n in seen)


def test_progress_line_ends_at_the_steps_taken(capsys, monkeypatch):
    # The progress line (tqdm absent) closes at the steps the run took: all of them, or fewer when `converge`
    # stopped it early; never at 100% for a run that did not take every step.
    monkeypatch.setitem(sys.modules, "tqdm", None)
    res = nystrom.quantum(grid=64, imaginary_time=True, x0=0.5, dt=0.05, steps=10000, converge=1e-8, progress=True)
    last = capsys.readouterr().err.rstrip("\n").split("\r")[-1]
    assert res.steps_taken < 10000
    assert last.startswith(f"nystrom: t = {res.steps_taken} of 10000 (")
    assert "100.0%" not in last
    nystrom.quantum(grid=64, dt=0.05, steps=40, progress=True)
    last = capsys.readouterr().err.rstrip("\n").split("\r")[-1]
    assert last == "nystrom: t = 40 of 40 (100.0%)"


@pytest.mark.skipif(os.name != "posix", reason="needs POSIX signals")
def test_ctrl_c_interrupts_a_long_propagation():
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            nystrom.quantum(**dict(BIG, steps=10**7))
    finally:
        timer.cancel()


def test_imaginary_time_refuses_backward_methods_and_names_the_forward_ones():
    # Kahan-Li 8 on the double well (128 points, box 8) gives E0 = 212 for 0.8696, with norm 1: its negative
    # coefficients amplify the highest wave numbers in imaginary time. The message is the library's, as in C++ and
    # the CLI.
    well = dict(potential="double-well", grid=128, box=8.0, imaginary_time=True, steps=400)
    for method in ("KL8", "FR"):
        refused = f"'{method}' has a coefficient with a real part that is not positive"
        with pytest.raises(ValueError, match=refused) as e:
            nystrom.quantum(method=method, **well)
        msg = str(e.value)
        assert "\n" not in msg
        for alt in ("M4..M16", "mpe:", "Chin's 4A", "AC1", "BC1", "allow_negative_coefficients"):
            assert alt in msg
    m8 = nystrom.quantum(method="M8", **well)
    bc1 = nystrom.quantum(method="BC1", **well)
    assert bc1.energy == pytest.approx(m8.energy, abs=1e-8)
    assert 0 < m8.energy < 1  # below the barrier V(0) = 1
    forced = nystrom.quantum(method="KL8", allow_negative_coefficients=True, **well)
    assert abs(forced.energy - m8.energy) > 1  # the wrong answer the refusal prevents


def test_default_method_is_kl8_in_real_time_and_m8_in_imaginary_time():
    # M8 blew up on the double well at dt = 0.01 in real time (an MPE is not unitary); KL8 keeps the norm
    res = nystrom.quantum("double-well", dt=0.01, steps=200)
    assert res.method == "KL8" and abs(res.norm - 1) <= 1e-12
    with pytest.raises(RuntimeError, match="smaller step or a unitary method .*KL8"):
        nystrom.quantum("double-well", method="M8", dt=0.01, steps=1000)
    assert nystrom.quantum(imaginary_time=True, steps=10).method == "M8"


def test_initial_wave_function_is_normalised_and_gives_the_gaussian_result():
    x = -10.0 + np.arange(64) * (20.0 / 64)
    gauss = math.pi ** -0.25 * np.exp(-(x - 1) ** 2 / 2 + 0.5j * x)
    a = nystrom.quantum(grid=64, method="KL8", dt=0.05, steps=40, x0=1.0, p0=0.5)
    b = nystrom.quantum(grid=64, method="KL8", dt=0.05, steps=40, psi0=3 * gauss)
    assert b.norm == pytest.approx(1, abs=1e-13)
    assert b.energy == pytest.approx(a.energy, abs=1e-12)
    assert b.mean_position[0] == pytest.approx(a.mean_position[0], abs=1e-12)
    assert math.isnan(b.exact_error)
    # an odd start relaxes to the first excited state, E = 3/2; a real array is accepted
    odd = nystrom.quantum(grid=64, imaginary_time=True, dt=0.1, steps=100, psi0=x * np.exp(-x * x / 3))
    assert odd.energy == pytest.approx(1.5, abs=1e-9)
    two = nystrom.quantum(dims=2, grid=16, box=12.0, steps=2, psi0=np.ones((16, 16), dtype=complex))
    assert two.norm == pytest.approx(1, abs=1e-13)
    for kwargs, match in ((dict(psi0=np.ones(63)), r"psi0 has shape \(63,\), expected \(64,\)"),
                          (dict(psi0=np.full(64, np.nan)), "the initial wave function is not finite"),
                          (dict(psi0=np.zeros(64)), "the initial wave function is zero"),
                          (dict(psi0=np.ones(64), x0=1.0), "psi0 replaces the Gaussian")):
        with pytest.raises(ValueError, match=match):
            nystrom.quantum(grid=64, steps=2, **kwargs)
    with pytest.raises(TypeError):
        nystrom.quantum(grid=64, steps=2, psi0=np.array(["a"] * 64))


def test_converge_stops_imaginary_time_at_the_ground_state():
    # from x0 = 0.5 (coherent state, excited weight 1/8): E - 1/2 = e^(-2 tau)/8, |dE/dtau| = 2 (E - 1/2), so the
    # criterion 1e-8 is met near tau = ln(2.5e7)/2 = 8.5, i.e. 170 steps of 0.05
    res = nystrom.quantum(grid=64, imaginary_time=True, x0=0.5, dt=0.05, steps=10000, converge=1e-8)
    assert res.converged is True and res.steps == 10000
    assert abs(res.steps_taken - 170) <= 9
    assert res.time == pytest.approx(0.05 * res.steps_taken, abs=1e-12)
    assert abs(res.energy - 0.5) < 1e-8
    short = nystrom.quantum(grid=64, imaginary_time=True, x0=0.5, dt=0.05, steps=20, converge=1e-8)
    assert short.converged is False and short.steps_taken == 20
    assert nystrom.quantum(steps=2).converged is None
    with pytest.raises(ValueError, match="needs imaginary time"):
        nystrom.quantum(steps=2, converge=1e-8)
    with pytest.raises(ValueError, match="converge must be positive"):
        nystrom.quantum(steps=2, imaginary_time=True, converge=0.0)


def test_docstring_examples_run():
    import doctest

    import nystrom._quantum as module

    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 10
    assert result.failed == 0
