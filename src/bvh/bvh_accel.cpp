#include "bvh/bvh_accel.hpp"

#include "cellrt/error.hpp"
#include "core/timer.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt {
namespace {

// The traversals, in the order of bvh_traversals().
enum class Traversal { paired, wide, stream, packet };

Traversal traversal_named(const std::string& name) {
    const std::string& chosen = detail::choose_traversal(bvh_traversals(), name, "bvh");
    return chosen == "wide"     ? Traversal::wide
           : chosen == "stream" ? Traversal::stream
           : chosen == "packet" ? Traversal::packet
                                : Traversal::paired;
}

class BvhAccelerator final : public Accelerator {
public:
    BvhAccelerator(std::span<const Triangle> triangles, const detail::BvhBuildOptions& options,
                   const detail::BvhKernels& kernels, Traversal traversal)
        : options_(options), kernels_(kernels), traversal_(traversal), triangle_count_(triangles.size()) {
        const Timer timer;
        tree_ = detail::build_bvh(triangles, options);
        build_seconds_ = timer.seconds();
        build_cpu_seconds_ = timer.cpu_seconds();
    }

    // A view of `other`'s tree traced by the given traversal (bvh_with_traversal).
    BvhAccelerator(const BvhAccelerator& other, Traversal traversal)
        : options_(other.options_), kernels_(other.kernels_), traversal_(traversal), triangle_count_(other.triangle_count_),
          shared_(&other.tree()) {}

    AccelStats stats() const override {
        AccelStats s;
        s.name = "bvh";
        s.traversal = bvh_traversals()[static_cast<std::size_t>(traversal_)];
        if (traversal_ == Traversal::packet) s.simd_lanes = kernels_.packet_rays;  // one ray a lane
        s.build_seconds = build_seconds_;
        s.build_cpu_seconds = build_cpu_seconds_;
        s.memory_bytes = tree().nodes.size() * sizeof(detail::BvhNode) + tree().leaves.size() * sizeof(detail::BvhLeaf);
        s.triangles = triangle_count_;
        TreeReport r;
        r.nodes = tree().nodes.size() + tree().leaves.size();
        r.inner_nodes = tree().nodes.size();
        r.leaves = tree().leaves.size();
        r.max_depth = tree().depth;
        r.mean_leaf_depth = tree().mean_leaf_depth;
        r.triangles_per_leaf = tree().mean_leaf_triangles;
        r.references_per_triangle = triangle_count_ ? double(tree().references) / double(triangle_count_) : 0.0;
        r.sah_cost = tree().sah_cost;
        s.tree = r;
        s.settings = {{"bins", std::to_string(options_.bins)},
                      {"max_leaf", std::to_string(options_.max_leaf)},
                      {"traversal_cost", param_number(options_.traversal_cost)},
                      {"intersection_cost", param_number(options_.intersection_cost)},
                      {"split_budget", param_number(options_.split_budget)},
                      {"isa", kernels_.isa}};
        return s;
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        (traversal_ == Traversal::stream   ? kernels_.stream_closest
         : traversal_ == Traversal::packet ? kernels_.packet_closest
         : traversal_ == Traversal::paired ? kernels_.paired_closest
                                           : kernels_.closest)(tree(), rays, hits, counters);
    }
    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        (traversal_ == Traversal::stream   ? kernels_.stream_any
         : traversal_ == Traversal::packet ? kernels_.packet_any
         : traversal_ == Traversal::paired ? kernels_.paired_any
                                           : kernels_.any)(tree(), rays, occluded, counters);
    }

    const detail::BvhTree& tree() const { return shared_ ? *shared_ : tree_; }

    detail::BvhBuildOptions options_;
    const detail::BvhKernels& kernels_;
    Traversal traversal_;
    std::size_t triangle_count_;
    detail::BvhTree tree_;
    const detail::BvhTree* shared_ = nullptr;  // a view's tree, owned by the accelerator it was made from
    double build_seconds_ = 0.0, build_cpu_seconds_ = 0.0;
};

}  // namespace

std::unique_ptr<Accelerator> detail::bvh_with_traversal(const Accelerator& bvh, const std::string& traversal) {
    const auto* b = dynamic_cast<const BvhAccelerator*>(&bvh);
    if (!b) throw Error("bvh_with_traversal: not a wide BVH");
    return std::unique_ptr<Accelerator>(new BvhAccelerator(*b, traversal_named(traversal)));
}

const ParamTable& bvh_params() {
    using enum ParamType;
    static const ParamTable table{
        {"bins", integer, "16", 2, 256, {}, "centroid bins per axis of the binned SAH (Wald 2007)"},
        {"max_leaf", integer, "8", 1, 8, {}, "most triangles in a leaf; a leaf is one eight-lane group"},
        {"traversal_cost", number, "1", 0.001, 1000, {}, "SAH cost of visiting a node (eight box tests)"},
        {"intersection_cost", number, "2", 0.001, 1000, {},
         "SAH cost of testing a leaf (up to eight triangles at once)"},
        {"split_budget", number, "0.5", 0, 4, {},
         "spatial splits (Stich et al. 2009): about this many extra references per triangle; 0 builds without them"},
    };
    return table;
}

// A function's static, not a namespace-scope one: the registry copies the list when it is first used,
// which may be during another unit's static initialisation (a test's list of configurations).
// The first is the default: two rays' walks at a time, as fast as one ray's or faster on every kind
// of ray since their set-up is made in lanes (docs/INCOHERENT.md, "Thirteenth round").
const std::vector<std::string>& bvh_traversals() {
    static const std::vector<std::string> names{"paired", "wide", "stream", "packet"};
    return names;
}

std::unique_ptr<Accelerator> make_bvh(std::span<const Triangle> triangles, const AccelConfig& config,
                                      const detail::BvhKernels& kernels) {
    detail::ParamReader params(bvh_params(), config, "bvh");
    detail::BvhBuildOptions options;
    options.bins = params.integer("bins");
    options.max_leaf = params.integer("max_leaf");
    options.traversal_cost = params.number("traversal_cost");
    options.intersection_cost = params.number("intersection_cost");
    options.split_budget = params.number("split_budget");
    options.threads = config.threads;
    params.finish();
    return std::make_unique<BvhAccelerator>(triangles, options, kernels, traversal_named(config.traversal));
}

}  // namespace cellrt
