#include "cuda/device_memory.hpp"

#include <bit>
#include <cstdint>

#include "cellrt/error.hpp"
#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

constexpr const char* kCaches[] = {"node", "triangle"};

// LINExSETS, or LINExSETSxWAYS when 4-way: as the local store's CacheLayout::to_string writes it.
std::string layout_text(const SharedCacheLayout& l) {
    std::string s = std::to_string(l.line_bytes);
    s += 'x';
    s += std::to_string(l.sets);
    if (l.ways != 1) {
        s += 'x';
        s += std::to_string(l.ways);
    }
    return s;
}

bool is_memory_param(const std::string& name) {
    for (const ParamSpec& p : device_memory_params())
        if (p.name == name) return true;
    return false;
}

}  // namespace

std::string DeviceMemoryConfig::to_string() const {
    if (!shared) return "global";
    return "shared: node cache " + layout_text(node_cache) + ", triangle cache " + layout_text(triangle_cache) + ", " +
           std::to_string(shared_bytes()) + " B a block" + (async ? ", asynchronous access" : "");
}

const ParamTable& device_memory_params() {
    using enum ParamType;
    static const ParamTable table = [] {
        ParamTable t{{"memory", choice, "global", 0, 0, {"global", "shared"},
                      "CUDA: the tree in global memory through L1/L2 (global), or the study's software caches in "
                      "each block's shared memory (shared)"},
                     {"access", choice, "sync", 0, 0, {"sync", "async"},
                      "CUDA, memory=shared: node reads wait for their line (sync), or a node's child pair is "
                      "touched when the node is read, its lines copied by cp.async until the next read waits "
                      "(async; the study's section 4.3)"}};
        for (const char* cache : kCaches) {
            const std::string c = cache;
            t.push_back({c + "_line", integer, "128", 16, 4096, {},
                         "CUDA, memory=shared: line size of the " + c + " cache in bytes, a power of two"});
            t.push_back({c + "_sets", integer, "128", 1, 1 << 20, {},
                         "CUDA, memory=shared: sets of the " + c + " cache, a power of two"});
            t.push_back({c + "_ways", choice, "1", 0, 0, {"1", "4"},
                         "CUDA, memory=shared: the " + c + " cache direct-mapped (1) or 4-way with LRU (4)"});
        }
        return t;
    }();
    return table;
}

DeviceMemoryConfig read_device_memory(const AccelConfig& config) {
    AccelConfig mine;
    for (const auto& [name, value] : config.params)
        if (is_memory_param(name)) mine.params[name] = value;
    ParamReader in(device_memory_params(), mine, "cuda");
    DeviceMemoryConfig m;
    m.shared = in.choice("memory") == "shared";
    m.async = in.choice("access") == "async";
    SharedCacheLayout* layouts[] = {&m.node_cache, &m.triangle_cache};
    for (int i = 0; i < 2; ++i) {
        const std::string c = kCaches[i];
        SharedCacheLayout& l = *layouts[i];
        l.line_bytes = static_cast<std::uint32_t>(in.integer(c + "_line"));
        l.sets = static_cast<std::uint32_t>(in.integer(c + "_sets"));
        l.ways = in.choice(c + "_ways") == "4" ? 4 : 1;
        if (!std::has_single_bit(l.line_bytes))
            throw Error("cuda parameter " + c + "_line=" + std::to_string(l.line_bytes) + ": a line is a power of two bytes");
        if (!std::has_single_bit(l.sets))
            throw Error("cuda parameter " + c + "_sets=" + std::to_string(l.sets) + ": the number of sets is a power of two");
    }
    in.finish();
    if (!m.shared)
        for (const auto& [name, value] : mine.params)
            if (name != "memory")
                throw Error("cuda parameter " + name + "=" + value + " shapes the shared-memory caches: it needs memory=shared");
    return m;
}

AccelConfig without_device_memory(const AccelConfig& config) {
    AccelConfig out = config;
    std::erase_if(out.params, [](const auto& p) { return is_memory_param(p.first); });
    return out;
}

void check_shared_memory(const DeviceMemoryConfig& memory, std::size_t budget, std::uint64_t tree_bytes) {
    if (!memory.shared) return;
    if (memory.shared_bytes() > budget)
        throw Error("the shared-memory caches (node cache " + layout_text(memory.node_cache) + ": " +
                    std::to_string(memory.node_cache.bytes()) + " B, triangle cache " +
                    layout_text(memory.triangle_cache) + ": " + std::to_string(memory.triangle_cache.bytes()) +
                    " B, with their directories) need " + std::to_string(memory.shared_bytes()) + " B, over the " +
                    std::to_string(budget) + " B of shared memory a block of this device has");
    // Tags hold line numbers in 32 bits, ~0 marking an empty line: the smallest line (16 B) must number them.
    if (tree_bytes >= (std::uint64_t(SharedCache::kEmpty) << 4))
        throw Error("the shared-memory caches address at most 64 GiB of tree, not " + std::to_string(tree_bytes) + " B");
}

}  // namespace cellrt::detail
