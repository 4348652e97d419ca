#include "kd_structure.hpp"

#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

constexpr Named<KdBuildMethod> kMethods[] = {
    {"hybrid", KdBuildMethod::hybrid}, {"sweep", KdBuildMethod::sweep}, {"binned", KdBuildMethod::binned}};

std::string text(double v) { return param_number(v); }
std::string text(bool v) { return v ? "true" : "false"; }

}  // namespace

// Defaults are KdBuildParams's (kd_tree.hpp), so that a builder called directly and one called
// through the table build the same tree.
const ParamTable& KdStructure::param_table() {
    static const ParamTable table = [] {
        const KdBuildParams d;
        using enum ParamType;
        return ParamTable{
            {"traversal_cost", number, text(d.traversal_cost), 1e-6, 1e6, {},
             "`K_T`, cost of a traversal step (Wald & Havran's constant); trees for SIMD packets default to " +
                 text(kKdPacketTraversalCost) + " (a packet tests a triangle on all lanes for about one step's price)"},
            {"intersection_cost", number, text(d.intersection_cost), 1e-6, 1e6, {},
             "`K_I`, cost of a triangle test (Wald & Havran's constant)"},
            {"empty_bonus", number, text(d.empty_bonus), 0.0, 0.99, {},
             "a split with an empty side costs `(1 - empty_bonus)` x its SAH (Mitsuba 0.6's 0.9; W&H's lambda = 0.8 "
             "is 0.2)"},
            {"max_depth", integer, text(double(d.max_depth)), 0, kKdMaxDepth, {},
             "depth limit; 0 chooses `8 + 1.3 log2 N` (pbrt's and Mitsuba's rule), capped at " + text(double(kKdMaxDepth))},
            {"leaf_size", integer, text(double(d.leaf_size)), 0, 1 << 20, {},
             "nodes with at most this many triangles are leaves (Mitsuba's `stopPrims`)"},
            {"method", choice, name_of(kMethods, d.method), 0, 0, names_of(kMethods),
             "binning above `sweep_below` references and the exact sweep below, or one of them for the whole build"},
            {"sweep_below", integer, text(double(d.sweep_below)), 1, 1 << 30, {}, "the switch-over of `hybrid`"},
            {"bins", integer, text(double(d.bins)), 4, 4096, {},
             "bins per axis of min-max binning (Mitsuba's default)"},
            {"perfect_splits", boolean, text(d.perfect_splits), 0, 0, {},
             "clip straddling triangles to the child cells"},
            {"clip_ratio", number, text(d.clip_ratio), 0.0, 1.0, {},
             "with perfect splits, clip only straddlers whose box spans at least this fraction of the cell on an "
             "axis other than the split axis (others: their box cut to each child cell); 0 clips all"},
            {"retract", boolean, text(d.retract), 0, 0, {}, "replace subtrees no cheaper than a leaf by the leaf"},
            {"max_bad_refines", integer, text(double(d.max_bad_refines)), 0, 64, {},
             "the bad-refinement rule's allowance per path"},
        };
    }();
    return table;
}

KdBuildParams read_kd_params(const AccelConfig& config) {
    ParamReader in(KdStructure::param_table(), config, KdStructure::kName);
    KdBuildParams p;
    const std::string packet_default = text(kKdPacketTraversalCost);
    p.traversal_cost = in.number("traversal_cost", config.simd == "off" ? nullptr : &packet_default);
    p.intersection_cost = in.number("intersection_cost");
    p.empty_bonus = in.number("empty_bonus");
    p.max_depth = in.integer("max_depth");
    p.leaf_size = in.integer("leaf_size");
    p.method = value_named(kMethods, in.choice("method"), "kd build method");
    p.sweep_below = in.integer("sweep_below");
    p.bins = in.integer("bins");
    p.perfect_splits = in.boolean("perfect_splits");
    p.clip_ratio = in.number("clip_ratio");
    p.retract = in.boolean("retract");
    p.max_bad_refines = in.integer("max_bad_refines");
    p.threads = config.threads;
    in.finish();
    return p;
}

// Every parameter in force, as `kd@...` takes them back (Mitsuba 0.6's build report lists its
// whole configuration): a report says which tree it describes.
std::vector<std::pair<std::string, std::string>> KdStructure::settings() const {
    const KdBuildParams& p = params;
    return {{"method", name_of(kMethods, p.method)},
            {"costs", "traversal " + text(p.traversal_cost) + ", intersection " + text(p.intersection_cost)},
            {"parameters", param_list({{"traversal_cost", param_text_exact(p.traversal_cost)},
                                       {"intersection_cost", param_text_exact(p.intersection_cost)},
                                       {"empty_bonus", param_text_exact(p.empty_bonus)},
                                       {"max_depth", text(double(p.max_depth))},
                                       {"leaf_size", text(double(p.leaf_size))},
                                       {"method", name_of(kMethods, p.method)},
                                       {"sweep_below", text(double(p.sweep_below))},
                                       {"bins", text(double(p.bins))},
                                       {"perfect_splits", text(p.perfect_splits)},
                                       {"clip_ratio", param_text_exact(p.clip_ratio)},
                                       {"retract", text(p.retract)},
                                       {"max_bad_refines", text(double(p.max_bad_refines))}})}};
}

}  // namespace cellrt::detail
