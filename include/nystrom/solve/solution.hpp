// What solve() returns: the saved states, the located events, the dense output, the counts and the
// status of a run (Solution), and the event functions it locates (Event).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "nystrom/core/scalar.hpp"
#include "nystrom/core/state.hpp"
#include "nystrom/solve/checkpoint.hpp"
#include "nystrom/solve/dense.hpp"

namespace nystrom {

/// An event function g(t, q, v): its zeros are located (direction: +1 rising only, -1 falling only,
/// 0 both); a terminal event ends the integration there.
template <class V>
struct Event {
  using real_type = real_t<typename V::value_type>;
  std::string name;
  std::function<real_type(const real_type& t, const V& q, const V& v)> g;
  int direction = 0;
  bool terminal = false;
};

template <class V>
struct EventHit {
  using real_type = real_t<typename V::value_type>;
  std::string name;
  std::size_t index = 0;  // which event
  real_type t{};
  V q, v;
};

enum class SolveStatus { success, terminated_by_event, failed };

template <class V>
struct Solution {
  using real_type = real_t<typename V::value_type>;
  std::vector<real_type> t;
  std::vector<V> q, v;
  /// The state where the integration ended (t1, a terminal event, or the last saved state of a failed run).
  real_type t_final{};
  V q_final, v_final;
  long force_evals = 0;         // by the method: every stage, rejected steps and starting-step estimates
                                // (a failed run: those up to the failure)
  long output_force_evals = 0;  // at step ends for the dense output and events
  long accepted = 0, rejected = 0;
  /// Adaptive multi-product methods: whether the products carried their own rounding (precise products: a run in
  /// float or double whose controlled tolerance is at most 1e4 eps, e.g. M12-adaptive at tolerances of 9e-12 and
  /// below, or at every tolerance with a compensated force; AdaptiveMpeIntegrator::precise_products). False for every
  /// other method.
  bool precise_products = false;
  SolveStatus status = SolveStatus::success;
  std::string message;
  std::vector<EventHit<V>> events;
  DenseOutput<V> dense;
  std::optional<Checkpoint<real_type>> checkpoint;

  /// The state at any t within the integrated span.
  State<V> operator()(const real_type& tt) const { return dense(tt); }
};

}  // namespace nystrom
