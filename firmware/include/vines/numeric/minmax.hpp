// Maximum and minimum for the hot loops. std::fmax/fmin honour IEEE NaN rules
// and compile to library calls on x86-64; these are a compare and a select.
// With a NaN operand they return the second one: callers either cannot see a
// NaN there or catch it elsewhere (the loop's divergence check).
#pragma once

namespace vines::numeric {

template <typename S>
inline S max_of(S a, S b) { return a > b ? a : b; }
template <typename S>
inline S min_of(S a, S b) { return a < b ? a : b; }
template <typename S>
inline S abs_of(S a) { return a < S(0) ? -a : a; }

}  // namespace vines::numeric
