#pragma once
// The fewest bytes one element of an LCM array takes on the wire, for the
// bounds lcmtypes/harden_decoders.cmake puts before every resize of a
// generated decoder: a count times this must fit in the bytes left.
#include <string>
#include <type_traits>
#include <vector>

namespace acyclic::lcm_wire {

template <class T, class = void>
struct MinSize {
  // A struct: its encoding with every string empty and every count zero.
  static int get() { return T{}._getEncodedSizeNoHash(); }
};
template <class T>
struct MinSize<T, std::enable_if_t<std::is_arithmetic_v<T>>> {
  static int get() { return static_cast<int>(sizeof(T)); }  // bool and int8_t: 1 byte, as on the wire
};
template <>
struct MinSize<std::string> {
  static int get() { return 5; }  // a length and the terminating NUL
};
template <class T>
struct MinSize<std::vector<T>> {
  // A row of a two-dimensional array: its length is checked where it is read.
  static int get() { return 1; }
};

// Whether `count` elements of the array `a` cannot be in `left` bytes.
template <class Array>
bool tooMany(int count, int left, const Array&) {
  using Element = typename std::remove_reference_t<Array>::value_type;
  return count < 0 || static_cast<long long>(count) * MinSize<Element>::get() > left;
}

}  // namespace acyclic::lcm_wire
