// The float watertight test's t on slivers and grazing rays, unrefined: how far the point at t lies
// from the triangle, over the triangle's largest offset from the origin (the least traversal margin
// is 2^-16 of that), by the ratio triangle.hpp's ill_conditioned compares with kIllConditioned.
//   g++ -O2 -std=gnu++20 -ffp-contract=off -Iinclude -Itests docs/figures/exact_hits_2026-12-07/float_t_error.cpp -o /tmp/e && /tmp/e
#include <array>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include "cellrt/triangle.hpp"
#include "slivers.hpp"
#include "triangle_distance.hpp"
using namespace cellrt;
using namespace cellrt::test;
// For unrefined float hits: the worst relative miss by ratio bucket.
int main() {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    double worst[8] = {0}; int count[8] = {0};
    for (int i = 0; i < 4000; ++i) {
        const float len = i % 3 == 0 ? 12.f : (i % 3 == 1 ? 1.f : 0.1f);
        const Triangle tri = random_sliver(rng, len, [&] { return std::pow(10.f, -1.f - 6.f * u01(rng)) * len; });
        for (int k = 0; k < 50; ++k) {
            const Ray ray = ray_onto(tri, rng, k % 2, [&] { return std::pow(10.f, -1.f - 6.f * u01(rng)); });
            WatertightRay w(ray);
            const float* c9 = reinterpret_cast<const float*>(&tri);
            float X[3],Y[3],Z[3];
            for(int q=0;q<3;q++){ Z[q]=c9[3*q+w.kz]-w.org[w.kz]; X[q]=(c9[3*q+w.kx]-w.org[w.kx])-w.sx*Z[q]; Y[q]=(c9[3*q+w.ky]-w.org[w.ky])-w.sy*Z[q];}
            float eu=X[2]*Y[1]-Y[2]*X[1], ev=X[0]*Y[2]-Y[0]*X[2], ew=X[1]*Y[0]-Y[1]*X[0];
            if ((eu<0||ev<0||ew<0)&&(eu>0||ev>0||ew>0)) continue;
            float det=eu+ev+ew; if (!det_in_range(det)) continue;
            float az=w.sz*Z[0], bz=w.sz*Z[1], cz=w.sz*Z[2];
            float t=(eu*az+ev*bz+ew*cz)*(1.f/det);
            float lat=0; for(int q=0;q<3;q++) lat=std::max({lat,std::fabs(X[q]),std::fabs(Y[q])});
            float depth=std::max({Z[0],Z[1],Z[2]})-std::min({Z[0],Z[1],Z[2]});
            double ratio = (double)lat*depth/std::fabs(det);
            int bkt = ratio < 4 ? 0 : ratio < 16 ? 1 : ratio < 64 ? 2 : ratio < 256 ? 3 : ratio < 1024 ? 4 : ratio < 4096 ? 5 : 6;
            double m = (double)relative_miss(tri, ray, t);
            worst[bkt] = std::max(worst[bkt], m); count[bkt]++;
        }
    }
    const char* names[] = {"<4","<16","<64","<256","<1024","<4096",">="};
    for (int b = 0; b < 7; ++b) printf("ratio %6s: %6d hits, worst miss %g (x 2^-16: %g)\n", names[b], count[b], worst[b], worst[b] / 0x1p-16);
}
