// SIMD lanes for the packet kernels and the wide BVH: GCC/Clang generic vectors of kLanes floats,
// included inside an instruction-set namespace (see isa.hpp) that defines kLanes. Arithmetic on
// these types is IEEE single precision lane by lane with no contraction (-ffp-contract=off), so a
// lane computes the very bits the scalar code computes from the same operands in the same order.
//
// No include guard: included once per namespace of lanes, in its instruction set's target.

typedef float F __attribute__((vector_size(4 * kLanes)));
typedef std::int32_t I __attribute__((vector_size(4 * kLanes)));  // lane masks: -1 true, 0 false
typedef std::uint32_t U __attribute__((vector_size(4 * kLanes)));

// Every lane x: one broadcast instruction where the set has one. (Not F{} + x: an addition of zero,
// which the compiler may not fold away, costs an instruction per use and turns -0 into +0; and GCC 12
// builds a vector initialised lane by lane from inserts.)
// By the vector's size, as lane_bits below.
template <class V>
inline V lane_splat(float x) {
#if defined(CELLRT_SIMD_AVX512)
    if constexpr (sizeof(V) == 64) return reinterpret_cast<V>(_mm512_set1_ps(x));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    if constexpr (sizeof(V) == 32) return reinterpret_cast<V>(_mm256_set1_ps(x));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2) || defined(CELLRT_SIMD_SSE)
    if constexpr (sizeof(V) == 16) return reinterpret_cast<V>(_mm_set1_ps(x));
#endif
    V v;
    for (int i = 0; i < static_cast<int>(sizeof(V) / 4); ++i) v[i] = x;
    return v;
}
inline F splat(float x) { return lane_splat<F>(x); }
inline I splat_i(std::int32_t x) { return I{} + x; }
inline U splat_u(std::uint32_t x) { return U{} + x; }
inline I mask_of(bool b) { return splat_i(b ? -1 : 0); }

// Bit i set when lane i of the mask is true: one instruction where the set has one (the including
// file defines CELLRT_SIMD_SSE, _AVX2 or _AVX512 when it compiles for that set). By the vector's
// size, so that a unit can hold lanes of two widths (the packets' and the wide BVH's eight).
template <class V>
inline unsigned lane_bits(V m) {
#if defined(CELLRT_SIMD_AVX512)
    if constexpr (sizeof(V) == 64) return _mm512_movepi32_mask(reinterpret_cast<__m512i>(m));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    if constexpr (sizeof(V) == 32) return static_cast<unsigned>(_mm256_movemask_ps(reinterpret_cast<__m256>(m)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2) || defined(CELLRT_SIMD_SSE)
    if constexpr (sizeof(V) == 16) return static_cast<unsigned>(_mm_movemask_ps(reinterpret_cast<__m128>(m)));
#endif
    unsigned out = 0;
    for (int i = 0; i < static_cast<int>(sizeof(V) / 4); ++i) out |= (m[i] < 0 ? 1u : 0u) << i;
    return out;
}
inline unsigned bits(I m) { return lane_bits(m); }
inline bool any(I m) { return bits(m) != 0; }

// bits(a <= b) (false where either lane is NaN) straight from the compare where the set has mask
// registers: GCC 12 turns an AVX-512 compare's mask into a vector of lanes and back before it reaches
// a general register. By the vector's size, as lane_bits.
template <class V>
inline unsigned lane_bits_le(V a, V b) {
#if defined(CELLRT_SIMD_AVX512)
    if constexpr (sizeof(V) == 64)
        return _mm512_cmp_ps_mask(reinterpret_cast<__m512>(a), reinterpret_cast<__m512>(b), _CMP_LE_OQ);
    if constexpr (sizeof(V) == 32)
        return _mm256_cmp_ps_mask(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b), _CMP_LE_OQ);
#endif
    return lane_bits(a <= b);
}
inline unsigned bits_le(F a, F b) { return lane_bits_le(a, b); }

// IEEE square root lane by lane (correctly rounded, so equal to std::sqrt).
template <class V>
inline V lane_sqrt(V x) {
#if defined(CELLRT_SIMD_AVX512)
    // The masked form: GCC 12's unmasked one reads an uninitialised vector (harmlessly) and warns.
    if constexpr (sizeof(V) == 64)
        return reinterpret_cast<V>(_mm512_mask_sqrt_ps(reinterpret_cast<__m512>(x), 0xffff, reinterpret_cast<__m512>(x)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    if constexpr (sizeof(V) == 32) return reinterpret_cast<V>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2) || defined(CELLRT_SIMD_SSE)
    if constexpr (sizeof(V) == 16) return reinterpret_cast<V>(_mm_sqrt_ps(reinterpret_cast<__m128>(x)));
#endif
    for (int i = 0; i < static_cast<int>(sizeof(V) / 4); ++i) x[i] = std::sqrt(x[i]);
    return x;
}
inline F sqrt_lanes(F x) { return lane_sqrt(x); }

// Lane-wise a ? b : c, for floats and integers.
inline F select(I m, F a, F b) { return m ? a : b; }
inline I select(I m, I a, I b) { return m ? a : b; }
inline U select(I m, U a, U b) { return m ? a : b; }

// The smaller of two integers, lane by lane: one instruction where the set has one (GCC 12 makes a
// compare and a masked move of the generic a < b ? a : b). By the vector's size, as lane_bits.
template <class V>
inline V lane_min_i(V a, V b) {
#if defined(CELLRT_SIMD_AVX512)
    if constexpr (sizeof(V) == 64) return reinterpret_cast<V>(_mm512_min_epi32(reinterpret_cast<__m512i>(a), reinterpret_cast<__m512i>(b)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    if constexpr (sizeof(V) == 32) return reinterpret_cast<V>(_mm256_min_epi32(reinterpret_cast<__m256i>(a), reinterpret_cast<__m256i>(b)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2) || defined(CELLRT_SIMD_SSE)
    if constexpr (sizeof(V) == 16) return reinterpret_cast<V>(_mm_min_epi32(reinterpret_cast<__m128i>(a), reinterpret_cast<__m128i>(b)));
#endif
    return b < a ? b : a;
}

// The larger and the smaller of two floats, lane by lane, for operands that are not NaN (the value
// std::max and std::min give; of +0 and -0 either): one instruction where the set has one, where the
// generic a < b ? b : a is a compare and a blend. By the vector's size, as lane_bits.
template <class V>
inline V lane_max_f(V a, V b) {
#if defined(CELLRT_SIMD_AVX512)
    // The masked form: the plain one starts from _mm512_undefined_ps(), which GCC 12 warns of.
    if constexpr (sizeof(V) == 64) {
        const __m512 x = reinterpret_cast<__m512>(a);
        return reinterpret_cast<V>(_mm512_mask_max_ps(x, static_cast<__mmask16>(-1), x, reinterpret_cast<__m512>(b)));
    }
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    if constexpr (sizeof(V) == 32) return reinterpret_cast<V>(_mm256_max_ps(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2) || defined(CELLRT_SIMD_SSE)
    if constexpr (sizeof(V) == 16) return reinterpret_cast<V>(_mm_max_ps(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b)));
#endif
    return a < b ? b : a;
}
template <class V>
inline V lane_min_f(V a, V b) {
#if defined(CELLRT_SIMD_AVX512)
    if constexpr (sizeof(V) == 64) {
        const __m512 x = reinterpret_cast<__m512>(a);
        return reinterpret_cast<V>(_mm512_mask_min_ps(x, static_cast<__mmask16>(-1), x, reinterpret_cast<__m512>(b)));
    }
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2)
    if constexpr (sizeof(V) == 32) return reinterpret_cast<V>(_mm256_min_ps(reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b)));
#endif
#if defined(CELLRT_SIMD_AVX512) || defined(CELLRT_SIMD_AVX2) || defined(CELLRT_SIMD_SSE)
    if constexpr (sizeof(V) == 16) return reinterpret_cast<V>(_mm_min_ps(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b)));
#endif
    return b < a ? b : a;
}

// The scalar kernels' NaN-keeping min/max (kernel/traversal.hpp), lane by lane.
inline F min_keep(F kept, F x) { return select(x < kept, x, kept); }
inline F max_keep(F kept, F x) { return select(x > kept, x, kept); }

// The lanes of a bit mask (bit i: lane i), as a lane mask.
inline I met_mask(unsigned met) {
    const I bit = []<std::size_t... L>(std::index_sequence<L...>) {
        return I{static_cast<std::int32_t>(1u << L)...};
    }(std::make_index_sequence<kLanes>());
    return (splat_i(static_cast<std::int32_t>(met)) & bit) != 0;
}

// The lane-wise minimum by type, for code written once for floats and integers.
inline F min_lanes(F a, F b) { return min_keep(a, b); }
inline I min_lanes(I a, I b) { return lane_min_i(a, b); }
