#include "local_store.hpp"

#include "cellrt/error.hpp"
#include "cellrt/ray.hpp"

namespace cellrt {

CacheAccess parse_cache_access(const std::string& option, const std::string& text) {
    if (text == "sync") return CacheAccess::sync;
    if (text == "async") return CacheAccess::async;
    throw Error(option + " '" + text + "' must be sync or async");
}

const char* to_string(CacheAccess access) { return access == CacheAccess::sync ? "sync" : "async"; }

std::size_t max_batch_rays(std::size_t budget_bytes) { return budget_bytes / (sizeof(Ray) + sizeof(Hit)); }

std::vector<LocalStoreAllocation> allocate_local_store(const LocalStoreConfig& config, std::size_t stack_bytes) {
    validate_cache_layout(config.node_cache, "node cache " + config.node_cache.to_string());
    validate_cache_layout(config.triangle_cache, "triangle cache " + config.triangle_cache.to_string());
    if (config.batch_rays == 0) throw Error("local store: a batch needs at least one ray");
    // Checked before any product or sum below can overflow; the model's transfers count 32-bit bytes.
    if (config.budget_bytes > kMaxLocalStoreBytes)
        throw Error("local store: a budget of " + std::to_string(config.budget_bytes) + " bytes is more than the " +
                    "model's " + std::to_string(kMaxLocalStoreBytes));
    if (config.batch_rays > max_batch_rays(config.budget_bytes))
        throw Error("local store: a batch of " + std::to_string(config.batch_rays) + " rays and results needs more " +
                    "than the budget of " + std::to_string(config.budget_bytes) + " bytes");
    auto cache = [](const char* name, const CacheLayout& l) {
        return LocalStoreAllocation{std::string(name) + " " + l.to_string(),
                                    l.capacity() + l.lines() * kDirectoryBytesPerLine};
    };
    const std::vector<LocalStoreAllocation> allocations = {
        cache("node cache", config.node_cache),
        cache("triangle cache", config.triangle_cache),
        {"traversal stack", stack_bytes},
        {"batch of " + std::to_string(config.batch_rays) + " rays and results",
         config.batch_rays * (sizeof(Ray) + sizeof(Hit))},
    };
    std::size_t total = 0;
    for (const auto& a : allocations) total += a.bytes;
    if (total <= config.budget_bytes) return allocations;
    std::string parts;
    for (const auto& a : allocations) parts += (parts.empty() ? "" : ", ") + a.what + " " + std::to_string(a.bytes);
    throw Error("local store: the configuration needs " + std::to_string(total) + " bytes, " +
                std::to_string(total - config.budget_bytes) + " more than the budget of " +
                std::to_string(config.budget_bytes) + " bytes (" + parts + "; caches count " +
                std::to_string(kDirectoryBytesPerLine) + " directory bytes per line)");
}

}  // namespace cellrt
