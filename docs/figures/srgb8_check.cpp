// Every float from +0 to 1 in order (1,065,353,217 of them): the byte of a PNG channel
// (cellrt::srgb8_exact: lround(255 * linear_to_srgb(x))) never falls, and cellrt::srgb8, its table,
// gives the same byte. The table rests on the first; docs/DISTRIBUTED.md, "8-bit pixels". About 10 s.
//   g++ -I include -O2 -std=c++20 docs/figures/srgb8_check.cpp build/libcellrt.a -lstb -o srgb8_check
#include <bit>
#include <cstdint>
#include <cstdio>

#include "cellrt/image.hpp"

int main() {
    long long changes = 0, falls = 0, differ = 0;
    unsigned previous = 0;
    for (std::uint32_t bits = 0; bits <= 0x3F800000u; ++bits) {
        const float x = std::bit_cast<float>(bits);
        const unsigned exact = cellrt::srgb8_exact(x);
        falls += exact < previous;
        changes += exact != previous;
        differ += cellrt::srgb8(x) != exact;
        previous = exact;
    }
    std::printf("floats in [0, 1]: 1065353217; byte changes %lld, falls %lld, table differs %lld\n", changes, falls,
                differ);
    return falls == 0 && differ == 0 ? 0 : 1;
}
