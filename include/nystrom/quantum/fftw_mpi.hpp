// A grid distributed over MPI ranks: FFTW's MPI transforms on a slab decomposition along the first axis.
// Rank r holds the rows [first_r, first_r + rows_r) of the first axis (fftw_mpi_local_size), in position
// space and, since the output is not transposed, in Fourier space too, so the flows' diagonal factors and
// the observables need only the global indices of their points; sums (norm, energy, <x>, <p>) are
// MPI_Allreduce over the communicator.
//
// Only this header needs MPI: link -lfftw3_mpi -lfftw3l_mpi and MPI (cmake/NystromDeps.cmake: target
// nystrom::fftw_mpi, NYSTROM_MPI). The caller initialises MPI before and finalises it after.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <fftw3-mpi.h>
#include <mpi.h>

#include "nystrom/quantum/fftw.hpp"
#include "nystrom/quantum/grid.hpp"

namespace nystrom::quantum {

template <class R>
struct FftwMpiTraits;

template <>
struct FftwMpiTraits<double> {
  using plan = fftw_plan;
  using complex = fftw_complex;
  static void init() { fftw_mpi_init(); }
  static std::ptrdiff_t local_size(int rank, const std::ptrdiff_t* n, MPI_Comm c, std::ptrdiff_t* n0,
                                   std::ptrdiff_t* start) {
    return fftw_mpi_local_size(rank, n, c, n0, start);
  }
  static plan plan_dft(int rank, const std::ptrdiff_t* n, complex* p, MPI_Comm c, int sign, unsigned flags) {
    return fftw_mpi_plan_dft(rank, n, p, p, c, sign, flags);
  }
  static void execute(const plan p, complex* x) { fftw_mpi_execute_dft(p, x, x); }
  static void destroy(plan p) { fftw_destroy_plan(p); }
  static MPI_Datatype datatype() { return MPI_DOUBLE; }
};

template <>
struct FftwMpiTraits<long double> {
  using plan = fftwl_plan;
  using complex = fftwl_complex;
  static void init() { fftwl_mpi_init(); }
  static std::ptrdiff_t local_size(int rank, const std::ptrdiff_t* n, MPI_Comm c, std::ptrdiff_t* n0,
                                   std::ptrdiff_t* start) {
    return fftwl_mpi_local_size(rank, n, c, n0, start);
  }
  static plan plan_dft(int rank, const std::ptrdiff_t* n, complex* p, MPI_Comm c, int sign, unsigned flags) {
    return fftwl_mpi_plan_dft(rank, n, p, p, c, sign, flags);
  }
  static void execute(const plan p, complex* x) { fftwl_mpi_execute_dft(p, x, x); }
  static void destroy(plan p) { fftwl_destroy_plan(p); }
  static MPI_Datatype datatype() { return MPI_LONG_DOUBLE; }
};

/// In-place transforms of a grid of 2 or 3 dimensions distributed over the ranks of `comm` (collective:
/// every rank constructs it and calls forward(), backward() and sum() in the same order). The wisdom file
/// of FftOptions is not used.
template <class R>
class MpiFftPair final : public FftTransforms<R> {
 public:
  using traits = FftwMpiTraits<R>;

  MpiFftPair(const std::vector<int>& shape, const FftOptions& opt, MPI_Comm comm) : comm_(comm) {
    if (shape.size() < 2) throw std::invalid_argument("a distributed grid needs 2 or 3 dimensions");
    int ranks = 1;
    MPI_Comm_size(comm_, &ranks);
    if (shape[0] < ranks)
      throw std::invalid_argument("the grid has fewer points per axis (" + std::to_string(shape[0]) +
                                  ") than MPI ranks (" + std::to_string(ranks) + ")");
    std::vector<std::ptrdiff_t> n(shape.begin(), shape.end());
    std::lock_guard<std::mutex> lock(fftw_planner_mutex());
    static const bool initialised = (traits::init(), true);
    (void)initialised;
    std::ptrdiff_t rows = 0, start = 0;
    const std::ptrdiff_t alloc = traits::local_size(static_cast<int>(n.size()), n.data(), comm_, &rows, &start);
    std::size_t row = 1;
    for (std::size_t a = 1; a < n.size(); ++a) row *= static_cast<std::size_t>(n[a]);
    first_ = static_cast<std::size_t>(start) * row;
    local_ = static_cast<std::size_t>(rows) * row;
    // FFTW may need more room than the slab for its transposes: then the transforms run in a buffer
    direct_ = static_cast<std::size_t>(alloc) <= local_;
    buffer_.resize(std::max<std::size_t>(static_cast<std::size_t>(alloc), local_ + 1));
    auto* p = reinterpret_cast<typename traits::complex*>(buffer_.data());
    const unsigned flags = opt.measure ? FFTW_MEASURE : FFTW_ESTIMATE;
    fwd_ = traits::plan_dft(static_cast<int>(n.size()), n.data(), p, comm_, FFTW_FORWARD, flags);
    bwd_ = traits::plan_dft(static_cast<int>(n.size()), n.data(), p, comm_, FFTW_BACKWARD, flags);
    if (!fwd_ || !bwd_) throw std::runtime_error("FFTW could not plan the distributed transform");
  }
  MpiFftPair(const MpiFftPair&) = delete;
  MpiFftPair& operator=(const MpiFftPair&) = delete;
  ~MpiFftPair() override {
    std::lock_guard<std::mutex> lock(fftw_planner_mutex());
    if (fwd_) traits::destroy(fwd_);
    if (bwd_) traits::destroy(bwd_);
  }

  void forward(Field<R>& f) const override { execute(fwd_, f); }
  void backward(Field<R>& f) const override { execute(bwd_, f); }
  std::size_t first() const override { return first_; }
  std::size_t local_size() const override { return local_; }
  void sum(R* x, int n) const override { MPI_Allreduce(MPI_IN_PLACE, x, n, traits::datatype(), MPI_SUM, comm_); }

 private:
  void execute(typename traits::plan plan, Field<R>& f) const {
    if (f.size() != local_) throw std::invalid_argument("field and distributed grid differ in size");
    if (direct_) {  // f is allocated by fftw_malloc, aligned as the planning array
      traits::execute(plan, reinterpret_cast<typename traits::complex*>(f.data()));
      return;
    }
    std::copy(f.begin(), f.end(), buffer_.begin());
    traits::execute(plan, reinterpret_cast<typename traits::complex*>(buffer_.data()));
    std::copy(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(local_), f.begin());
  }

  MPI_Comm comm_;
  std::size_t first_ = 0, local_ = 0;
  bool direct_ = false;
  mutable Field<R> buffer_;
  typename traits::plan fwd_{}, bwd_{};
};

/// The transforms for QuantumProblem::transforms on the ranks of `comm`: a slab per rank for 2 and 3
/// dimensions; in 1D (where FFTW's MPI transforms change the distribution between input and output), and on
/// one rank, every rank holds the whole grid and computes the same result.
template <class R>
std::function<std::unique_ptr<FftTransforms<R>>(const Grid<R>&, const FftOptions&)> distributed_transforms(
    MPI_Comm comm) {
  return [comm](const Grid<R>& g, const FftOptions& opt) -> std::unique_ptr<FftTransforms<R>> {
    int ranks = 1;
    MPI_Comm_size(comm, &ranks);
    if (g.dims == 1 || ranks == 1) return std::make_unique<FftPair<R>>(g.shape(), opt);
    return std::make_unique<MpiFftPair<R>>(g.shape(), opt, comm);
  };
}

}  // namespace nystrom::quantum
