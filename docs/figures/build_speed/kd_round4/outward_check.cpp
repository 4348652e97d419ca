// float_below/above against the earlier definitions on many doubles, bit for bit.
#include <cstdio>
#include <random>
#include <cstring>
#include "kernel/outward.hpp"  // src/kernel/outward.hpp
using namespace cellrt::detail;
static float old_below(double x) { float f = (float)x; if ((double)f > x) f = float_step_down(f); return float_step_down(f); }
static float old_above(double x) { float f = (float)x; if ((double)f < x) f = float_step_up(f); return float_step_up(f); }
static unsigned b(float f) { unsigned u; std::memcpy(&u, &f, 4); return u; }
int main() {
    std::mt19937_64 r(3); long bad = 0, n = 0;
    auto check = [&](double x) { ++n; if (b(float_below(x)) != b(old_below(x)) || b(float_above(x)) != b(old_above(x))) { if (bad++ < 5) std::printf("x=%a new %a %a old %a %a\n", x, float_below(x), float_above(x), old_below(x), old_above(x)); } };
    for (int i = 0; i < 20000000; ++i) { std::uint64_t u = r(); double x; std::memcpy(&x, &u, 8); check(x); }
    for (int i = 0; i < 5000000; ++i) { std::uint32_t u = (std::uint32_t)r(); float f; std::memcpy(&f, &u, 4); check(f); check(std::nextafter((double)f, 1e300)); check(std::nextafter((double)f, -1e300)); }
    for (double x : {0.0, -0.0, 1e-46, -1e-46, 1e-45, -1e-45, 2.8e-45, 4.2e-45, 7e-45, -7e-45, 3.4028234663852886e38, -3.4028234663852886e38, 3.5e38, -3.5e38, 1e300, -1e300, (double)INFINITY, -(double)INFINITY, (double)NAN})
        for (double y : {x, std::nextafter(x, 1e308), std::nextafter(x, -1e308)}) check(y);
    for (std::uint32_t u = 0; u < 64; ++u) for (std::uint32_t s : {0u, 0x80000000u}) { float f; std::uint32_t v = u | s; std::memcpy(&f, &v, 4); check(f); check(std::nextafter((double)f, 1.0)); check(std::nextafter((double)f, -1.0)); }
    std::printf("checked %ld, differing %ld\n", n, bad);
}
