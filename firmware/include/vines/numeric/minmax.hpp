// Maximum and minimum for the hot loops. std::fmax/fmin honour IEEE NaN rules
// and compile to library calls on x86-64; these are a compare and a select
// (one maxsd/minsd). For |x| use std::fabs: a bit mask, where a compare and
// select would keep the sign of -0 and cost a blend.
// With a NaN operand they return the second one: callers either cannot see a
// NaN there or catch it elsewhere (the loop's divergence check).
#pragma once

namespace vines::numeric {

template <typename S>
inline S max_of(S a, S b) { return a > b ? a : b; }
template <typename S>
inline S min_of(S a, S b) { return a < b ? a : b; }

}  // namespace vines::numeric
