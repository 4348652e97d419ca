// The renderer's rules for one pixel, in one source for the CPU and the GPU (CELLRT_HD): the camera's
// primary ray, the rays a shading casts from a hit (shadow, AO, diffuse bounce) and the colour their
// answers give. The CPU's frame workload (workload.hpp) makes its batches with these functions and
// shades with them (render.cpp); the GPU frame path runs shade_pixel() in each thread
// (cuda/device_frame.hpp). Every step is a +, -, *, /, sqrt or an integer operation, compiled with no
// contraction on both sides (docs/GPU.md), so a pixel's colour is the same bits wherever it is made.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "cellrt/host_device.hpp"
#include "cellrt/ray.hpp"
#include "cellrt/sampling.hpp"
#include "cellrt/triangle.hpp"
#include "cellrt/vec.hpp"

namespace cellrt {

enum class Shading : std::uint8_t { direct, ao, diffuse };

inline constexpr int kMaxAoSamples = 64;

struct ShadingOptions {
    Shading shading = Shading::direct;
    int ao_samples = 4;  // AO rays per primary hit, 1..kMaxAoSamples
};

// The AO rays' reach: this fraction of the scene box's diagonal.
inline constexpr float kAoReachFraction = 0.1f;

// The random numbers of a pixel: sample s of the AO rays uses dimensions 0 and 1, the bounce
// dimensions 2 and 3, so no two rays of a pixel share a number.
inline constexpr std::uint32_t kAoDims = 0, kBounceDims = 2;

// A pinhole camera's rays: one through the centre of each pixel (camera.hpp's PinholeCamera checks
// the camera and fills this). Plain data, copied to the GPU as it is.
struct PinholeProjection {
    Vec3 origin, forward, right, up;
    float half_w = 0.f, half_h = 0.f;
    float width = 1.f, height = 1.f;

    // The ray through the centre of pixel (px, py); py = 0 is the top row. Direction is normalised.
    CELLRT_HD Ray primary(int px, int py) const {
        const float sx = (2.f * (static_cast<float>(px) + 0.5f) / width - 1.f) * half_w;
        const float sy = (1.f - 2.f * (static_cast<float>(py) + 0.5f) / height) * half_h;
        Ray r;
        r.org = origin;
        r.dir = normalize(forward + right * sx + up * sy);
        return r;
    }
};

// The point a hit names and the triangle's geometric normal there, turned to face the side the ray
// came from. Where the normal's length under- or overflows in float (edges of some 5e-12 or 4e9 and
// beyond) it is normalised from the vector divided by its largest component; a triangle with no
// normal at all (zero area: the test hits one where rounding gives it an area, as at a T-junction)
// faces the ray, whose direction is rescaled the same way. Both were NaN or zero, and the shadow
// ray's offset converted NaN to an integer (undefined; found by review, 2026-12-07).
struct SurfacePoint {
    Vec3 position, normal;
    // The largest coordinate magnitude the point was made from: its own and its triangle's corners'.
    // The point's rounding, and a test of a ray leaving it against its own triangle, err by ulps of
    // this, not of the point (offset_ray_origin).
    float magnitude = 0.f;
};

CELLRT_HD inline SurfacePoint surface_point(const Triangle& tri, const Ray& ray, const Hit& hit) {
    const Vec3 g = tri.geometric_normal();
    const float len = length(g);
    Vec3 n;
    if (len > 0.f && len < kInfinity) [[likely]] {
        n = g * (1.f / len);
    } else {
        const float gm = max_magnitude(g);
        n = gm > 0.f && gm < kInfinity ? normalize(g * (1.f / gm)) : -normalize(ray.dir * (1.f / max_magnitude(ray.dir)));
    }
    if (dot(n, ray.dir) > 0.f) n = -n;
    const Vec3 p = tri.v0 * (1.f - hit.u - hit.v) + tri.v1 * hit.u + tri.v2 * hit.v;
    return {p, n, std::fmax(std::fmax(max_magnitude(p), max_magnitude(tri.v0)),
                            std::fmax(max_magnitude(tri.v1), max_magnitude(tri.v2)))};
}

// How far a ray leaving a surface point starts off the surface: 2^-18 (32 ulps) of the largest
// magnitude the point was made from, and at least 2^-16 near the origin. After Wächter & Binder ("A
// Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, ch. 6), with pbrt's
// insight (3rd ed., section 3.9) that a point interpolated from its triangle's corners, and a test of
// a ray leaving it against that triangle, err by ulps of the corners, not of the point: 256 ulps of
// the point itself left rays from the middle of a ground 10 km wide hitting the ground they left,
// half of those under 45 degrees (AO speckle on builtin:city's ground, lit points in shadow; found by
// audit, 2026-12-07). Measured on such grounds: 4 ulps of the magnitude already suffice, 1 does not;
// 32 leave a factor 8.
CELLRT_HD inline float surface_offset(float magnitude) { return std::fmax(magnitude * 0x1p-18f, 0x1p-16f); }

// A secondary ray's origin: the surface point pushed off the surface along its normal (which faces
// the side the ray came from) by surface_offset, so that the ray cannot hit the surface it starts on.
CELLRT_HD inline Vec3 offset_ray_origin(const SurfacePoint& sp) {
    return sp.position + sp.normal * surface_offset(sp.magnitude);
}

// The renderer's shadow ray from surface point `sp` toward a point light: origin
// offset_ray_origin(sp), unit direction, tnear 0, tfar short of the light by surface_offset of the
// larger of the light's and the origin's magnitudes, so that a surface through the light itself does
// not shadow it (its hit's t errs by a few ulps of those magnitudes), while a wall nearer the light
// than that does: a fixed 1e-4 of the distance let the light of a lamp 1 mm inside a closed slab out
// onto points 10 away (found by audit, 2026-12-07).
CELLRT_HD inline Ray shadow_ray(const SurfacePoint& sp, const Vec3& light) {
    Ray s;
    s.org = offset_ray_origin(sp);
    const Vec3 to_light = light - s.org;
    const float dist = length(to_light);
    s.dir = to_light * (1.f / dist);
    s.tnear = 0.f;
    s.tfar = std::fmax(dist - surface_offset(std::fmax(max_magnitude(light), max_magnitude(s.org))), 0.f);
    return s;
}

// A ray leaving the surface point `sp` in the cosine-weighted direction drawn for (pixel, sample,
// dims), reaching `tfar`; its origin is pushed off the surface as a shadow ray's is.
CELLRT_HD inline Ray hemisphere_ray(const SurfacePoint& sp, std::uint64_t pixel, std::uint32_t sample,
                                    std::uint32_t dims, float tfar) {
    Ray r;
    r.org = offset_ray_origin(sp);
    r.dir = cosine_hemisphere(sp.normal, hash_uniform(pixel, sample, dims), hash_uniform(pixel, sample, dims + 1));
    r.tfar = tfar;
    return r;
}

// The colours. Each pixel's colour is a sum in a fixed order of terms that hits decide, so it is the
// same bits under every structure, traversal, packet size, thread count and device.
namespace shade {

// Every surface's colour (a function: a constant of class type is not visible to device code).
CELLRT_HD constexpr Vec3 albedo() { return {0.8f, 0.78f, 0.74f}; }
inline constexpr float kAmbient = 0.12f;

// What a ray that escapes sees.
CELLRT_HD inline Vec3 sky(const Vec3& dir) {
    const float k = 0.5f * (dir.y + 1.f);
    return Vec3{0.9f, 0.95f, 1.f} * (1.f - k) + Vec3{0.35f, 0.55f, 0.9f} * k;
}

// Lambert's cosine at the start of a shadow ray (unit direction `dir`, from a surface of normal
// `normal`), 0 where something blocks the light.
CELLRT_HD inline float lambert(bool occluded, const Vec3& normal, const Vec3& dir) {
    return occluded ? 0.f : std::max(0.f, dot(normal, dir));
}

// `direct`, the study's: Lambert under the point light and a little ambient light.
CELLRT_HD inline Vec3 direct(float lambert_cos, const Vec3& light_color) {
    return albedo() * (kAmbient + lambert_cos) * light_color;
}

// `ao`: the fraction of the hit's `samples` AO rays that escape.
CELLRT_HD inline Vec3 ambient_occlusion(int open, int samples) {
    return albedo() * (static_cast<float>(open) / static_cast<float>(samples));
}

// `diffuse`: with cosine-weighted bounces the estimate of the light a bounce brings is what arrives
// along it (the cosine and the density cancel): the sky where it escapes, or the direct light at its
// hit (bounce_light).
CELLRT_HD inline Vec3 bounce_light(float lambert_cos, const Vec3& light_color) {
    return albedo() * light_color * lambert_cos;
}
CELLRT_HD inline Vec3 diffuse(float lambert_cos, const Vec3& light_color, const Vec3& incoming) {
    return albedo() * (light_color * lambert_cos + incoming);
}

}  // namespace shade

// What shade_pixel() needs of a frame besides the triangles and the tree: plain data for the GPU.
struct FrameShading {
    PinholeProjection camera;
    Vec3 light_position, light_color;
    ShadingOptions shading;
    float ao_reach = 0.f;  // AO shading: kAoReachFraction of the scene box's diagonal (else 0)
    int frame_width = 0;   // pixel (x, y) seeds its random numbers with y * frame_width + x
};

// The colour of pixel (x, y): its primary ray, the rays its shading casts, in the CPU's order, and the
// colour of render.cpp. closest(ray, primary) returns a ray's hit under the hit rule (primary: the
// camera's ray, else a bounce); any(ray) whether anything blocks it. `triangles` are the scene's,
// which a hit's index names.
template <class Closest, class Any>
CELLRT_HD Vec3 shade_pixel(const FrameShading& f, const Triangle* triangles, int x, int y, Closest&& closest,
                           Any&& any) {
    const Ray primary = f.camera.primary(x, y);
    const Hit hit = closest(primary, true);
    if (!hit.is_hit()) return shade::sky(primary.dir);
    const SurfacePoint sp = surface_point(triangles[hit.prim], primary, hit);
    const std::uint64_t pixel =
        static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(f.frame_width) + static_cast<std::uint64_t>(x);
    switch (f.shading.shading) {
        case Shading::ao: {
            int open = 0;
            for (int s = 0; s < f.shading.ao_samples; ++s)
                open += any(hemisphere_ray(sp, pixel, static_cast<std::uint32_t>(s), kAoDims, f.ao_reach)) ? 0 : 1;
            return shade::ambient_occlusion(open, f.shading.ao_samples);
        }
        case Shading::diffuse: {
            const Ray shadow = shadow_ray(sp, f.light_position);
            const float direct = shade::lambert(any(shadow), sp.normal, shadow.dir);
            const Ray bounce = hemisphere_ray(sp, pixel, 0, kBounceDims, kInfinity);
            const Hit bounce_hit = closest(bounce, false);
            Vec3 incoming = shade::sky(bounce.dir);
            if (bounce_hit.is_hit()) {
                const SurfacePoint bp = surface_point(triangles[bounce_hit.prim], bounce, bounce_hit);
                const Ray bounce_shadow = shadow_ray(bp, f.light_position);
                incoming = shade::bounce_light(shade::lambert(any(bounce_shadow), bp.normal, bounce_shadow.dir),
                                               f.light_color);
            }
            return shade::diffuse(direct, f.light_color, incoming);
        }
        case Shading::direct: break;
    }
    const Ray shadow = shadow_ray(sp, f.light_position);
    return shade::direct(shade::lambert(any(shadow), sp.normal, shadow.dir), f.light_color);
}

}  // namespace cellrt
