#pragma once
// Two doubles at a time for the MARS processor's inner loops, without giving up bit-identical results.

#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace marsala::detail {

// Two doubles at once: GCC/Clang vector extensions (SSE2 on x86-64, NEON on AArch64, plain code elsewhere).
// Only exactly rounded operations (+ - *), element by element, so every value is the scalar one.
typedef double Pair __attribute__((vector_size(16)));

inline Pair load(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline void store(double* p, Pair v) { std::memcpy(p, &v, sizeof v); }

// Element-wise a[k] > b[k] ? a[k] : b[k] (SSE2's maxpd): b on ties, so max(v, x) keeps x's bits when v == x.
inline Pair max(Pair a, Pair b) {
#if defined(__SSE2__)
  return reinterpret_cast<Pair>(_mm_max_pd(reinterpret_cast<__m128d>(a), reinterpret_cast<__m128d>(b)));
#else
  return Pair{a[0] > b[0] ? a[0] : b[0], a[1] > b[1] ? a[1] : b[1]};
#endif
}

// All bits of lane k set when a[k] > b[k], else none (lanes as doubles: only either() and any_set() read them).
inline Pair greater_mask(Pair a, Pair b) {
#if defined(__SSE2__)
  return reinterpret_cast<Pair>(_mm_cmpgt_pd(reinterpret_cast<__m128d>(a), reinterpret_cast<__m128d>(b)));
#else
  std::uint64_t m[2] = {a[0] > b[0] ? ~std::uint64_t{0} : 0, a[1] > b[1] ? ~std::uint64_t{0} : 0};
  Pair v;
  std::memcpy(&v, m, sizeof v);
  return v;
#endif
}

// Lane-wise OR of two greater_mask() results.
inline Pair either(Pair a, Pair b) {
#if defined(__SSE2__)
  return reinterpret_cast<Pair>(_mm_or_pd(reinterpret_cast<__m128d>(a), reinterpret_cast<__m128d>(b)));
#else
  std::uint64_t x[2], y[2];
  std::memcpy(x, &a, sizeof x);
  std::memcpy(y, &b, sizeof y);
  x[0] |= y[0];
  x[1] |= y[1];
  std::memcpy(&a, x, sizeof x);
  return a;
#endif
}

// True when some lane of a greater_mask() result is set.
inline bool any_set(Pair m) {
#if defined(__SSE2__)
  return _mm_movemask_pd(reinterpret_cast<__m128d>(m)) != 0;
#else
  std::uint64_t x[2];
  std::memcpy(x, &m, sizeof x);
  return (x[0] | x[1]) != 0;
#endif
}

// Bit k set when a[k] > b[k], k = 0, 1.
inline unsigned greater(Pair a, Pair b) {
#if defined(__SSE2__)
  return static_cast<unsigned>(
      _mm_movemask_pd(_mm_cmpgt_pd(reinterpret_cast<__m128d>(a), reinterpret_cast<__m128d>(b))));
#else
  return static_cast<unsigned>(a[0] > b[0]) | static_cast<unsigned>(a[1] > b[1]) << 1;
#endif
}

}  // namespace marsala::detail
