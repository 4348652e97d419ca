// A tree traced through the local-store model: the structure is built as for direct memory, its
// arrays are mapped into the model's main memory, and every worker thread runs the structure's own
// kernels over CachedMemory and its own local store, batch by batch. A template over the
// structure's descriptor (kdtree/kd_structure.hpp), which the registry instantiates for every tree it
// lists (accel/local_store_registry.cpp); the local store holds the stack the descriptor declares for
// the traversal (stack_bytes).
#pragma once

#include <algorithm>
#include <memory>
#include <type_traits>
#include <utility>

#include <tbb/enumerable_thread_specific.h>

#include "cached_memory.hpp"
#include "core/timer.hpp"
#include "kernel/named.hpp"
#include "kernel/param_reader.hpp"
#include "kernel/traversal.hpp"
#include "local_store.hpp"

namespace cellrt::detail {

// A built structure and its image in the model's main memory, shared by every configuration traced over it.
template <class S>
struct Built {
    Built(std::span<const Triangle> triangles, const AccelConfig& config) : structure(build(triangles, config)) {
        image.nodes = memory.add(structure.nodes().data(), structure.nodes().size_bytes());
        image.entries = memory.add(structure.entries().data(), structure.entries().size_bytes());
        image.triangles = memory.add(structure.triangle_array().data(), structure.triangle_array().size_bytes());
        image.node_count = static_cast<std::uint32_t>(structure.nodes().size());
        image.leaf_bound = structure.entries().size();
        image.depth = node_depths(structure.nodes());
        for (std::size_t i = 0; i < image.node_count; ++i)
            if (image.depth[i] != image.kNoDepth && structure.nodes()[i].is_leaf())
                image.max_leaf = std::max(image.max_leaf, structure.nodes()[i].count());
    }
    S build(std::span<const Triangle> triangles, const AccelConfig& config) {
        Timer timer;
        S s(triangles, config);
        build_seconds = timer.seconds();
        return s;
    }
    double build_seconds = 0.0;
    S structure;
    MainMemory memory;
    StructureImage<typename S::Node> image;
};

// The kernels' work counters, forwarded, and the cycles of that work on the worker's clock.
template <class Counters>
struct ModelCounters {
    Counters& counters;
    WorkerStore& store;
    std::uint32_t step_cycles, leaf_cycles, test_cycles;

    void node() {
        counters.node();
        store.work(step_cycles);
    }
    void leaf() {
        counters.leaf();
        store.work(leaf_cycles);
    }
    void triangle() {
        counters.triangle();
        store.work(test_cycles);
    }
};

template <class S>
class ModelAccelerator final : public LocalStoreAccelerator {
public:
    using Node = typename S::Node;

    ModelAccelerator(std::shared_ptr<const Built<S>> built, const LocalStoreConfig& config,
                     const std::string& traversal)
        : built_(std::move(built)),
          config_(config),
          traversal_name_(choose_traversal(names_of(S::kTraversals), traversal, S::kName)),
          traversal_(value_named(S::kTraversals, traversal_name_, "traversal")),
          allocations_(allocate_local_store(config, S::stack_bytes(traversal_))),
          workers_([this] { return WorkerStore(config_, built_->memory); }) {}

    AccelStats stats() const override {
        const LocalStoreConfig& c = config_;
        const S& structure = built_->structure;
        AccelStats s;
        s.name = S::kName;
        s.traversal = traversal_name_;
        s.build_seconds = built_->build_seconds;
        s.memory_bytes = structure.memory_bytes();
        s.triangles = structure.triangle_array().size();
        s.tree = structure.report();
        s.settings = structure.settings();
        s.settings.emplace_back("local store", std::to_string(c.budget_bytes / 1024) + " KiB, node cache " +
                                                   c.node_cache.to_string() + ", triangle cache " +
                                                   c.triangle_cache.to_string() + ", " + to_string(c.access) +
                                                   (c.access == CacheAccess::async && !c.retouch ? " without re-touch"
                                                                                                   : ""));
        return s;
    }

    const LocalStoreConfig& local_store_config() const override { return config_; }
    std::vector<LocalStoreAllocation> local_store_allocations() const override { return allocations_; }

    LocalStoreStats local_store_stats() const override {
        LocalStoreStats s;
        for (const WorkerStore& w : workers_) {
            s.node_cache += w.node_cache.stats;
            s.triangle_cache += w.triangle_cache.stats;
            s.rays += w.rays();
            s.batches += w.batches();
            s.cycles += w.cycles();
            s.stall_cycles += w.stall_cycles();
            s.frame_cycles = std::max(s.frame_cycles, w.cycles());
            ++s.workers;
        }
        return s;
    }

    std::unique_ptr<LocalStoreAccelerator> with_local_store(const LocalStoreConfig& config,
                                                            const std::string& traversal) const override {
        return std::make_unique<ModelAccelerator>(built_, config, traversal);
    }

private:
    void do_intersect(std::span<const Ray> rays, std::span<Hit> hits, TraversalCounters* counters) const override {
        trace(rays.size(), sizeof(Hit), [&](std::size_t i, std::size_t n, auto& kernel) {
            closest_hits(built_->structure.bounds(), rays.subspan(i, n), hits.subspan(i, n), counters, kernel);
        });
    }

    void do_occluded(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                     TraversalCounters* counters) const override {
        trace(rays.size(), sizeof(std::uint8_t), [&](std::size_t i, std::size_t n, auto& kernel) {
            any_hits(built_->structure.bounds(), rays.subspan(i, n), occluded.subspan(i, n), counters, kernel);
        });
    }

    // Traces `count` rays on the calling thread's worker, one batch of at most batch_rays at a time:
    // `batch(first, n, kernel)` runs the batch loop over rays [first, first + n) with `kernel`.
    template <class Batch>
    void trace(std::size_t count, std::size_t result_bytes, Batch&& batch) const {
        WorkerStore& store = workers_.local();
        CachedMemory<Node> mem(store, built_->image, config_);
        const CostModel& cost = config_.cost;
        const std::uint32_t step = cost.inner_step(traversal_ == S::Traversal::branchless);
        S::with_kernel(traversal_, [&](auto kernel) {
            auto through_model = [&](const TraversalRay& r, auto& q, auto& c) {
                store.begin_ray();
                ModelCounters<std::remove_reference_t<decltype(c)>> counted{c, store, step, cost.leaf,
                                                                            cost.triangle_test};
                return kernel(built_->structure.tree, mem, r, q, counted);
            };
            for (std::size_t i = 0; i < count; i += config_.batch_rays) {
                const std::size_t n = std::min(config_.batch_rays, count - i);
                store.load_batch(static_cast<std::uint32_t>(n), static_cast<std::uint32_t>(n * sizeof(Ray)));
                batch(i, n, through_model);
                store.store_results(static_cast<std::uint32_t>(n * result_bytes));
            }
        });
    }

    std::shared_ptr<const Built<S>> built_;
    LocalStoreConfig config_;
    std::string traversal_name_;
    typename S::Traversal traversal_;
    std::vector<LocalStoreAllocation> allocations_;
    mutable tbb::enumerable_thread_specific<WorkerStore> workers_;
};

// Builds S over `triangles` for the model `local_store`. A bad traversal or configuration is refused
// before time is spent on the build.
template <class S>
std::unique_ptr<LocalStoreAccelerator> make_model(std::span<const Triangle> triangles, const AccelConfig& config,
                                                  const LocalStoreConfig& local_store) {
    const std::string traversal = choose_traversal(names_of(S::kTraversals), config.traversal, S::kName);
    allocate_local_store(local_store, S::stack_bytes(value_named(S::kTraversals, traversal, "traversal")));
    auto built = std::make_shared<const Built<S>>(triangles, config);
    return std::make_unique<ModelAccelerator<S>>(std::move(built), local_store, traversal);
}

}  // namespace cellrt::detail
