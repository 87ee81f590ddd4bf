"""nystrom.methods(), method_info() and coeffs(): the catalog seen from Python."""
import json
import os
import subprocess
from fractions import Fraction

import pytest

import nystrom


def test_methods_lists_families_with_their_fields():
    cat = nystrom.methods()
    assert len(cat) >= 20
    keys = {"name", "family", "order", "stages", "forces_per_step", "fsal", "symmetric", "symplectic", "complex",
            "adaptive", "order_control", "published_digits", "tolerance_exponent", "aliases", "source", "description"}
    for m in cat:
        assert keys <= set(m)
        # The controller's tolerance exponent: in (0.5, 1] for an adaptive method, None for fixed steps.
        assert (m["tolerance_exponent"] is None) == (not m["adaptive"])
        assert m["tolerance_exponent"] is None or 0.5 <= m["tolerance_exponent"] <= 1
        assert m["family"] in {"splitting", "composition", "rkn", "mpe", "extrapolation"}
        assert m["order"] >= 2
    names = {m["name"]: m for m in cat}
    # Order control (the order chosen per step) is an adaptive multi-product expansion, the catalog's MPE-adaptive.
    assert {n for n, m in names.items() if m["order_control"]} == {"MPE-adaptive"}
    assert nystrom.method_info("MPE-adaptive-max:8")["order_control"] is True
    # Orders from the publications: Verlet 2, Forest-Ruth 4 (Chin 2010), DP12 12 (Dormand, El-Mikkawy, Prince).
    assert names["VV"]["order"] == 2 and names["PV"]["order"] == 2
    assert names["FR"]["order"] == 4 and names["FR"]["symplectic"]
    assert names["DP12"]["family"] == "rkn" and names["DP12"]["order"] == 12
    assert names["Chambers"]["complex"]
    # DP12's controller works to a calibrated tolerance (its global error grows faster than tol); DOP853's does not.
    assert names["DP12-adaptive"]["tolerance_exponent"] < 1 and names["DOP853-adaptive"]["tolerance_exponent"] == 1
    # GBS closes the list: adaptive in step and order, up to order 2 x 12 columns by default.
    assert cat[-1]["name"] == "GBS" and cat[-1]["family"] == "extrapolation"
    assert cat[-1]["order"] == 24 and cat[-1]["adaptive"] and cat[-1]["forces_per_step"] == 0


def test_method_info_resolves_specifications():
    m = nystrom.method_info("M8")
    assert m["family"] == "mpe" and m["order"] == 8
    # An MPE on position Verlet with sequence k costs sum(k) forces per step (Chin 2010, eq 17): 1+2+3+4.
    assert m["forces_per_step"] == 10
    assert nystrom.method_info("mpe:1,2,3")["order"] == 6
    with pytest.raises(ValueError, match="unknown method"):
        nystrom.method_info("NoSuchMethod")
    # GBS with its sequence and columns in the specification: the order it can reach is 2 x columns
    assert nystrom.method_info("GBS:bulirsch:10")["order"] == 20
    assert nystrom.method_info("gbs:romberg")["name"] == "GBS:romberg"
    with pytest.raises(ValueError, match="^GBS: unknown step-number sequence 'fibonacci'"):
        nystrom.method_info("GBS:fibonacci")
    with pytest.raises(ValueError, match="^GBS: the columns must be an integer between 3 and 20"):
        nystrom.method_info("GBS:harmonic:40")
    with pytest.raises(TypeError):
        nystrom.method_info(8)


def mpe_exact(k):
    # Chin (2010) eq (14): c_i = prod_{j != i} k_i^2 / (k_i^2 - k_j^2).
    out = []
    for i, ki in enumerate(k):
        c = Fraction(1)
        for j, kj in enumerate(k):
            if j != i:
                c *= Fraction(ki * ki, ki * ki - kj * kj)
        out.append(c)
    return out


@pytest.mark.parametrize("seq", [[1, 2], [1, 2, 3], [1, 2, 3, 4, 5], [2, 3, 5]])
def test_mpe_coefficients_are_the_exact_rationals(seq):
    d = nystrom.coeffs("mpe", seq=seq)
    assert d["sequence"] == seq
    assert d["order"] == 2 * len(seq)
    assert [Fraction(x) for x in d["coefficients"]] == mpe_exact(seq)
    assert d["force_evals_pv"] == sum(seq)


def test_mpe_coefficients_by_order_and_errors():
    assert nystrom.coeffs("mpe", order=6)["sequence"] == [1, 2, 3]
    with pytest.raises(ValueError):
        nystrom.coeffs("mpe", order=5)
    with pytest.raises(ValueError):
        nystrom.coeffs("mpe")
    with pytest.raises(ValueError):
        nystrom.coeffs("mpe", seq=[1, 1])


def test_method_coefficients_of_a_splitting_and_an_rkn():
    vv = nystrom.coeffs("VV")
    assert vv["family"] == "splitting"
    # Velocity Verlet: kick h/2, drift h, kick h/2.
    assert [(s["flow"], float(s["re"])) for s in vv["steps"]] == [("kick", 0.5), ("drift", 1.0), ("kick", 0.5)]
    fr = nystrom.coeffs("FR", digits=30)
    theta = 1 / (2 - 2 ** (1 / 3))
    drifts = [float(s["re"]) for s in fr["steps"] if s["flow"] == "drift"]
    assert drifts[0] == pytest.approx(theta / 2, rel=1e-15)
    assert sum(drifts) == pytest.approx(1.0, rel=1e-15)
    dp = nystrom.coeffs("DP12")
    assert dp["family"] == "rkn" and len(dp["c"]) == 17
    with pytest.raises(ValueError):
        nystrom.coeffs("VV", digits=0)


def test_bch_orders_and_leading_terms():
    # Velocity Verlet: second order, its degree-3 error terms are (1/12)[T,[T,V]]-type brackets (nonzero).
    vv = nystrom.bch("VV", degree=3)
    assert vv["order"] == 2 and vv["exact"]
    assert vv["leading"]["degree"] == 3 and vv["leading"]["norm"] > 0
    assert not vv["degrees"][2]["vanishes"]
    fr = nystrom.bch("FR", degree=5)
    assert fr["order"] == 4 and fr["declared_order"] == 4
    assert all(d["vanishes"] for d in fr["degrees"][:4])
    # Symmetric methods have no even-degree terms beyond the first.
    assert fr["degrees"][5 - 1]["vanishes"] is False
    with pytest.raises(ValueError, match="splitting methods"):
        nystrom.bch("DP12")
    with pytest.raises(ValueError):
        nystrom.bch("VV", degree=0)


def test_method_info_is_the_command_lines_record():
    # `nystrom methods SPEC --json` and method_info(SPEC) describe the same method with the same numbers
    tool = os.environ.get("NYSTROM_BIN")
    if not tool:
        pytest.skip("NYSTROM_BIN (the command-line tool) not set")
    specs = ["M12-adaptive", "mpe:1,2,3", "GBS:bulirsch:10", "DP12-adaptive", "adjoint:Y4"]
    out = subprocess.run([tool, "methods", *specs, "--json"], capture_output=True, text=True, check=True).stdout
    records = json.loads(out)
    assert len(records) == len(specs)
    for spec, cli in zip(specs, records):
        py = nystrom.method_info(spec)
        assert py == cli, spec
        # both records carry each library's name of the force count and of the velocity flag
        assert py["forces_per_step"] == py["force_evals_per_step"] and py["velocity"] == py["velocity_dependent"]
    # the same refusal, in the same words
    bad = subprocess.run([tool, "methods", "GBS:fibonacci"], capture_output=True, text=True)
    assert bad.returncode == 2
    with pytest.raises(ValueError) as e:
        nystrom.method_info("GBS:fibonacci")
    assert str(e.value) in bad.stderr
