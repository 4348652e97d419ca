#include <chrono>
#include <cstdio>
#include <random>
#include <vector>
#include <algorithm>
#include <bit>
#include <array>
#include <utility>
#include <cstdint>
#include <cstring>
using E = std::uint64_t;
static void rank_sort(E* list, std::size_t n) {
    E unsorted[32]; std::copy_n(list, n, unsorted);
    for (std::size_t i = 0; i < n; ++i) { std::size_t rank = 0; for (std::size_t j = 0; j < n; ++j) rank += unsorted[j] < unsorted[i]; list[rank] = unsorted[i]; }
}
template <std::size_t n> constexpr std::size_t nsize() { std::size_t c = 0;
 for (std::size_t p = 1; p < n; p += p) for (std::size_t k = p; k >= 1; k /= 2) for (std::size_t j = k % p; j + k < n; j += 2 * k) for (std::size_t i = 0; i < k && i + j + k < n; ++i) c += (i + j) / (2 * p) == (i + j + k) / (2 * p); return c; }
template <std::size_t n> constexpr auto npairs() { std::array<std::pair<std::uint8_t, std::uint8_t>, nsize<n>()> o{}; std::size_t c = 0;
 for (std::size_t p = 1; p < n; p += p) for (std::size_t k = p; k >= 1; k /= 2) for (std::size_t j = k % p; j + k < n; j += 2 * k) for (std::size_t i = 0; i < k && i + j + k < n; ++i) if ((i + j) / (2 * p) == (i + j + k) / (2 * p)) o[c++] = {std::uint8_t(i + j), std::uint8_t(i + j + k)}; return o; }
[[gnu::always_inline]] inline void cx(E& x, E& y) { E a = x, b = y; bool s = b < a; x = s ? b : a; y = s ? a : b; }
template <std::size_t n> void net(E* e) { static constexpr auto P = npairs<n>(); [&]<std::size_t... i>(std::index_sequence<i...>) { (cx(e[P[i].first], e[P[i].second]), ...); }(std::make_index_sequence<P.size()>{}); }
static void net_sort(E* list, std::size_t n) {
    if (n <= 1) return; E b[32]; std::copy_n(list, n, b); std::size_t s = std::bit_ceil(n); std::fill(b + n, b + s, ~E{0});
    switch (s) { case 2: net<2>(b); break; case 4: net<4>(b); break; case 8: net<8>(b); break; case 16: net<16>(b); break; default: net<32>(b); }
    std::copy_n(b, n, list);
}
int main() {
    // sizes drawn like Sponza's histogram: even sizes 2..32 weighted
    std::vector<int> sizes; std::mt19937 r(1);
    int w[] = {0,0,80591,0,135794,0,80711,0,58639,0,37192,0,21302,0,14206,0,7437,0,5997,0,4308,0,3165,0,3144,0,2515,0,1657,0,1406,0,1342};
    std::discrete_distribution<int> d(std::begin(w), std::end(w));
    for (int i = 0; i < 400000; ++i) sizes.push_back(d(r));
    std::vector<E> data; for (int s : sizes) for (int k = 0; k < s; ++k) data.push_back(((E)r() << 32) | r());
    for (int round = 0; round < 3; ++round) for (int m = 0; m < 2; ++m) {
        std::vector<E> v = data; auto t0 = std::chrono::steady_clock::now(); std::size_t off = 0;
        for (int s : sizes) { if (m) net_sort(&v[off], s); else rank_sort(&v[off], s); off += s; }
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("%s %.1f ms (check %llu)\n", m ? "network" : "rank", ms, (unsigned long long)v[v.size()/2]);
    }
}
