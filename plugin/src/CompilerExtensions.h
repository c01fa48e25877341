// The one switch for compiler extensions in QuatHinge's own code. QUATHINGE_HAVE_VECTOR_EXTENSIONS is 1 with GCC and
// Clang (both define __GNUC__), 0 with any other compiler (MSVC) and in the portable build (-DQUATHINGE_PORTABLE=ON
// defines QUATHINGE_PORTABLE), which is then standard C++17 alone. Every extension the library and the stabilizer use
// sits behind it, with a standard fallback that computes the same values:
//   - GCC vector types and __builtin_shufflevector for SIMD lanes (MatrixLanes.h: the fallback is a four-scalar struct
//     doing the same IEEE operations lane by lane, so the same bits);
//   - QUATHINGE_ALWAYS_INLINE (__attribute__((always_inline))) and QUATHINGE_UNLIKELY (__builtin_expect): hints only,
//     empty in the fallback.
// Bullet's own macros (SIMD_FORCE_INLINE, ATTRIBUTE_ALIGNED16) are Bullet's and not switched here.
#ifndef QUATHINGE_COMPILER_EXTENSIONS_H
#define QUATHINGE_COMPILER_EXTENSIONS_H

#if defined(__GNUC__) && !defined(QUATHINGE_PORTABLE)
#define QUATHINGE_HAVE_VECTOR_EXTENSIONS 1
#else
#define QUATHINGE_HAVE_VECTOR_EXTENSIONS 0
#endif

#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
#define QUATHINGE_ALWAYS_INLINE __attribute__((always_inline))
#define QUATHINGE_UNLIKELY(condition) __builtin_expect(!!(condition), 0)
#else
#define QUATHINGE_ALWAYS_INLINE
#define QUATHINGE_UNLIKELY(condition) (condition)
#endif

#endif
