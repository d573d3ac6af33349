// Grow: a list for the working storage of the batched searches
// (cycle_maxima.hpp, periodic_roots.hpp). It appends inline and never gives
// its storage back, so a list a thread keeps allocates nothing once warm.
#pragma once
#include <algorithm>
#include <cstddef>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

#include "mech/inline.hpp"

namespace mech {

// A list for the searches' working storage (mech::CycleScratch): appending
// is inline (std::vector's emplace_back stayed a call in the model's
// translation unit, 6% of a recuperative DOE design) and the storage is
// never given back. T: default-constructible (the storage is made ahead)
// and copyable.
template <class T>
class Grow {
 public:
  void clear() { n_ = 0; }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  T* begin() { return data_.data(); }
  T* end() { return data_.data() + n_; }
  const T* begin() const { return data_.data(); }
  const T* end() const { return data_.data() + n_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  operator std::span<T>() { return {begin(), n_}; }               // NOLINT: a view of the list
  operator std::span<const T>() const { return {begin(), n_}; }   // NOLINT
  MECH_FORCE_INLINE void push_back(const T& x) {
    if (n_ == room_) [[unlikely]] grow();
    data_[n_++] = x;
  }
  // Built in place (a root search: no copy of its ~200 bytes).
  template <class... A>
  MECH_FORCE_INLINE void emplace_back(A&&... a) {
    static_assert(std::is_trivially_destructible_v<T>);
    if (n_ == room_) [[unlikely]] grow();
    std::construct_at(&data_[n_++], std::forward<A>(a)...);
  }

 private:
  [[gnu::noinline]] void grow() {
    data_.resize(std::max<std::size_t>(16, 2 * data_.size()));
    room_ = data_.size();  // kept: data_.size() divides by sizeof(T) on every push
  }
  std::vector<T> data_;
  std::size_t n_ = 0, room_ = 0;
};

}  // namespace mech
