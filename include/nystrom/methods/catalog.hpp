// The method catalog: every named method, and the parser for method specifications.
//
// Specifications accepted by resolve_method():
//   NAME or alias         a catalog entry (see `nystrom methods`)
//   M<2n>                 natural-sequence MPE of any even order on position Verlet (M4 ... M16 listed)
//   mpe:1,2,4             MPE on position Verlet with the given sequence
//   mpe-vv:1,2,3          MPE on velocity Verlet
//   M<2n>-adaptive        natural-sequence MPE with adaptive steps (engines/adaptive_mpe.hpp; needs a tolerance)
//   mpe-adaptive:1,2,3    adaptive MPE on position Verlet (also mpe-pv-adaptive:), mpe-vv-adaptive: on velocity Verlet
//   MPE-adaptive          natural-sequence MPE on position Verlet with order (4..16) and step control per step
//   MPE-adaptive-max:P    the same with orders 4..P (P even, 4 to 16)
//   adjoint:NAME          the adjoint of a splitting method (sub-steps reversed)
//   file:PATH             a splitting method from a method file (nystrom/analysis/method_file.hpp, which
//                         must be included: it installs the reader, set_method_file_reader)
//   triplejump:P          Yoshida's triple jump of even order P on position Verlet (also triplejump-pv:P);
//   triplejump-vv:P       on velocity Verlet (compositions.hpp)
//   suzuki:P              Suzuki's 5-fold fractal composition of even order P on position Verlet
//   suzuki-vv:P           (also suzuki-pv:P) and on velocity Verlet
//
// The definitions are compiled in libnystrom (lib/catalog.cpp).
#pragma once

#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom {

namespace detail {
/// Fills the fields of MethodInfo that follow from the coefficients (stages, forces per step, FSAL,
/// complex; clears `symplectic` for complex methods whose imaginary parts are dropped).
void finalize_info(MethodDef& d);
}  // namespace detail

/// All named methods, with derived fields filled in. Built once.
const std::vector<MethodDef>& catalog();

/// What `nystrom methods` and nystrom.methods() list: the catalog, then GBS (the one method of solve()
/// without a coefficient table; its cost per step varies with its order, listed as 0 stages and forces).
std::vector<MethodDef> listed_methods();

/// Resolves a method specification (see the top of this file). Throws nystrom::invalid_input.
MethodDef resolve_method(const std::string& spec);

/// The Gragg-Bulirsch-Stoer extrapolation integrator (engines/gbs.hpp) as a method for solve(): adaptive
/// step and order, tolerances rtol and atol (family "extrapolation"; its data is the GbsDef: the step-number
/// sequence and the columns of the table). Named "GBS" with the defaults, else "GBS:SEQUENCE[:COLUMNS]".
MethodDef gbs_method_def(const GbsDef& gbs = {});

/// The multi-product expansion over Gragg's modified midpoint rule with sequence k (engines/mpe_midpoint.hpp):
/// order 2 k.size(), for velocity-dependent forces and first-order systems, with fixed steps
/// ("mpe-midpoint:1,2,3") or adaptive ("mpe-midpoint-adaptive:1,2,3,4", at least two products; the error
/// estimate drops the largest k); family "mpe-midpoint", resolved by resolve_solve_method only, since it runs
/// through solve().
MethodDef midpoint_mpe_method_def(const std::vector<long>& k, const std::string& name, bool adaptive = false);

/// The multi-product expansion over Verlet with the sequence of a midpoint one, for forces a(t, q):
/// "mpe:1,2,3" for "mpe-midpoint:1,2,3", "mpe-adaptive:1,2,3" for "mpe-midpoint-adaptive:1,2,3".
std::string verlet_mpe_counterpart(const MethodDef& midpoint);

/// The names of the methods that integrate velocity-dependent forces a(t, q, v) (MethodInfo::velocity):
/// those of the catalog and GBS.
std::vector<std::string> velocity_methods();

/// The one-line refusal of method `name` for a velocity-dependent force, naming the methods that accept
/// one (the same text in C++, Python and the command-line tool).
std::string velocity_refusal(const std::string& name);

/// The one-line refusal of method `name` for a first-order system y' = f(t, y) (which runs with the same
/// methods).
std::string first_order_refusal(const std::string& name);
/// Throws invalid_input with that line unless the method integrates first-order systems (also declared in
/// the light <nystrom/solve.hpp>).
void require_first_order(const MethodDef& method);
void require_first_order(const std::string& method);

/// What solve() resolves: resolve_method(spec), "GBS", "GBS:SEQUENCE" or "GBS:SEQUENCE:COLUMNS" for the
/// extrapolation integrator (sequence harmonic, romberg or bulirsch; columns 3 to 20, default harmonic:12), and
/// "mpe-midpoint:K1,K2,..." and "mpe-midpoint-adaptive:K1,K2,..." (midpoint_mpe_method_def).
MethodDef resolve_solve_method(const std::string& spec);

/// Reads the method file of a "file:PATH" specification. The method-file format, which verifies a file's
/// declared order by the BCH expansion, lives above the methods (analysis/method_file.hpp); including
/// that header installs its reader here, so that resolving a catalog method never compiles the BCH
/// machinery. Without a reader, resolve_method refuses "file:" specifications.
using MethodFileReader = MethodDef (*)(const std::string& path);
void set_method_file_reader(MethodFileReader reader);

}  // namespace nystrom
