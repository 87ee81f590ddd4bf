// A uniform interface over the three engines: build any catalog method for a state type V and a
// force functor F, then step or integrate. The engine is chosen once, at construction; the hot
// loop runs inside the engine with the force inlined (dispatch is per integrate() call).
#pragma once

#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

#include "nystrom/core/bignum.hpp"
#include "nystrom/core/error.hpp"
#include "nystrom/engines/mpe.hpp"
#include "nystrom/engines/rkn.hpp"
#include "nystrom/engines/splitting.hpp"
#include "nystrom/methods/method.hpp"
#include "nystrom/methods/method_data.hpp"

namespace nystrom {

/// MPE coefficients c_i converted to S. Refuses orders whose rounding amplification sum|c_i| would
/// destroy more than half of the significant digits of S (amp * eps > sqrt(eps)): such an order is
/// "beyond what the scalar type can represent" (double: up to M56; float128: far beyond M100).
template <class S>
std::vector<S> mpe_coefficients_as(const MpeCoefficients& mc) {
  using T = real_t<S>;
  const double amp = mpe_amplification(mc);
  // amp * eps <= sqrt(eps), in logarithms (eps = 2^(1-bits) underflows a double beyond 1074 bits).
  if (!(std::log2(amp) <= 0.5 * static_cast<double>(scalar_traits<T>::bits() - 1)))
    throw std::invalid_argument("MPE order " + std::to_string(mc.order()) + " is beyond what " +
                                scalar_traits<T>::name() + " can represent: the coefficients amplify rounding by " +
                                std::to_string(amp) + " (use a wider --precision)");
  std::vector<S> c;
  mpfr_t x;
  mpfr_init2(x, static_cast<mpfr_prec_t>(reference_bits(scalar_traits<T>::bits())));
  for (const auto& q : mc.c) {
    mpfr_set_q(x, q.get_mpq_t(), MPFR_RNDN);
    c.push_back(S(from_mpfr_as<T>(x)));
  }
  mpfr_clear(x);
  return c;
}

template <class V, class F>
class Integrator {
 public:
  using scalar_type = typename V::value_type;
  using real_type = real_t<scalar_type>;

  Integrator(const MethodData& data, F force, EngineOptions opt = {}) : impl_(make(data, std::move(force), opt)) {}

  void integrate(State<V>& s, real_type h, long n) {
    std::visit([&](auto& e) { e.integrate(s, h, n); }, impl_);
  }
  void step(State<V>& s, real_type h) { integrate(s, h, 1); }
  long force_evals() const {
    return std::visit([](const auto& e) { return e.force_evals(); }, impl_);
  }
  F& force() {
    return std::visit([](auto& e) -> F& { return e.force(); }, impl_);
  }
  /// The compensated-summation carries of the run (checkpoint/restart).
  Compensator<V>& compensator() {
    return std::visit([](auto& e) -> Compensator<V>& { return e.compensator(); }, impl_);
  }

 private:
  using Impl = std::variant<SplittingStepper<V, F>, RknStepper<V, F>, MpeStepper<V, F>>;

  // A scheme normalised in high precision and rounded to the working type, with the coefficients' rounding
  // residuals: a run with a compensated force takes them (the rounded coefficients bias every step the same way,
  // below the plain force's rounding but above the compensated force's).
  static std::pair<SplittingScheme<scalar_type>, std::vector<scalar_type>> rounded_with_residuals(
      const SplittingScheme<bigcomplex>& scheme) {
    using S = scalar_type;
    const auto exact = normalized(scheme);
    auto rounded = convert_scheme<S>(exact, [](const bigcomplex& x) { return to_scalar<S>(x); });
    std::vector<S> lo;
    lo.reserve(exact.steps.size());
    for (std::size_t i = 0; i < exact.steps.size(); ++i)
      lo.push_back(rounding_residual(exact.steps[i].coef, rounded.steps[i].coef));
    return {std::move(rounded), std::move(lo)};
  }

  static Impl make(const MethodData& data, F force, EngineOptions opt) {
    using S = scalar_type;
    auto conv = [](const bigcomplex& x) { return to_scalar<S>(x); };
    if (const auto* sp = std::get_if<SplittingScheme<bigcomplex>>(&data)) {
      if constexpr (SplittingStepper<V, F>::carried_force) {
        auto [rounded, lo] = rounded_with_residuals(*sp);
        Impl impl(std::in_place_index<0>, std::move(rounded), std::move(force), opt);
        std::get<0>(impl).set_coefficient_residuals(std::move(lo));
        return impl;
      } else {
        return Impl(std::in_place_index<0>, convert_scheme<S>(*sp, conv), std::move(force), opt);
      }
    }
    if (const auto* t = std::get_if<RknTableau<bigcomplex>>(&data))
      return Impl(std::in_place_index<1>, convert_tableau<S>(*t, conv), std::move(force), opt);
    const auto& m = std::get<MpeDef>(data);
    const auto mc = mpe_coefficients(m.k);
    if constexpr (MpeStepper<V, F>::carried_force) {
      auto [rounded, lo] = rounded_with_residuals(m.base);
      Impl impl(std::in_place_index<2>, m.k, mpe_coefficients_as<S>(mc), std::move(rounded), std::move(force), opt);
      std::get<2>(impl).set_base_coefficient_residuals(std::move(lo));
      return impl;
    } else {
      return Impl(std::in_place_index<2>, m.k, mpe_coefficients_as<S>(mc), convert_scheme<S>(m.base, conv),
                  std::move(force), opt);
    }
  }

  Impl impl_;
};

/// Builds `def` for state type V at a reference precision matched to V's scalar type. Coefficients
/// published as decimals with too few digits for that type are refined (methods/refine.hpp), or
/// refused with std::invalid_argument when they cannot be.
/// An adaptive method (info.adaptive: "DP12-adaptive", "M12-adaptive", ...) is refused with
/// invalid_input: its step size comes from a tolerance, which solve() (nystrom/solve.hpp) handles.
template <class V, class F>
Integrator<V, F> make_integrator(const MethodDef& def, F force, EngineOptions opt = {}) {
  using T = real_t<typename V::value_type>;
  if (def.info.adaptive)
    throw invalid_input("method '" + def.info.name +
                        "' chooses its steps from a tolerance: run it with solve() (nystrom/solve.hpp), not with "
                        "fixed steps");
  const auto data = shared_method_data_for(def, scalar_traits<T>::bits(), scalar_traits<T>::name());
  // The working values are created outside method_data_for's reference precision: for
  // run-time-precision types (mpfr_real) it must not leak into the working precision.
  return Integrator<V, F>(*data, std::move(force), opt);
}

/// Any fixed-step method on a real state: a real method steps it directly; a complex-coefficient method
/// steps its complexified copy (rebind_vector_t<V, std::complex<T>>) and the real parts come back after
/// every call (the imaginary parts are dropped after every step inside the engine unless
/// EngineOptions::keep_complex). The one place where a real state meets a complex method.
template <class V, class F>
class RealStateIntegrator {
 public:
  using real_type = typename V::value_type;
  using VC = rebind_vector_t<V, std::complex<real_type>>;

  RealStateIntegrator(const MethodDef& def, F force, EngineOptions opt = {})
      : impl_(def.info.complex ? Impl(std::in_place_index<1>, make_integrator<VC>(def, std::move(force), opt))
                               : Impl(std::in_place_index<0>, make_integrator<V>(def, std::move(force), opt))) {}

  /// n steps of size h, in place.
  void integrate(State<V>& s, real_type h, long n) {
    if (auto* r = std::get_if<0>(&impl_)) {
      r->integrate(s, h, n);
    } else {
      auto sc = convert_state<VC>(s);
      std::get<1>(impl_).integrate(sc, h, n);
      s = convert_state<V>(sc);
    }
  }
  long force_evals() const {
    return std::visit([](const auto& e) { return e.force_evals(); }, impl_);
  }

 private:
  using Impl = std::variant<Integrator<V, F>, Integrator<VC, F>>;
  Impl impl_;
};

}  // namespace nystrom
