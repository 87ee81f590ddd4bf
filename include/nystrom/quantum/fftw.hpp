// FFTW for the quantum layer: the double (fftw_) and long double (fftwl_) interfaces behind one traits
// class, an allocator with FFTW's alignment (so one plan serves every wave function of a grid through
// the new-array execute functions), threaded plans and an optional wisdom file.
//
// Link: -lfftw3 (double), -lfftw3l (long double), and -lfftw3_threads / -lfftw3l_threads with
// NYSTROM_HAVE_FFTW_THREADS defined (cmake/NystromDeps.cmake: target nystrom::fftw).
#pragma once

#include <complex>
#include <cstddef>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <fftw3.h>

namespace nystrom::quantum {

template <class R>
struct FftwTraits;

template <>
struct FftwTraits<double> {
  using plan = fftw_plan;
  using complex = fftw_complex;
  static void* malloc(std::size_t n) { return fftw_malloc(n); }
  static void free(void* p) { fftw_free(p); }
  static plan plan_dft(int rank, const int* n, complex* in, complex* out, int sign, unsigned flags) {
    return fftw_plan_dft(rank, n, in, out, sign, flags);
  }
  static void execute(const plan p, complex* in, complex* out) { fftw_execute_dft(p, in, out); }
  static void destroy(plan p) { fftw_destroy_plan(p); }
  static int import_wisdom(const char* f) { return fftw_import_wisdom_from_filename(f); }
  static int export_wisdom(const char* f) { return fftw_export_wisdom_to_filename(f); }
#ifdef NYSTROM_HAVE_FFTW_THREADS
  static int init_threads() { return fftw_init_threads(); }
  static void plan_with_nthreads(int n) { fftw_plan_with_nthreads(n); }
#endif
};

template <>
struct FftwTraits<long double> {
  using plan = fftwl_plan;
  using complex = fftwl_complex;
  static void* malloc(std::size_t n) { return fftwl_malloc(n); }
  static void free(void* p) { fftwl_free(p); }
  static plan plan_dft(int rank, const int* n, complex* in, complex* out, int sign, unsigned flags) {
    return fftwl_plan_dft(rank, n, in, out, sign, flags);
  }
  static void execute(const plan p, complex* in, complex* out) { fftwl_execute_dft(p, in, out); }
  static void destroy(plan p) { fftwl_destroy_plan(p); }
  static int import_wisdom(const char* f) { return fftwl_import_wisdom_from_filename(f); }
  static int export_wisdom(const char* f) { return fftwl_export_wisdom_to_filename(f); }
#ifdef NYSTROM_HAVE_FFTW_THREADS
  static int init_threads() { return fftwl_init_threads(); }
  static void plan_with_nthreads(int n) { fftwl_plan_with_nthreads(n); }
#endif
};

/// std::allocator with FFTW's SIMD alignment.
template <class T>
struct FftwAllocator {
  using value_type = T;
  FftwAllocator() = default;
  template <class U>
  FftwAllocator(const FftwAllocator<U>&) {}
  T* allocate(std::size_t n) {
    void* p = FftwTraits<double>::malloc(n * sizeof(T));
    if (!p) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) { FftwTraits<double>::free(p); }
  template <class U>
  bool operator==(const FftwAllocator<U>&) const {
    return true;
  }
};

/// A wave function (or any complex field) on a grid, row-major, last axis fastest (FFTW's order).
template <class R>
using Field = std::vector<std::complex<R>, FftwAllocator<std::complex<R>>>;

/// How plans are made.
struct FftOptions {
  int threads = 1;          // FFTW threads per transform (ignored without NYSTROM_HAVE_FFTW_THREADS)
  bool measure = false;     // FFTW_MEASURE instead of FFTW_ESTIMATE (slower to plan, faster to run)
  std::string wisdom_file;  // read before planning and written after, when not empty
};

/// The FFTW planner is not thread-safe: every plan is made and destroyed under this lock.
inline std::mutex& fftw_planner_mutex() {
  static std::mutex m;
  return m;
}

/// The transforms of one grid as the flows see them: forward and backward in place on the points this
/// process holds, which are the flat (row-major) indices [first(), first() + local_size()) of the grid, and
/// the sum of a few numbers over all processes. FftPair holds the whole grid; a distributed grid
/// (quantum/fftw_mpi.hpp) holds a slab of the first axis per MPI rank, in position and Fourier space alike.
template <class R>
class FftTransforms {
 public:
  virtual ~FftTransforms() = default;
  /// Unnormalised: backward(forward(f)) = N f, N the points of the whole grid.
  virtual void forward(Field<R>& f) const = 0;
  virtual void backward(Field<R>& f) const = 0;
  virtual std::size_t first() const = 0;
  virtual std::size_t local_size() const = 0;
  /// x_i <- sum over the processes of x_i, i < n (nothing to do on one process).
  virtual void sum(R* x, int n) const = 0;
};

/// Forward and backward in-place transforms of one shape, usable on every Field of that shape.
template <class R>
class FftPair final : public FftTransforms<R> {
 public:
  using traits = FftwTraits<R>;

  FftPair(const std::vector<int>& shape, const FftOptions& opt) {
    for (int n : shape) total_ *= static_cast<std::size_t>(n);
    Field<R> scratch(total_);
    std::lock_guard<std::mutex> lock(fftw_planner_mutex());
#ifdef NYSTROM_HAVE_FFTW_THREADS
    static const bool threads_ok = traits::init_threads() != 0;
    if (threads_ok) traits::plan_with_nthreads(opt.threads > 0 ? opt.threads : 1);
#endif
    if (!opt.wisdom_file.empty()) traits::import_wisdom(opt.wisdom_file.c_str());
    const unsigned flags = opt.measure ? FFTW_MEASURE : FFTW_ESTIMATE;
    auto* p = reinterpret_cast<typename traits::complex*>(scratch.data());
    fwd_ = traits::plan_dft(static_cast<int>(shape.size()), shape.data(), p, p, FFTW_FORWARD, flags);
    bwd_ = traits::plan_dft(static_cast<int>(shape.size()), shape.data(), p, p, FFTW_BACKWARD, flags);
    if (!fwd_ || !bwd_) throw std::runtime_error("FFTW could not plan the transform");
    if (!opt.wisdom_file.empty()) traits::export_wisdom(opt.wisdom_file.c_str());
  }
  FftPair(const FftPair&) = delete;
  FftPair& operator=(const FftPair&) = delete;
  ~FftPair() {
    std::lock_guard<std::mutex> lock(fftw_planner_mutex());
    if (fwd_) traits::destroy(fwd_);
    if (bwd_) traits::destroy(bwd_);
  }

  void forward(Field<R>& f) const override {
    auto* p = reinterpret_cast<typename traits::complex*>(f.data());
    traits::execute(fwd_, p, p);
  }
  void backward(Field<R>& f) const override {
    auto* p = reinterpret_cast<typename traits::complex*>(f.data());
    traits::execute(bwd_, p, p);
  }
  std::size_t first() const override { return 0; }
  std::size_t local_size() const override { return total_; }
  void sum(R*, int) const override {}

 private:
  std::size_t total_ = 1;
  typename traits::plan fwd_{}, bwd_{};
};

}  // namespace nystrom::quantum
