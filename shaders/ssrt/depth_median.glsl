// Shared by the ssrt depth filter passes (depth_merge / depth_bilateral / depth_final.comp):
// the lower median of up to 25 (or 9) depths held in registers, and the validity rule.
//
// Why a sorting network: on lavapipe an invocation is a SIMD lane, so data-dependent loops
// (insertion sort, nth_element) run as long as the slowest lane and index arrays dynamically
// (spilled to memory). A fixed network of min/max pairs on constant indices stays branch-free
// and in registers. Excluded taps are +inf, so the n included values sort to the front and the
// lower median of a variable count n is rank (n - 1) / 2 <= 12 (<= 4 for 9 taps): the networks
// below are Batcher's odd-even merge sort of 32 (16) inputs, with the comparators that only
// touch the always-+inf padding removed and then every comparator that cannot reach ranks
// 0..12 (0..4) pruned away (124 and 25 comparators; generated and checked exhaustively against
// a full sort on random inputs with +inf placed anywhere).
#ifndef MRGI_SSRT_DEPTH_MEDIAN_GLSL
#define MRGI_SSRT_DEPTH_MEDIAN_GLSL

#define MRGI_DEPTH_EXCLUDED uintBitsToFloat(0x7f800000u)  // +inf: sorts after every depth

// A depth is a measurement/surface when positive and finite (NaN compares false).
bool depth_valid(float d) { return d > 0.0f && !isinf(d); }

#define CX(a, b) { float lo_ = min(v[a], v[b]); v[b] = max(v[a], v[b]); v[a] = lo_; }

#define MRGI_SORT_LOWER_25 \
  CX(0,1) CX(2,3) CX(4,5) CX(6,7) CX(8,9) CX(10,11) CX(12,13) CX(14,15) CX(16,17) CX(18,19) \
  CX(20,21) CX(22,23) CX(0,2) CX(1,3) CX(4,6) CX(5,7) CX(8,10) CX(9,11) CX(12,14) CX(13,15) \
  CX(16,18) CX(17,19) CX(20,22) CX(21,23) CX(1,2) CX(5,6) CX(9,10) CX(13,14) CX(17,18) \
  CX(21,22) CX(0,4) CX(1,5) CX(2,6) CX(3,7) CX(8,12) CX(9,13) CX(10,14) CX(11,15) CX(16,20) \
  CX(17,21) CX(18,22) CX(19,23) CX(2,4) CX(3,5) CX(10,12) CX(11,13) CX(18,20) CX(19,21) \
  CX(1,2) CX(3,4) CX(5,6) CX(9,10) CX(11,12) CX(13,14) CX(17,18) CX(19,20) CX(21,22) CX(0,8) \
  CX(1,9) CX(2,10) CX(3,11) CX(4,12) CX(5,13) CX(6,14) CX(7,15) CX(16,24) CX(4,8) CX(5,9) \
  CX(6,10) CX(7,11) CX(20,24) CX(2,4) CX(3,5) CX(6,8) CX(7,9) CX(10,12) CX(11,13) CX(18,20) \
  CX(19,21) CX(22,24) CX(1,2) CX(3,4) CX(5,6) CX(7,8) CX(9,10) CX(11,12) CX(13,14) CX(17,18) \
  CX(19,20) CX(21,22) CX(23,24) CX(0,16) CX(1,17) CX(2,18) CX(3,19) CX(4,20) CX(5,21) CX(6,22) \
  CX(7,23) CX(8,24) CX(8,16) CX(9,17) CX(10,18) CX(11,19) CX(12,20) CX(13,21) CX(4,8) CX(5,9) \
  CX(6,10) CX(7,11) CX(12,16) CX(13,17) CX(2,4) CX(3,5) CX(6,8) CX(7,9) CX(10,12) CX(11,13) \
  CX(1,2) CX(3,4) CX(5,6) CX(7,8) CX(9,10) CX(11,12)

#define MRGI_SORT_LOWER_9 \
  CX(0,1) CX(2,3) CX(4,5) CX(6,7) CX(0,2) CX(1,3) CX(4,6) CX(5,7) CX(1,2) CX(5,6) CX(0,4) \
  CX(1,5) CX(2,6) CX(3,7) CX(2,4) CX(3,5) CX(1,2) CX(3,4) CX(5,6) CX(0,8) CX(4,8) CX(2,4) \
  CX(3,5) CX(1,2) CX(3,4)

// Lower median of the included (finite) entries of v; `count` of them, 1..25.
float lower_median25(float v[25], int count) {
  MRGI_SORT_LOWER_25
  int mid = (count - 1) / 2;
  float m = v[0];
  [[unroll]] for (int i = 1; i < 13; ++i) m = mid == i ? v[i] : m;  // selects, no dynamic index
  return m;
}

float lower_median9(float v[9], int count) {
  MRGI_SORT_LOWER_9
  int mid = (count - 1) / 2;
  float m = v[0];
  [[unroll]] for (int i = 1; i < 5; ++i) m = mid == i ? v[i] : m;
  return m;
}

#undef CX
#endif  // MRGI_SSRT_DEPTH_MEDIAN_GLSL
