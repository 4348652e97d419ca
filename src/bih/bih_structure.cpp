#include "bih_structure.hpp"

#include "kernel/param_reader.hpp"

namespace cellrt::detail {
namespace {

constexpr Named<BihSplit> kSplits[] = {{"global", BihSplit::global}, {"sah", BihSplit::sah}};

std::string text(double v) { return param_number(v); }

}  // namespace

// Defaults are BihBuildParams's (bih_tree.hpp).
const ParamTable& BihStructure::param_table() {
    static const ParamTable table = [] {
        const BihBuildParams d;
        using enum ParamType;
        return ParamTable{
            {"split", choice, name_of(kSplits, d.split), 0, 0, names_of(kSplits),
             "the study's global heuristic, or the SAH over binned centres (docs/BIH.md)"},
            {"leaf_size", integer, text(d.leaf_size), 1, 1 << 20, {},
             "nodes with at most this many triangles are leaves (Sunflow's choice)"},
            {"max_depth", integer, text(d.max_depth), 1, kBihMaxDepth, {},
             "depth limit; traversal stacks are sized by its largest value"},
            {"empty_cut", number, text(d.empty_cut), 0.0, 1.0, {},
             "emit an empty-space node when more than this fraction of the node is empty beside its triangles "
             "(Sunflow's 1/1.3 rule); 1 never does"},
            {"traversal_cost", number, text(d.traversal_cost), 1e-6, 1e6, {},
             "`split=sah`: cost of a node visit (the kd-tree's default, so that the two structures' trees compare)"},
            {"intersection_cost", number, text(d.intersection_cost), 1e-6, 1e6, {},
             "`split=sah`: cost of a triangle test (the kd-tree's default)"},
            {"sah_max_leaf", integer, text(d.sah_max_leaf), 1, 1 << 20, {},
             "`split=sah`: the largest leaf made when no split is cheaper; larger nodes take the cheapest split "
             "(nodes of `leaf_size` triangles or fewer are leaves first: at or below it, no effect)"},
        };
    }();
    return table;
}

BihBuildParams read_bih_params(const AccelConfig& config) {
    ParamReader in(BihStructure::param_table(), config, BihStructure::kName);
    BihBuildParams p;
    p.split = value_named(kSplits, in.choice("split"), "BIH split");
    p.leaf_size = in.integer("leaf_size");
    p.max_depth = in.integer("max_depth");
    p.empty_cut = in.number("empty_cut");
    p.traversal_cost = in.number("traversal_cost");
    p.intersection_cost = in.number("intersection_cost");
    p.sah_max_leaf = in.integer("sah_max_leaf");
    p.threads = config.threads;
    in.finish();
    return p;
}

// Every parameter in force, as `bih@...` takes them back, the SAH's too (read only with split=sah).
std::vector<std::pair<std::string, std::string>> BihStructure::settings() const {
    const BihBuildParams& p = params;
    std::vector<std::pair<std::string, std::string>> s{{"split", name_of(kSplits, p.split)}};
    if (p.split == BihSplit::sah)
        s.emplace_back("costs", "traversal " + text(p.traversal_cost) + ", intersection " + text(p.intersection_cost));
    s.emplace_back("parameters", param_list({{"split", name_of(kSplits, p.split)},
                                             {"leaf_size", text(p.leaf_size)},
                                             {"max_depth", text(p.max_depth)},
                                             {"empty_cut", param_text_exact(p.empty_cut)},
                                             {"traversal_cost", param_text_exact(p.traversal_cost)},
                                             {"intersection_cost", param_text_exact(p.intersection_cost)},
                                             {"sah_max_leaf", text(p.sah_max_leaf)}}));
    return s;
}

}  // namespace cellrt::detail
