#include <cstdio>

#include "cellrt/accelerator.hpp"

namespace cellrt {
namespace {

std::string fixed(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> AccelStats::figures() const {
    std::vector<std::pair<std::string, std::string>> f{
        {"traversal", traversal},
        {"simd lanes", simd_lanes ? std::to_string(simd_lanes) : "off"},
        {"triangles", std::to_string(triangles)},
    };
    f.insert(f.end(), settings.begin(), settings.end());
    if (!tree) return f;
    const TreeReport& t = *tree;
    f.insert(f.end(), {{"nodes", std::to_string(t.nodes)}, {"inner nodes", std::to_string(t.inner_nodes)}});
    if (t.empty_space_nodes) f.emplace_back("empty-space nodes", std::to_string(*t.empty_space_nodes));
    f.insert(f.end(), {
                          {"leaves", std::to_string(t.leaves)},
                          {"empty leaves", std::to_string(t.empty_leaves)},
                          {"depth limit", t.depth_limit ? std::to_string(t.depth_limit) : "none"},
                          {"max depth", std::to_string(t.max_depth)},
                          {"mean leaf depth", fixed("%.2f", t.mean_leaf_depth)},
                          {"tris per leaf", fixed("%.2f", t.triangles_per_leaf)},
                          {"refs per tri", fixed("%.3f", t.references_per_triangle)},
                          {"SAH cost", fixed("%.2f", t.sah_cost)},
                      });
    return f;
}

std::optional<std::string> AccelStats::setting(const std::string& name) const {
    for (const auto& [k, v] : settings)
        if (k == name) return v;
    return std::nullopt;
}

}  // namespace cellrt
