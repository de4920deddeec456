// A kernel's whole state as bytes and back, the byte writer and reader the
// 2D and 3D kernels' save_state/load_state share (world_state.cpp,
// sphere_world_state.cpp). Each kernel visits its members in one order with
// one function; a Writer appends them, a Reader takes them back. Numbers are
// stored as their bytes (native byte order): exact, and readable only by the
// same build, which is what the consolidation cache's key demands anyway. A
// state opens with an 8-byte mark of its kernel and layout, so another
// kernel's or another layout's bytes are refused, not misread.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "demcal/kernel/world.hpp"

namespace demcal::detail {

template <class T>
concept StateScalar = std::is_arithmetic_v<T> || std::is_enum_v<T>;

class StateWriter {
 public:
  /// Starts with the layout mark.
  explicit StateWriter(std::string_view mark) : out(mark) {}
  std::string out;

  template <StateScalar T>
  void operator()(const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <StateScalar T, class A>
  void operator()(const std::vector<T, A>& v) {
    (*this)(static_cast<uint64_t>(v.size()));
    out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
};

class StateReader {
 public:
  /// Bytes that do not open with `mark` fail; `what` names the kernel in the
  /// error (std::runtime_error).
  StateReader(std::string_view bytes, std::string_view mark, const char* what) : what_(what) {
    if (bytes.substr(0, mark.size()) != mark) fail();
    in_ = bytes.substr(mark.size());
  }

  template <StateScalar T>
  void operator()(T& v) {
    take(&v, sizeof(T));
  }
  template <StateScalar T, class A>
  void operator()(std::vector<T, A>& v) {
    uint64_t n = 0;
    (*this)(n);
    if (n > (in_.size() - at_) / sizeof(T)) fail();
    v.resize(n);
    take(v.data(), n * sizeof(T));
  }
  /// Throws unless every byte was read.
  void finish() const {
    if (at_ != in_.size()) fail();
  }
  /// Throws unless `fits` (sizes read that do not fit together).
  void require(bool fits) const {
    if (!fits) fail();
  }
  [[noreturn]] void fail() const {
    throw std::runtime_error(std::string(what_) + ": not the bytes of a saved state of this build");
  }

 private:
  void take(void* to, size_t n) {
    if (n > in_.size() - at_) fail();
    if (n) std::memcpy(to, in_.data() + at_, n);
    at_ += n;
  }
  const char* what_;
  std::string_view in_;
  size_t at_ = 0;
};

/// A kernel's save_state(): its `mark`, then the members `visit(writer)`
/// visits.
template <class Visit>
std::string write_state(std::string_view mark, Visit visit) {
  StateWriter writer(mark);
  visit(writer);
  return std::move(writer.out);
}

/// A kernel's load_state() up to its checks of the sizes read: `bytes` that
/// open with `mark`, the members `visit(reader)` visits, and not a byte more
/// (else std::runtime_error naming `what`). Returns the reader for those
/// checks (StateReader::require, fail).
template <class Visit>
StateReader read_state(std::string_view bytes, std::string_view mark, const char* what,
                       Visit visit) {
  StateReader reader(bytes, mark, what);
  visit(reader);
  reader.finish();
  return reader;
}

// The value types both kernels hold, visited in one place each. A new
// member must be visited here: the sizes catch one that is not (x86-64
// layouts).
static_assert(sizeof(ContactLaw) == 3 * sizeof(double));
static_assert(sizeof(KernelOptions) == 4 * sizeof(double) + 4 * sizeof(int));
static_assert(sizeof(Integration) == 5 * sizeof(double));

template <class Law, class Visitor>  // ContactLaw, const or not
void visit_law(Law& law, Visitor& v) {
  v(law.kn);
  v(law.kt);
  v(law.friction);
}

template <class Options, class Visitor>  // KernelOptions, const or not
void visit_options(Options& o, Visitor& v) {
  v(o.skin_ratio);
  v(o.max_overlap_ratio);
  v(o.check_interval);
  v(o.max_energy_ratio);
  v(o.max_energy_created);
  v(o.energy_check_interval);
  v(o.threads);
}

template <class In, class Visitor>  // Integration, const or not
void visit_integration(In& in, Visitor& v) {
  v(in.dt);
  v(in.damping_ratio_translation);
  v(in.damping_ratio_rotation);
  v(in.mass_scaling);
  v(in.lock_rotation);
}

}  // namespace demcal::detail
