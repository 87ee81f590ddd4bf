"""Lock discipline between the module and the library: threads mixing MPFR runs, Python forces, new method
specifications, dense output and the catalog finish (a watchdog process kills a deadlocked run)."""
import subprocess
import sys
import textwrap

STRESS = textwrap.dedent("""
    import sys, threading, time
    import nystrom
    from nystrom.problems import Kepler

    sys.setswitchinterval(1e-5)  # hand the GIL over as often as possible
    DURATION = float(sys.argv[1])
    stop = time.monotonic() + DURATION
    done = {}
    errors = []

    def loop(name, body):
        def run():
            i = 0
            try:
                while time.monotonic() < stop:
                    body(i)
                    i += 1
            except BaseException as e:  # reported by the parent
                errors.append(f"{name}: {type(e).__name__}: {e}")
            done[name] = i
        return threading.Thread(target=run, name=name)

    def mpfr(i):  # holds the library's MPFR precision lock for the whole run; Python runs in its heartbeat
        nystrom.solve(Kepler(0.5), t_span=(0, 1), method="M6", steps=64, precision="mpfr", bits=160 + i % 7,
                      progress=lambda t: None)

    def mpfr_dense(i):
        res = nystrom.solve(Kepler(0.3), t_span=(0, 1), method="FR", steps=16, precision="mpfr", bits=128,
                            dense_output=True)
        res.sol([0.25, 0.5])

    def python_force(offset):
        def body(i):  # a method specification not resolved before: its coefficients are built under the lock
            k = 3 + offset + 4 * (i % 40)
            nystrom.solve(lambda t, q: -q, [1.0], [0.0], t_span=(0, 1), method=f"mpe:1,2,{k}", steps=4,
                          events=lambda t, q, v: q[0] - 0.5)
        return body

    def catalog(i):
        nystrom.method_info(f"mpe:2,3,{5 + i % 50}")
        nystrom.coeffs("mpe", seq=[1, 2, 4 + i % 30])
        nystrom.coeffs(f"mpe:1,3,{6 + i % 30}", digits=30)
        nystrom.bch("FR", degree=3)

    threads = [loop("mpfr", mpfr), loop("mpfr_dense", mpfr_dense), loop("catalog", catalog)]
    threads += [loop(f"python_force_{j}", python_force(j)) for j in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        print("\\n".join(errors))
        sys.exit(1)
    print(" ".join(f"{k}={v}" for k, v in sorted(done.items())))
""")


def test_mixed_threads_never_deadlock(child_env):
    duration = 4.0
    try:
        out = subprocess.run([sys.executable, "-c", STRESS, str(duration)], env=child_env, capture_output=True,
                             text=True, timeout=duration + 90)
    except subprocess.TimeoutExpired:
        raise AssertionError("threads mixing MPFR runs, Python forces and new method specifications deadlocked")
    assert out.returncode == 0, out.stdout + out.stderr
    counts = dict(x.split("=") for x in out.stdout.split())
    assert len(counts) == 6 and all(int(v) >= 1 for v in counts.values()), out.stdout
