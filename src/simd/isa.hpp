// Instruction sets the SIMD kernels are built for, and which one runs. Each set's kernels are
// compiled in a translation unit of their own under `#pragma GCC target` and a namespace of their
// own (accel/kernels_<isa>.cpp), so the rest of the program stays baseline code and a machine without, say,
// AVX-512 never executes an AVX-512 instruction. `portable` is the same code with the compiler's
// generic vectors and no target: it builds and runs anywhere.
#pragma once

#include <string>
#include <vector>

namespace cellrt::detail {

enum class Isa { portable, sse, avx2, avx512 };

const char* to_string(Isa isa);
int lanes(Isa isa);  // rays per SIMD packet: 4, 4, 8, 16

// Sets whose kernels are in this binary and that this processor runs, best last.
std::vector<Isa> available_isas();

// "auto" (the best available), "portable", "sse", "avx2", "avx512" ("off", single rays, is the
// caller's business). Throws cellrt::Error for an unknown name or a set this binary or this processor
// cannot run, listing the available ones.
Isa parse_isa(const std::string& name);

}  // namespace cellrt::detail
