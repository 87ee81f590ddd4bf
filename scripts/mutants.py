#!/usr/bin/env python3
"""Mechanical mutation testing: mutants sampled from a seed, nobody chooses them.

    python3 scripts/mutants.py --seed 1 --count 60            # sample, build, run, report
    python3 scripts/mutants.py --seed 1 --count 60 --list     # the sample only (no build)
    python3 scripts/mutants.py --seed 1 --count 60 --only 3,17 # some mutants of that sample
    python3 scripts/mutants.py --seed 7 --count 3 --layers core,operators --max-seconds 170   # CI's sample
    python3 scripts/mutants.py --replay build/mutants/report-1.json   # that sample again, on today's code

Every mutation site of the library's code is enumerated in a fixed order, then `--count` of them are
drawn with random.Random(seed). The code is include/nystrom/{engines,solve,operators,quantum,planetary,core}/
and lib/; comments, string and character literals and preprocessor lines are never mutated. The
operators (clang-format puts spaces around every binary operator, which tells a binary `*` from a
pointer and a comparison `<` from a template bracket):

    arith    a binary + - * / (or += -= *= /=) replaced by its opposite (+ <-> -, * <-> /)
    compare  < <-> <=, > <-> >=, == <-> !=
    logic    && <-> ||, true <-> false
    literal  a numeric literal perturbed: an integer n -> n + 1; a decimal's last digit + 1 (9 -> 8)
    drop     a term of a sum dropped: `a + b * c` -> `a` (the term runs to the next + or - at its depth)
    swap     two neighbouring arguments of a call swapped: f(a, b) -> f(b, a)
    negate   the condition of an if or while negated: if (c) -> if (!(c))

Each mutant is applied to a copy of the sources (build/mutants/src, never the working tree), and the test
programs of the mutated file's layer (LAYERS below) are rebuilt (with libstdc++'s assertions, so that an
index out of bounds stops the program as the sanitizer build of CI would) and run whole, without a filter, each with
a time limit (five times its unmutated time, at least 60 s). A mutant that does not compile is skipped and
counted apart; it is killed when one of its programs fails or runs out of time. Before the first mutant the
unmutated programs must pass. The build is -O0 without precompiled headers (build/mutants/obj, ccache when
installed): a mutant in a header that lib/ compiles rebuilds the library objects that include it. The
report goes to build/mutants/report-<seed>.json and ends with the line

    killed K of M mechanically generated mutants (seed S, E equivalent)

where M counts the mutants that compiled and E those of the survivors that EQUIVALENT lists (a mutant is
named by file, line and its text, so the list survives unrelated edits elsewhere in the file). The exit
status is 1 when a survivor is not listed as equivalent.

A sample is drawn from the sites of the code of its day: once the code changes, the same seed draws other
mutants. --replay runs the mutants of a report again (each found by the text of its line, the nearest one to
its recorded line when several match; a mutant whose line is gone is counted apart), so that a sample's
score can be re-measured after every change. Its report goes to build/mutants/replay-<seed>.json.
"""

import argparse
import glob
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCOPE_DIRS = ["include/nystrom/engines", "include/nystrom/solve", "include/nystrom/operators",
              "include/nystrom/quantum", "include/nystrom/planetary", "include/nystrom/core", "lib"]

# Files compiled by no library test program (they are exercised through the command-line tool only, whose
# tests this script does not build): a mutant there could not be killed by the layer's programs.
EXCLUDED = {
    "include/nystrom/quantum/fftw_mpi.hpp",  # MPI ranks of `nystrom quantum` (test_quantum_cli)
}

# file -> layer: the first matching prefix wins. layer -> the test programs run whole for its mutants.
# A program is in a layer when it reaches that layer's code and builds and runs in seconds at -O0.
FILE_LAYER = [
    ("include/nystrom/engines/step_control.hpp", "step_control"),
    ("include/nystrom/engines/adaptive_rkn.hpp", "adaptive_rkn"),
    ("include/nystrom/engines/embedded_pair.hpp", "adaptive_rkn"),
    ("include/nystrom/engines/adaptive_mpe", "adaptive_mpe"),
    ("include/nystrom/engines/gbs.hpp", "gbs"),
    ("include/nystrom/engines/mpe_midpoint.hpp", "velocity"),
    ("include/nystrom/engines/options.hpp", "options"),
    ("include/nystrom/engines/rkn.hpp", "rkn"),
    ("include/nystrom/engines/", "engines"),
    ("include/nystrom/solve/odeint.hpp", "odeint"),
    ("include/nystrom/solve/checkpoint.hpp", "checkpoint"),
    ("include/nystrom/solve/", "solve"),
    ("lib/catalog.cpp", "catalog"),
    ("lib/method_data.cpp", "catalog"),
    ("lib/", "solve"),
    ("include/nystrom/operators/", "operators"),
    ("include/nystrom/quantum/", "quantum"),
    ("include/nystrom/planetary/", "planetary"),
    ("include/nystrom/core/files.hpp", "files"),
    ("include/nystrom/core/", "core"),
]
LAYERS = {
    "engines": ["test_engines", "test_compensated", "test_carry", "test_engine_edges"],
    "rkn": ["test_engines", "test_compensated", "test_carry", "test_engine_edges", "test_adaptive_rkn"],
    "step_control": ["test_adaptive_rkn", "test_adaptive_mpe", "test_adaptive_cost", "test_carry",
                     "test_solve_directions"],
    "adaptive_rkn": ["test_adaptive_rkn", "test_adaptive_cost", "test_carry", "test_solve_directions", "test_velocity"],
    "adaptive_mpe": ["test_adaptive_mpe", "test_adaptive_cost", "test_carry", "test_solve_directions"],
    "gbs": ["test_gbs", "test_adaptive_cost", "test_engine_edges", "test_solve_directions"],
    "solve": ["test_solve", "test_dense", "test_solve_directions", "test_velocity"],
    "checkpoint": ["test_solve", "test_solve_directions", "test_files"],
    "odeint": ["test_solve_odeint"],
    "catalog": ["test_engines", "test_properties", "test_catalog_specs"],
    "operators": ["test_operators"],
    "quantum": ["test_quantum", "test_diffusion"],
    "velocity": ["test_velocity", "test_solve_directions"],
    "options": ["test_gbs", "test_adaptive_rkn", "test_adaptive_mpe", "test_engine_edges"],
    "planetary": ["test_planetary", "test_engine_edges"],
    "files": ["test_files"],
    "core": ["test_precision", "test_compensated", "test_carry", "test_engine_edges"],
}

# Survivors shown equivalent: (file, line text stripped, mutated text stripped) -> the reason.
EQUIVALENT = {
    ("include/nystrom/engines/mpe.hpp", "bool lockstep_ = false, concurrent_ = false;",
     "bool lockstep_ = false, concurrent_ = true;"):
    "the only constructor assigns concurrent_ before any use: the default member initializer is never read",
    ("include/nystrom/engines/step_control.hpp", "hmax_ = opt.h_max > 0 ? std::min(span, R(opt.h_max)) : span;",
     "hmax_ = opt.h_max > 0 ? std::min(R(opt.h_max), span) : span;"):
    "std::min of two finite values (AdaptiveOptions::validate) is the same value in either order",
    ("include/nystrom/planetary/kepler_drift.hpp", "inline constexpr std::size_t kKeplerBatch = 8;",
     "inline constexpr std::size_t kKeplerBatch = 9;"):
    "the batch size of the short-drift path only groups orbits, each computed from its own data alone, in a loop "
    "that takes any batch size: the same results",
    ("include/nystrom/solve/drivers.hpp", "return dir > 0 ? t : T(-t);", "return dir >= 0 ? t : T(-t);"):
    "the direction is +1 or -1, never 0 (solve_run sets it from the sign of t1 - t0, 1 when they are equal; the "
    "converters start at 1): the two tests agree on every value it takes",
    ("include/nystrom/solve/drivers.hpp",
     "const R hk = (opt.steps <= 0 && k == n - 1) ? R((tau1 - tau0) - h * R(n - 1)) : h;",
     "const R hk = (opt.steps <= 1 && k == n - 1) ? R((tau1 - tau0) - h * R(n - 1)) : h;"):
    "it differs only for steps = 1, where the one step's length is h = |t1 - t0| / 1 and the mutant's is "
    "(tau1 - tau0) - 0 h with tau = +-t: the same number, since negation is exact and rounding is symmetric",
    ("include/nystrom/engines/gbs.hpp", "out.q[c] = std::min(t, clock_end_);", "out.q[c] = std::min(clock_end_, t);"):
    "std::min of two numbers is the same number in either order; the two differ only for equal zeros of opposite "
    "sign (a clock that reaches t1 = 0 gives the force t = +0 or -0, the same time) or a NaN clock (a failed step, "
    "refused either way)",
    ("include/nystrom/planetary/kepler_drift.hpp", "if (f < 0 || (!std::isfinite(static_cast<double>(f)) && s < 0))",
     "if (f <= 0 || (!std::isfinite(static_cast<double>(f)) && s < 0))"):
    "they differ only for f = 0 exactly, which never reaches the line: the convergence test just before it "
    "accepts |f| <= 4 eps (...) when f and r are finite, and an f of 0 with an r that is not finite cannot occur "
    "(r's G-functions g1, g2 enter f with g3, and overflow together)",
    ("include/nystrom/core/files.hpp", "out.resize(std::min(max_bytes + 1, out.size() * 2 + 4096));",
     "out.resize(std::min(out.size() * 2 + 4096, max_bytes + 1));"):
    "std::min of two values is the same value in either order",
    ("include/nystrom/quantum/schrodinger.hpp", "if (g_ != 0 && step_ > 0) {", "if (g_ != 0 || step_ > 0) {"):
    "for g = 0 the chemical-potential shift is never read (apply_b's linear branch does not use it, and "
    "chemical_potential_shift() has no caller), so accumulating it there changes no result",
}


def layer_of(path):
    for prefix, layer in FILE_LAYER:
        if path.startswith(prefix):
            return layer
    raise SystemExit(f"mutants: no layer for {path}")


def programs_of(layer, available):
    return [p for p in LAYERS[layer] if p in available]


# ---------------------------------------------------------------------------------------------------------
# Masking: a copy of the text in which comments, strings, character literals and preprocessor lines are
# blanked (same length, line breaks kept), so that the patterns below see code only.


def mask(text):
    out = list(text)
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start:
            j = i
            while j < n and text[j] in " \t":
                j += 1
            if j < n and text[j] == "#":  # preprocessor line, with its continuations
                k = j
                while k < n:
                    if text[k] == "\n" and text[k - 1] != "\\":
                        break
                    if text[k] != "\n":
                        out[k] = " "
                    k += 1
                i = k
                continue
            line_start = False
        if c == "\n":
            line_start = True
            i += 1
        elif text.startswith("//", i):
            while i < n and text[i] != "\n":
                out[i] = " "
                i += 1
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            for k in range(i, j):
                if text[k] != "\n":
                    out[k] = " "
            i = j
        elif c == 'R' and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            d = text.index("(", i)
            delim = ")" + text[i + 2:d] + '"'
            j = text.find(delim, d)
            j = n if j < 0 else j + len(delim)
            for k in range(i, j):
                if text[k] != "\n":
                    out[k] = " "
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            for k in range(i, min(j + 1, n)):
                out[k] = " "
            i = j + 1
        else:
            i += 1
    return "".join(out)


# ---------------------------------------------------------------------------------------------------------
# Mutation sites. Each is (offset, length, replacement, kind) in the file's text.

NUM = re.compile(r"(?<![\w.])(\d+\.\d*(?:[eE][-+]?\d+)?|\d*\.\d+(?:[eE][-+]?\d+)?|\d+(?:[eE][-+]?\d+)?)"
                 r"([fFlLuU]*)(?![\w.])")
BIN = re.compile(r"(?<=[\w)\]]) (\+|-|\*|/|\+=|-=|\*=|/=|<|<=|>|>=|==|!=|&&|\|\|) (?=[\w(!.:\-~*&])")
BOOL = re.compile(r"\b(true|false)\b")
COND = re.compile(r"\b(if|while)( constexpr)? \(")
OPPOSITE = {"+": "-", "-": "+", "*": "/", "/": "*", "+=": "-=", "-=": "+=", "*=": "/=", "/=": "*=",
            "<": "<=", "<=": "<", ">": ">=", ">=": ">", "==": "!=", "!=": "==", "&&": "||", "||": "&&"}
KIND = {"+": "arith", "-": "arith", "*": "arith", "/": "arith", "+=": "arith", "-=": "arith", "*=": "arith",
        "/=": "arith", "<": "compare", "<=": "compare", ">": "compare", ">=": "compare", "==": "compare",
        "!=": "compare", "&&": "logic", "||": "logic"}
CLOSERS = {")": "(", "]": "[", "}": "{"}


def match_paren(m, i):
    """Index of the bracket closing the one at m[i]."""
    depth = 0
    for j in range(i, len(m)):
        if m[j] in "([{":
            depth += 1
        elif m[j] in ")]}":
            depth -= 1
            if depth == 0:
                return j
    return -1


def term_end(m, i):
    """End of the additive term starting at i: the next top-level + - , ; ) ] } ? : or comparison."""
    depth = 0
    j = i
    n = len(m)
    while j < n:
        c = m[j]
        if c in "([{":
            depth += 1
        elif c in ")]}":
            if depth == 0:
                return j
            depth -= 1
        elif depth == 0:
            if c in ",;?" or c == "\n" and False:
                return j
            if c == " " and j + 2 < n:
                for op in (" + ", " - ", " < ", " > ", " <= ", " >= ", " == ", " != ", " && ", " || ", " = ",
                           " ? ", " : ", " += ", " -= ", " << ", " >> "):
                    if m.startswith(op, j):
                        return j
        j += 1
    return -1


def split_args(m, open_i, close_i):
    """Top-level argument spans [(a, b)] of the call whose parentheses are at open_i, close_i."""
    spans = []
    depth = 0
    start = open_i + 1
    for j in range(open_i + 1, close_i):
        c = m[j]
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "<" and m[j - 1] != " " and depth == 0:
            return []  # template arguments: too easy to misread
        elif c == "," and depth == 0:
            spans.append((start, j))
            start = j + 1
    spans.append((start, close_i))
    return spans


def sites(path, text):
    m = mask(text)
    out = []
    for mo in BIN.finditer(m):
        op = mo.group(1)
        a = mo.start(1)
        out.append((a, len(op), OPPOSITE[op], KIND[op]))
        if op in ("+", "-"):  # drop the term after the operator
            e = term_end(m, mo.end())
            if e > mo.end():
                out.append((mo.start(), e - mo.start(), "", "drop"))
    for mo in BOOL.finditer(m):
        out.append((mo.start(), len(mo.group(1)), "false" if mo.group(1) == "true" else "true", "logic"))
    for mo in NUM.finditer(m):
        s = mo.group(1)
        if re.fullmatch(r"\d+", s):
            if len(s) > 1 and s.startswith("0"):
                continue  # octal
            new = str(int(s) + 1)
        else:
            mant = re.match(r"[\d.]+", s).group(0)
            k = max(i for i, ch in enumerate(mant) if ch.isdigit())
            d = int(mant[k])
            new = s[:k] + str(d + 1 if d < 9 else 8) + s[k + 1:]
        out.append((mo.start(1), len(s), new, "literal"))
    for mo in COND.finditer(m):
        o = mo.end() - 1
        c = match_paren(m, o)
        if c < 0:
            continue
        inner = text[o + 1:c]
        if ";" in m[o + 1:c]:
            continue  # if (init; cond)
        out.append((o + 1, c - o - 1, "!(" + inner + ")", "negate"))
    for mo in re.finditer(r"[\w>]\(", m):
        o = mo.end() - 1
        word = re.search(r"(\w+)\s*$", m[:o])
        if word and word.group(1) in ("if", "while", "for", "switch", "return", "sizeof", "decltype", "catch",
                                      "static_assert", "requires", "alignof", "noexcept", "defined"):
            continue
        c = match_paren(m, o)
        if c < 0:
            continue
        args = split_args(m, o, c)
        if len(args) < 2:
            continue
        for (a0, a1), (b0, b1) in zip(args, args[1:]):
            x, y = text[a0:a1].strip(), text[b0:b1].strip()
            if not x or not y or x == y or "\n" in text[a0:b1]:
                continue
            lead = len(text[a0:a1]) - len(text[a0:a1].lstrip())
            out.append((a0 + lead, b1 - a0 - lead, y + ", " + x, "swap"))
    return sorted(set(out))


def enumerate_sites(root):
    files = []
    for d in SCOPE_DIRS:
        full = os.path.join(root, d)
        for name in sorted(os.listdir(full)):
            if name.endswith((".hpp", ".cpp")):
                rel = f"{d}/{name}"
                if rel not in EXCLUDED:
                    files.append(rel)
    allsites = []
    for rel in files:
        with open(os.path.join(root, rel)) as f:
            text = f.read()
        for s in sites(rel, text):
            allsites.append((rel, *s))
    return allsites


def describe(root, site):
    rel, off, length, new, kind = site
    with open(os.path.join(root, rel)) as f:
        text = f.read()
    line = text.count("\n", 0, off) + 1
    ls = text.rfind("\n", 0, off) + 1
    le = text.find("\n", off + length)
    le = len(text) if le < 0 else le
    before = text[ls:le]
    after = text[ls:off] + new + text[off + length:le]
    return {"file": rel, "line": line, "kind": kind, "before": before.strip(), "after": after.strip(),
            "layer": layer_of(rel)}


def relocate(root, m):
    """The site of a recorded mutant (a report's file, line, before and after) in today's sources: the line
    whose text is `before` (the one nearest the recorded line when several are), replaced whole by `after`
    with its indentation kept. None when no such line is left (the code changed)."""
    with open(os.path.join(root, m["file"])) as f:
        text = f.read()
    starts, pos = [], 0
    for line in text.split("\n"):
        if line.strip() == m["before"]:
            starts.append((pos, line))
        pos += len(line) + 1
    if not starts:
        return None
    best = min(starts, key=lambda sl: abs(text.count("\n", 0, sl[0]) + 1 - m["line"]))
    off = best[0] + len(best[1]) - len(best[1].lstrip())
    return (m["file"], off, len(best[1].strip()), m["after"], m["kind"])


def sample(root, seed, count, layers=None):
    allsites = enumerate_sites(root)
    if layers:
        allsites = [s for s in allsites if layer_of(s[0]) in layers]
    rng = random.Random(seed)
    picked = rng.sample(allsites, min(count, len(allsites)))
    return allsites, picked


# ---------------------------------------------------------------------------------------------------------
# Build and run.


def run(cmd, log, timeout=None, cwd=None):
    t0 = time.time()
    try:
        r = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, timeout=timeout, cwd=cwd)
        return r.returncode, time.time() - t0
    except subprocess.TimeoutExpired:
        return "timeout", time.time() - t0


def summarize(results, build, args, allsites, final, name="report"):
    """Writes the report (after every mutant, so that a stopped run keeps what it measured)."""
    killed = sum(r["verdict"] == "killed" for r in results)
    equivalent = sum(r["verdict"] == "equivalent" for r in results)
    survived = [r for r in results if r["verdict"] == "survived"]
    invalid = sum(r["verdict"] == "does not compile" for r in results)
    notrun = sum(r["verdict"] == "not run" for r in results)
    gone = sum(r["verdict"] == "gone" for r in results)
    compiled = killed + equivalent + len(survived)
    report = {"seed": args.seed, "count": args.count, "sites": len(allsites), "killed": killed,
              "compiled": compiled, "equivalent": equivalent, "does_not_compile": invalid, "not_run": notrun,
              "gone": gone, "mutants": results}
    os.makedirs(build, exist_ok=True)
    if getattr(args, "replay", None) and name == "report":
        name = "replay"
    out = os.path.join(build, f"{name}-{args.seed}.json")
    with open(out + ".tmp", "w") as f:
        json.dump(report, f, indent=1)
    os.replace(out + ".tmp", out)
    line = f"killed {killed} of {compiled} mechanically generated mutants (seed {args.seed}, {equivalent} equivalent)"
    if not final:
        return survived, line
    for r in survived:
        print(f"survivor {r['number']}: {r['file']}:{r['line']} '{r['before']}' -> '{r['after']}'")
    print(f"{invalid} did not compile" + (f", {notrun} not run (time budget)" if notrun else "") +
          (f", {gone} gone (their line changed since the sample was drawn)" if gone else "") + f"; report: {out}")
    print(line)
    return survived, line


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=60)
    ap.add_argument("--layers", help="comma-separated layers to sample from (default: all)")
    ap.add_argument("--only", help="comma-separated 1-based numbers of the sample to run")
    ap.add_argument("--run-layers", help="run only the mutants of the sample in these layers (comma-separated; the "
                                         "sample is the same as without it)")
    ap.add_argument("--list", action="store_true", help="print the sample, build nothing")
    ap.add_argument("--build", default=os.environ.get("NYSTROM_MUTANTS_DIR", "build/mutants"))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--max-seconds", type=float, default=0,
                    help="stop starting mutants after this many seconds (those not run are reported)")
    ap.add_argument("--lib-solve", default="double",
                    help="the lib/solve_<type>.cpp the scratch library compiles (comma-separated, or none)")
    ap.add_argument("--without", default="", help="comma-separated test programs to leave out of every layer")
    ap.add_argument("--keep-src", action="store_true", help="reuse the copy of the sources as it is")
    ap.add_argument("--replay", metavar="JSON",
                    help="run the mutants of this report again on today's sources and tests (the same sample after "
                         "the code changed: each found by its line's text; one whose line is gone is reported so); "
                         "--only selects by the report's numbers")
    ap.add_argument("--report", nargs="+", metavar="JSON",
                    help="merge these reports of one seed (e.g. two runs of disjoint --only sets) and summarise them "
                         "with today's EQUIVALENT table; builds nothing")
    args = ap.parse_args()
    os.chdir(ROOT)
    # A stop (Ctrl-C or kill) still restores the mutated file of the copy (the finally below).
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    if args.report:
        results, allsites = {}, []
        for path in args.report:
            with open(path) as f:
                rep = json.load(f)
            if rep["seed"] != args.seed:
                raise SystemExit(f"mutants: {path} is of seed {rep['seed']}, not {args.seed}")
            allsites = range(rep["sites"])
            for r in rep["mutants"]:
                if r["verdict"] != "not run":
                    results[r["number"]] = r
        merged = []
        for n in sorted(results):
            r = results[n]
            key = (r["file"], r["before"], r["after"])
            if r["verdict"] in ("survived", "equivalent"):
                r["verdict"] = "equivalent" if key in EQUIVALENT else "survived"
                if key in EQUIVALENT:
                    r["reason"] = EQUIVALENT[key]
            merged.append(r)
        for r in merged:
            if r["verdict"] == "equivalent":
                print(f"equivalent {r['number']}: {r['file']}:{r['line']} '{r['before']}' -> '{r['after']}': {r['reason']}")
        args.build = os.path.abspath(args.build)
        survived, _ = summarize(merged, args.build, args, allsites, final=True, name="merged")
        return 1 if survived else 0
    layers = set(args.layers.split(",")) if args.layers else None
    if layers and not layers <= set(LAYERS):
        raise SystemExit(f"mutants: unknown layer in {args.layers} (layers: {', '.join(sorted(LAYERS))})")
    if args.replay:
        with open(args.replay) as f:
            rep = json.load(f)
        args.seed, args.count = rep["seed"], rep["count"]
        allsites = range(rep["sites"])
        recorded = {r["number"]: r for r in rep["mutants"] if r["verdict"] not in ("does not compile", "not run")}
        picked = [None] * max(recorded, default=0)
        muts = [None] * len(picked)
        for n, r in recorded.items():
            picked[n - 1] = relocate(ROOT, r)
            muts[n - 1] = describe(ROOT, picked[n - 1]) if picked[n - 1] else {
                k: r[k] for k in ("file", "line", "kind", "before", "after", "layer")}
    else:
        allsites, picked = sample(ROOT, args.seed, args.count, layers)
        muts = [describe(ROOT, s) for s in picked]
    if args.list:
        print(f"{len(allsites)} mutation sites; seed {args.seed}, {len(picked)} drawn")
        for i, d in enumerate(muts, 1):
            print(f"{i:3d} {d['kind']:8s} {d['file']}:{d['line']} [{d['layer']}]\n      - {d['before']}\n"
                  f"      + {d['after']}")
        return 0
    only = [int(x) for x in args.only.split(",")] if args.only else range(1, len(picked) + 1)
    only = [i for i in only if 1 <= i <= len(muts) and muts[i - 1] is not None]
    if args.run_layers:
        only = [i for i in only if muts[i - 1]["layer"] in args.run_layers.split(",")]
    t_start = time.time()

    build = os.path.abspath(args.build)
    src, obj = os.path.join(build, "src"), os.path.join(build, "obj")
    os.makedirs(build, exist_ok=True)
    log_path = os.path.join(build, f"mutants-{args.seed}.log")
    log = open(log_path, "w")
    if not args.keep_src or not os.path.isdir(src):
        # A copy of the sources (tracked and untracked, not ignored), refreshed file by file: unchanged files
        # keep their time stamps, so the build folder stays valid between runs.
        files = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                               capture_output=True, check=True).stdout.decode().split("\0")
        for rel in filter(None, files):
            if not os.path.isfile(rel):
                continue
            dst = os.path.join(src, rel)
            with open(rel, "rb") as f:
                data = f.read()
            try:
                with open(dst, "rb") as f:
                    if f.read() == data:
                        continue
            except FileNotFoundError:
                os.makedirs(os.path.dirname(dst), exist_ok=True)
            with open(dst, "wb") as f:
                f.write(data)
        # The layers' programs call the compiled solve() on std::vector<double> only: the scratch library
        # compiles that instantiation alone (lib/solve_double.cpp; --lib-solve), a sixth of the cost of a mutant
        # in a header of the drivers or engines. A program that needs another fails to link in the unmutated
        # build, which stops the run.
        cm = os.path.join(src, "CMakeLists.txt")
        with open(cm) as f:
            text = f.read()
        keep = args.lib_solve.split(",") if args.lib_solve != "none" else []
        text2 = re.sub(r"\s*lib/solve_(\w+)\.cpp", lambda mo: mo.group(0) if mo.group(1) in keep else "", text)
        if text2 != text:
            with open(cm, "w") as f:
                f.write(text2)
    cfg = ["cmake", "-S", src, "-B", obj, "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_CXX_FLAGS_RELEASE=-O0 -D_GLIBCXX_ASSERTIONS",
           "-DNYSTROM_PCH=OFF", "-DNYSTROM_BUILD_TESTS=ON", "-DNYSTROM_TEST_SCOPE=library",
           "-DNYSTROM_BUILD_TOOL=OFF", "-DNYSTROM_BUILD_BENCH=OFF", "-DNYSTROM_BUILD_EXAMPLES=OFF"]
    if shutil.which("ninja"):
        cfg += ["-G", "Ninja"] if not os.path.exists(os.path.join(obj, "CMakeCache.txt")) else []
    if shutil.which("ccache"):
        cfg.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
    rc, _ = run(cfg, log)
    if rc != 0:
        raise SystemExit(f"mutants: cmake failed (log: {log_path})")
    available = set(os.path.basename(n)[:-4] for n in glob.glob(os.path.join(src, "tests", "*", "test_*.cpp"))) - set(
        args.without.split(","))

    def build_targets(targets):
        return run(["cmake", "--build", obj, "-j", str(args.jobs), "--target", *targets], log)[0] == 0

    def run_programs(progs, limits):
        for p in progs:
            log.write(f"--- {p}\n")
            log.flush()
            rc, dt = run([os.path.join(obj, "tests", p)], log, timeout=limits.get(p), cwd=obj)
            if rc != 0:
                return f"killed by {p}" + (" (timeout)" if rc == "timeout" else f" (exit {rc})"), dt
        return None, 0

    # The unmutated programs pass, and their times set the limits.
    needed = sorted({p for i in only for p in programs_of(muts[i - 1]["layer"], available)})
    print(f"mutants: building {len(needed)} unmutated test programs in {obj}", flush=True)
    if not build_targets(needed):
        raise SystemExit(f"mutants: the unmutated sources do not build (log: {log_path})")
    limits, times = {}, {}
    for p in needed:
        rc, dt = run([os.path.join(obj, "tests", p)], log, cwd=obj)
        if rc != 0:
            raise SystemExit(f"mutants: the unmutated {p} fails (log: {log_path})")
        limits[p], times[p] = max(60.0, 5 * dt), dt
    print("mutants: unmutated programs pass (" + ", ".join(f"{p} {times[p]:.1f} s" for p in needed) + ")",
          flush=True)

    results = []
    for i in only:
        d = dict(muts[i - 1], number=i)
        if picked[i - 1] is None:
            d["verdict"] = "gone"
            results.append(d)
            print(f"mutant {i}: gone (no line '{d['before']}' in {d['file']} today)", flush=True)
            continue
        rel, off, length, new, kind = picked[i - 1]
        if args.max_seconds and time.time() - t_start > args.max_seconds:
            d["verdict"] = "not run"
            results.append(d)
            continue
        progs = programs_of(d["layer"], available)
        target = os.path.join(src, rel)
        with open(target) as f:
            original = f.read()
        t0 = time.time()
        try:
            with open(target, "w") as f:
                f.write(original[:off] + new + original[off + length:])
            log.write(f"=== mutant {i}: {rel}:{d['line']}: {d['after']}\n")
            log.flush()
            if not build_targets(progs):
                d["verdict"] = "does not compile"
            else:
                why, _ = run_programs(progs, limits)
                d["verdict"] = "killed" if why else "survived"
                if why:
                    d["by"] = why
        finally:
            with open(target, "w") as f:
                f.write(original)
        key = (rel, d["before"], d["after"])
        if d["verdict"] == "survived" and key in EQUIVALENT:
            d["verdict"] = "equivalent"
            d["reason"] = EQUIVALENT[key]
        d["seconds"] = round(time.time() - t0, 1)
        results.append(d)
        print(f"mutant {i}: {d['verdict']}{' ' + d['by'] if 'by' in d else ''} in {d['seconds']} s: "
              f"{rel}:{d['line']} ({kind}) '{d['before']}' -> '{d['after']}'", flush=True)
        summarize(results, build, args, allsites, final=False)

    survived, line = summarize(results, build, args, allsites, final=True)
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
