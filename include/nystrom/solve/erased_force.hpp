// A user's force behind one fixed interface, so that the drivers and engines of solve() are compiled once,
// in libnystrom, for every supported scalar type, instead of once per force in every program.
//
// ErasedForce<T> owns a copy of the user's callable (a lambda, capturing or not, or any functor) and calls
// it through a function pointer: force(t, q, a) on std::vector<T> states, force(t, q, v, a) when the
// force depends on the velocity, and force(q, a) or force(t, q, a) on complex states (and a complex time)
// when the callable accepts them (complex-coefficient methods). Copies are deep, as copies of the
// callable itself would be: an engine that gives each thread its own force (the concurrent multi-product
// schedule) gets its own copy of the user's functor, exactly as on the inline path.
//
// After every call the size of the output is checked: a force that assigns a vector of another size to `a`
// is refused with invalid_input instead of writing past the engine's buffers.
#pragma once

#include <complex>
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nystrom/core/error.hpp"
#include "nystrom/solve/problem.hpp"

namespace nystrom {

namespace erased_detail {
[[noreturn]] inline void resized(std::size_t got, std::size_t want) {
  throw invalid_input("the force changed the size of its output a from " + std::to_string(want) + " to " +
                      std::to_string(got) + " (write a[i], do not assign a new vector)");
}
}  // namespace erased_detail

template <class T>
class ErasedForce {
 public:
  using V = std::vector<T>;
  using C = std::complex<T>;
  using VC = std::vector<C>;

  ErasedForce() = default;

  /// Wraps a copy of f, a force for states V in any form of SecondOrderProblem (force(q, a),
  /// force(t, q, a), force(q, v, a) or force(t, q, v, a)); force(q, a) or force(t, q, a) on complex states
  /// and times when f accepts them.
  template <class F>
  requires(!std::is_same_v<std::decay_t<F>, ErasedForce>) explicit ErasedForce(const F& f)
      : obj_(new F(f)), ops_(&ops_for<F>) {}

  ErasedForce(const ErasedForce& o) : obj_(o.ops_ ? o.ops_->clone(o.obj_) : nullptr), ops_(o.ops_) {}
  ErasedForce(ErasedForce&& o) noexcept : obj_(std::exchange(o.obj_, nullptr)), ops_(std::exchange(o.ops_, nullptr)) {}
  ErasedForce& operator=(ErasedForce o) noexcept {
    std::swap(obj_, o.obj_);
    std::swap(ops_, o.ops_);
    return *this;
  }
  ~ErasedForce() {
    if (ops_) ops_->destroy(obj_);
  }

  /// Whether the wrapped force takes the time (force(t, q, a)).
  bool time_dependent() const { return ops_ && ops_->time_dependent; }
  /// Whether the wrapped force takes the velocity (force(q, v, a) or force(t, q, v, a)).
  bool velocity_dependent() const { return ops_ && ops_->velocity != nullptr; }
  /// Whether it accepts complex states (and a complex time if it takes the time): complex-coefficient
  /// methods.
  bool accepts_complex() const { return ops_ && ops_->complex != nullptr; }

  /// a = a(t, q) (t is ignored by a time-independent force).
  void operator()(const T& t, const V& q, V& a) {
    const std::size_t n = a.size();
    ops_->real(obj_, t, q, a);
    if (a.size() != n) erased_detail::resized(a.size(), n);
  }
  /// a = a(t, q, v) of a velocity-dependent force.
  void operator()(const T& t, const V& q, const V& v, V& a) {
    const std::size_t n = a.size();
    ops_->velocity(obj_, t, q, v, a);
    if (a.size() != n) erased_detail::resized(a.size(), n);
  }
  /// a = a(t, q) on complex states and times (t is ignored by a time-independent force); invalid_input when
  /// the force does not accept them.
  void operator()(const C& t, const VC& q, VC& a) {
    if (!accepts_complex())
      throw invalid_input(
          "this method has complex coefficients: its force must accept complex states (and a complex time if it "
          "depends on time: a generic lambda or a template operator())");
    const std::size_t n = a.size();
    ops_->complex(obj_, t, q, a);
    if (a.size() != n) erased_detail::resized(a.size(), n);
  }

 private:
  struct Ops {
    void (*real)(void*, const T&, const V&, V&);
    void (*velocity)(void*, const T&, const V&, const V&, V&);
    void (*complex)(void*, const C&, const VC&, VC&);
    void* (*clone)(const void*);
    void (*destroy)(void*);
    bool time_dependent;
  };
  template <class F>
  static constexpr Ops ops_for = {
      [] {
        if constexpr (VelocityForce<F, V>)
          return static_cast<void (*)(void*, const T&, const V&, V&)>(nullptr);
        else
          return +[](void* p, const T& t, const V& q, V& a) {
            F& f = *static_cast<F*>(p);
            if constexpr (AutonomousForce<F, V>) {
              (void)t;
              f(q, a);
            } else {
              f(t, q, a);
            }
          };
      }(),
      [] {
        if constexpr (VelocityForce<F, V>)
          return +[](void* p, const T& t, const V& q, const V& v, V& a) {
            F& f = *static_cast<F*>(p);
            if constexpr (AutonomousVelocityForce<F, V>) {
              (void)t;
              f(q, v, a);
            } else {
              f(t, q, v, a);
            }
          };
        else
          return static_cast<void (*)(void*, const T&, const V&, const V&, V&)>(nullptr);
      }(),
      [] {
        using Complex = void (*)(void*, const C&, const VC&, VC&);
        if constexpr (AutonomousForce<F, V> && std::is_invocable_v<F&, const VC&, VC&>)
          return Complex{+[](void* p, const C&, const VC& q, VC& a) { (*static_cast<F*>(p))(q, a); }};
        else if constexpr (TimeDependentForce<F, V> && std::is_invocable_v<F&, const C&, const VC&, VC&>)
          return Complex{+[](void* p, const C& t, const VC& q, VC& a) { (*static_cast<F*>(p))(t, q, a); }};
        else
          return Complex{nullptr};
      }(),
      [](const void* p) -> void* { return new F(*static_cast<const F*>(p)); },
      [](void* p) { delete static_cast<F*>(p); },
      !AutonomousForce<F, V>};

  void* obj_ = nullptr;
  const Ops* ops_ = nullptr;
};

/// The forms the compiled drivers are instantiated for: a time-independent force and a time-dependent one
/// (each with its complex form).
template <class T>
struct ErasedAutonomous {
  ErasedForce<T> f;
  void operator()(const std::vector<T>& q, std::vector<T>& a) { f(T(0), q, a); }
  void operator()(const std::vector<std::complex<T>>& q, std::vector<std::complex<T>>& a) {
    f(std::complex<T>(0), q, a);
  }
};
template <class T>
struct ErasedTimed {
  ErasedForce<T> f;
  void operator()(const T& t, const std::vector<T>& q, std::vector<T>& a) { f(t, q, a); }
  void operator()(const std::complex<T>& t, const std::vector<std::complex<T>>& q, std::vector<std::complex<T>>& a) {
    f(t, q, a);
  }
};
/// A velocity-dependent force (always given the time: one instantiation for both of its forms).
template <class T>
struct ErasedVelocity {
  ErasedForce<T> f;
  void operator()(const T& t, const std::vector<T>& q, const std::vector<T>& v, std::vector<T>& a) { f(t, q, v, a); }
};

/// A problem on std::vector<T> states with its force erased: what the compiled solve() receives.
template <class T>
struct ErasedProblem {
  ErasedForce<T> force;
  std::vector<T> q0, v0;
  T t0{}, t1{};
};

template <class V, class F>
ErasedProblem<typename V::value_type> erase(const SecondOrderProblem<V, F>& p) {
  using T = typename V::value_type;
  static_assert(!takes_carry_v<F, V>,
                "a compensated force, force(q, cq, a, alo), runs on the inline path, where the engines use its low "
                "parts: #include <nystrom/solve_inline.hpp> and call solve_inline() (the compiled drivers call "
                "force(q, a) only)");
  return {ErasedForce<T>(p.force), std::vector<T>(p.q0.begin(), p.q0.end()), std::vector<T>(p.v0.begin(), p.v0.end()),
          p.t0, p.t1};
}

}  // namespace nystrom
