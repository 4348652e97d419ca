#include "isa.hpp"

#include "cellrt/error.hpp"

namespace cellrt::detail {

const char* to_string(Isa isa) {
    switch (isa) {
        case Isa::portable: return "portable";
        case Isa::sse: return "sse";
        case Isa::avx2: return "avx2";
        default: return "avx512";
    }
}

int lanes(Isa isa) { return isa == Isa::avx512 ? 16 : isa == Isa::avx2 ? 8 : 4; }

std::vector<Isa> available_isas() {
    std::vector<Isa> out{Isa::portable};
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    if (__builtin_cpu_supports("sse4.2")) out.push_back(Isa::sse);
    if (__builtin_cpu_supports("avx2")) out.push_back(Isa::avx2);
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512bw"))
        out.push_back(Isa::avx512);
#endif
    return out;
}

Isa parse_isa(const std::string& name) {
    const std::vector<Isa> have = available_isas();
    if (name == "auto") return have.back();
    for (Isa isa : {Isa::portable, Isa::sse, Isa::avx2, Isa::avx512}) {
        if (name != to_string(isa)) continue;
        for (Isa h : have)
            if (h == isa) return isa;
        std::string list;
        for (Isa h : have) list += std::string(list.empty() ? "" : ", ") + to_string(h);
        throw Error("SIMD instruction set " + name + " is not available on this machine or in this build (available: "
                    "auto, off, " + list + ")");
    }
    throw Error("SIMD instruction set '" + name + "' is not one of: auto, off, portable, sse, avx2, avx512");
}

}  // namespace cellrt::detail
