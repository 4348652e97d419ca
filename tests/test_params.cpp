// Every structure's parameter table: it validates, it is what the documents print, and every value it
// calls a default is one it accepts.
#include <gtest/gtest.h>

#include <algorithm>
#include <clocale>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "cellrt/accel.hpp"
#include "cellrt/builtin.hpp"
#include "cellrt/error.hpp"
#include "cuda/device_memory.hpp"

namespace cellrt {
namespace {

namespace fs = std::filesystem;

const fs::path kDocs = fs::path(CELLRT_TEST_DATA).parent_path().parent_path() / "docs";

const std::vector<Triangle>& small_scene() {
    static const Scene scene = load_scene("builtin:spheres?tris=400");
    return scene.triangles;
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// The text between <!-- params:KIND --> and <!-- /params --> in `doc`, without the surrounding newlines.
std::string documented_table(const std::string& doc, const std::string& kind) {
    const std::string open = "<!-- params:" + kind + " -->\n";
    const auto b = doc.find(open);
    if (b == std::string::npos) return "(no table marked " + open + ")";
    const auto e = doc.find("<!-- /params -->", b);
    return doc.substr(b + open.size(), e - b - open.size());
}

// The documents' tables are the code's tables, row for row (`cellrt info --params KIND` prints the
// same; rewrite a document's table from it when a parameter changes).
TEST(Params, DocumentsPrintTheTablesThatValidate) {
    std::vector<std::pair<std::string, std::string>> docs{{"kd", "KDTREE.md"}, {"bih", "BIH.md"}, {"bvh", "BVH.md"}, {"auto", "BVH.md"}};
    const auto kinds = accelerator_kinds();
    if (std::find(kinds.begin(), kinds.end(), "embree") != kinds.end()) docs.emplace_back("embree", "EMBREE.md");
    for (const auto& [kind, file] : docs)
        EXPECT_EQ(documented_table(read_text(kDocs / file), kind), param_table_markdown(accelerator_params(kind)))
            << "docs/" << file << " against the table of " << kind;
    EXPECT_EQ(documented_table(read_text(kDocs / "GPU.md"), "cuda"), param_table_markdown(detail::device_memory_params()))
        << "docs/GPU.md against the CUDA backend's memory parameters";
}

// Every default the tables print is accepted as a user's value, and giving every parameter at its
// default builds the tree that giving none does.
TEST(Params, DefaultsAreValidValuesAndTheBuildsDefaults) {
    for (const std::string& kind : accelerator_kinds()) {
        AccelConfig plain;
        plain.kind = kind;
        plain.threads = 1;
        AccelConfig spelled = plain;
        for (const ParamSpec& p : accelerator_params(kind)) spelled.params[p.name] = p.default_value;
        std::unique_ptr<Accelerator> a, b;
        ASSERT_NO_THROW(a = make_accelerator(small_scene(), plain)) << kind;
        ASSERT_NO_THROW(b = make_accelerator(small_scene(), spelled)) << kind;
        const AccelStats sa = a->stats(), sb = b->stats();
        EXPECT_EQ(sa.memory_bytes != 0, sb.memory_bytes != 0) << kind;
        if (sa.tree) {
            ASSERT_TRUE(sb.tree) << kind;
            EXPECT_EQ(sa.tree->nodes, sb.tree->nodes) << kind;
            EXPECT_EQ(sa.tree->sah_cost, sb.tree->sah_cost) << kind;
        }
    }
}

// A tree's report names every parameter in force, as the configuration takes them back: built again
// from the report's `parameters`, the tree is the same (the kd-tree's report named its method and
// costs only, so a report of `-P leaf_size=4` could not say which tree it described).
TEST(Params, ReportsNameEveryParameterInForceAndBuildTheSameTreeAgain) {
    // Long fractions too: six digits, as the tables print them, gave 0.1234567 back as 0.123457.
    for (const std::string spec : {"kd@leaf_size=4,empty_bonus=0.25", "kd:branched@perfect_splits=false",
                                   "kd@empty_bonus=0.1234567,traversal_cost=123456.7,clip_ratio=0.0123456789",
                                   "bih@split=sah,sah_max_leaf=8,traversal_cost=15.000001", "bih@leaf_size=3"}) {
        AccelConfig c = parse_accel_config(spec);
        c.threads = 1;
        const AccelStats first = make_accelerator(small_scene(), c)->stats();
        const std::string parameters = first.setting("parameters").value_or("");
        ASSERT_FALSE(parameters.empty()) << spec;
        for (const ParamSpec& p : accelerator_params(c.kind))
            EXPECT_NE(parameters.find(p.name + "="), std::string::npos) << spec << ": " << parameters;
        const std::string kind = c.kind + (c.traversal.empty() ? "" : ":" + c.traversal);
        AccelConfig again = parse_accel_config(kind + "@" + parameters);
        again.threads = 1;
        const AccelStats second = make_accelerator(small_scene(), again)->stats();
        EXPECT_EQ(second.setting("parameters"), first.setting("parameters")) << spec;
        ASSERT_TRUE(first.tree && second.tree) << spec;
        EXPECT_EQ(second.tree->nodes, first.tree->nodes) << spec;
        EXPECT_EQ(second.tree->sah_cost, first.tree->sah_cost) << spec;
    }
}

// Parameter numbers are written (the tables' defaults, the settings) and read in the C locale's form
// whatever the process's locale: printf's "%.0f" and "%g" as the C locale writes them, and a build
// with the defaults works under a locale whose decimal point is a comma (a caller's setlocale, as
// Python's locale.setlocale or a C program's, once made every default unreadable).
TEST(Params, NumbersAreWrittenAndReadAlikeInEveryLocale) {
    for (const double v : {0.0, 1.0, 15.0, 45.0, 0.1, 0.05, 0.99, 1e-6, 1e6, 2.5e-3, 123456.7, 1e15, 1e20, -0.5}) {
        char c_form[64];
        if (v == std::floor(v) && std::fabs(v) < 1e15) std::snprintf(c_form, sizeof c_form, "%.0f", v);
        else std::snprintf(c_form, sizeof c_form, "%g", v);
        EXPECT_EQ(param_number(v), c_form);
    }
    // A number too small for a double is read as the nearest double (0 here), as strtod read it.
    AccelConfig tiny = parse_accel_config("kd@empty_bonus=1e-400");
    tiny.threads = 1;
    EXPECT_NO_THROW(make_accelerator(small_scene(), tiny));
    struct Restore {
        std::string numeric = std::setlocale(LC_NUMERIC, nullptr);
        ~Restore() { std::setlocale(LC_NUMERIC, numeric.c_str()); }
    } restore;
    bool comma = false;
    for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8", "nl_NL.UTF-8", "ru_RU.UTF-8"})
        if (std::setlocale(LC_NUMERIC, name) && std::string(std::localeconv()->decimal_point) == ",") {
            comma = true;
            break;
        }
    if (!comma) GTEST_SKIP() << "no locale with a decimal comma is installed (localedef -i de_DE -f UTF-8 de_DE.UTF-8)";
    EXPECT_EQ(param_number(0.1), "0.1");
    EXPECT_EQ(param_number(1e-6), "1e-06");
    for (const std::string kind : {"kd", "bih", "bvh", "auto"}) {
        AccelConfig c;
        c.kind = kind;
        c.threads = 1;
        for (const ParamSpec& p : accelerator_params(kind)) {
            if (p.type == ParamType::number) c.params[p.name] = param_number(std::min(p.max, std::max(p.min, 0.25)));
        }
        EXPECT_NO_THROW(make_accelerator(small_scene(), c)) << kind;
    }
    AccelConfig comma_text;
    comma_text.kind = "kd";
    comma_text.params = {{"empty_bonus", "0,25"}};
    EXPECT_THROW(make_accelerator(small_scene(), comma_text), Error);
}

// Unknown names, values beyond a range, and unknown kinds or traversals are refused everywhere, with
// the structure and the parameter named.
TEST(Params, UnknownNamesAndValuesOutOfRangeAreRefused) {
    for (const std::string& kind : accelerator_kinds()) {
        AccelConfig c;
        c.kind = kind;
        c.params = {{"no_such_parameter", "1"}};
        try {
            make_accelerator(small_scene(), c);
            ADD_FAILURE() << kind << " accepted an unknown parameter";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("no_such_parameter"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(kind), std::string::npos) << e.what();
        }
        c.params.clear();
        c.traversal = "no_such_traversal";
        EXPECT_THROW(make_accelerator(small_scene(), c), Error) << kind;
        for (const ParamSpec& p : accelerator_params(kind)) {
            std::vector<std::string> bad{"", "x1"};
            if (p.type == ParamType::number || p.type == ParamType::integer) {
                char below[64], above[64];
                std::snprintf(below, sizeof below, "%.17g", p.min - 1.0);
                std::snprintf(above, sizeof above, "%.17g", p.max * 2.0 + 1.0);
                bad.insert(bad.end(), {below, above});
            }
            for (const std::string& v : bad) {
                AccelConfig b;
                b.kind = kind;
                b.params = {{p.name, v}};
                EXPECT_THROW(make_accelerator(small_scene(), b), Error) << kind << " " << p.name << "='" << v << "'";
            }
        }
    }
    EXPECT_THROW(accelerator_params("octree"), Error);
    EXPECT_THROW(accelerator_traversals("octree"), Error);
    // Numbers beyond a double's or a long's range are out of the parameter's range, NaN is no number.
    auto error_of = [](const std::string& kind, const std::string& name, const std::string& value) {
        AccelConfig c;
        c.kind = kind;
        c.params = {{name, value}};
        try {
            make_accelerator(small_scene(), c);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    auto range_of = [](const std::string& kind, const std::string& name) {
        for (const ParamSpec& p : accelerator_params(kind))
            if (p.name == name) return param_range(p);
        return std::string("(no parameter ") + name + ")";
    };
    for (const std::string v : {"1e309", "-1e309", "inf", "-inf"})
        EXPECT_EQ(error_of("kd", "traversal_cost", v),
                  "kd parameter traversal_cost=" + v + " is out of range " + range_of("kd", "traversal_cost"));
    EXPECT_EQ(error_of("kd", "traversal_cost", "nan"), "kd parameter traversal_cost='nan' is not a number");
    // The whole text is a decimal number, as in the scene files: no blanks, no hexadecimal (strtod
    // took both); a leading '+' is read.
    for (const std::string v : {" 5", "5 ", "0x10", "5,0", "", "1e", ".", "++5"})
        EXPECT_EQ(error_of("kd", "traversal_cost", v), "kd parameter traversal_cost='" + v + "' is not a number");
    for (const std::string v : {" 2", "0x2", "2.0", "1e1", ""})
        EXPECT_EQ(error_of("bih", "leaf_size", v), "bih parameter leaf_size='" + v + "' is not an integer");
    EXPECT_EQ(error_of("kd", "traversal_cost", "-0"),
              "kd parameter traversal_cost=-0 is out of range " + range_of("kd", "traversal_cost"));
    for (const std::string v : {"99999999999999999999", "-99999999999999999999", "9223372036854775807"})
        EXPECT_EQ(error_of("bih", "leaf_size", v),
                  "bih parameter leaf_size=" + v + " is out of range " + range_of("bih", "leaf_size"));
    EXPECT_THROW(make_accelerator(small_scene(), AccelConfig{"octree"}), Error);
}

TEST(Params, TablesListEveryTraversalTheStructuresOffer) {
    EXPECT_EQ(accelerator_traversals("kd"), (std::vector<std::string>{"branched", "rec", "branchless"}));
    EXPECT_EQ(accelerator_traversals("bih"), (std::vector<std::string>{"branched", "branchless"}));
    for (const std::string& kind : accelerator_kinds())
        for (const std::string& t : accelerator_traversals(kind)) {
            AccelConfig c;
            c.kind = kind;
            c.traversal = t;
            try {
                make_accelerator(small_scene(), c);
            } catch (const Error& e) {
                // Embree's packet widths are the processor's: a width it lacks (16 without AVX-512)
                // is refused, saying so, and is no defect of the table.
                const bool missing_width = kind == "embree" && std::string(e.what()).find("needs native") != std::string::npos;
                EXPECT_TRUE(missing_width) << kind << ":" << t << ": " << e.what();
            }
        }
}

// The SAH BIH's costs are parameters: with triangle tests made dearer against node visits, the SAH
// splits further, into more nodes.
TEST(Params, BihSahCostsShapeTheTree) {
    auto nodes = [](const std::string& intersection) {
        AccelConfig c = parse_accel_config("bih@split=sah,intersection_cost=" + intersection);
        return make_accelerator(small_scene(), c)->stats().tree.value().nodes;
    };
    EXPECT_LT(nodes("1"), nodes("1000"));
}

// An accelerator spec splits into its parts (checked later by make_accelerator); a parameter without
// a name or an '=' is refused in the spec's words.
TEST(Params, AcceleratorSpecsSplitOrAreRefused) {
    const AccelConfig c = parse_accel_config("kd:rec+avx2@leaf_size=2,bins=64");
    EXPECT_EQ(c.kind, "kd");
    EXPECT_EQ(c.traversal, "rec");
    EXPECT_EQ(c.simd, "avx2");
    EXPECT_EQ(c.params, (std::map<std::string, std::string>{{"leaf_size", "2"}, {"bins", "64"}}));
    for (const auto& [spec, part] : std::vector<std::pair<std::string, std::string>>{
             {"kd@", ""}, {"kd@leaf_size", "leaf_size"}, {"kd@=2", "=2"}, {"kd@a=1,,b=2", ""}, {"kd@a=1,", ""}}) {
        try {
            parse_accel_config(spec);
            ADD_FAILURE() << spec << " accepted";
        } catch (const Error& e) {
            EXPECT_EQ(std::string(e.what()), "accelerator parameter '" + part + "' must have the form NAME=VALUE");
        }
    }
    EXPECT_THROW(make_accelerator(small_scene(), parse_accel_config("kd+avx2:rec")), Error);  // SIMD set 'avx2:rec'
}

// A configuration written back is the canonical spec that parses to it: parts left out when absent
// or "off" (but "off" where it alone names a single-ray kernel: the CLI's and Python's bare "kd" is
// the packets), parameters by name. A repeated name, and an empty traversal or SIMD set, are refused.
TEST(Params, AcceleratorSpecsFormatBackToWhatTheyParseTo) {
    for (const auto& [spec, canonical] : std::vector<std::pair<std::string, std::string>>{
             {"kd", "kd+off"},
             {"kd:rec", "kd:rec"},
             {"kd+off", "kd+off"},
             {"kd:rec+off", "kd:rec"},
             {"bih", "bih+off"},
             {"brute", "brute+off"},
             {"bvh", "bvh"},
             {"embree", "embree"},
             {"bih+avx2", "bih+avx2"},
             {"kd:rec+avx2@leaf_size=2,bins=64", "kd:rec+avx2@bins=64,leaf_size=2"},
             {"auto@packets=bvh", "auto@packets=bvh"},
             {"kd@note=a:b+c", "kd+off@note=a:b+c"}}) {
        const AccelConfig c = parse_accel_config(spec);
        EXPECT_EQ(format_accel_config(c), canonical) << spec;
        const AccelConfig back = parse_accel_config(format_accel_config(c));
        EXPECT_EQ(back.kind, c.kind) << spec;
        EXPECT_EQ(back.traversal, c.traversal) << spec;
        EXPECT_EQ(back.simd, c.simd) << spec;
        EXPECT_EQ(back.params, c.params) << spec;
    }
    for (const char* bad : {"bvh@bins=8,bins=16", "kd:", "kd+", "kd:+sse"})
        EXPECT_THROW(parse_accel_config(bad), Error) << bad;
    EXPECT_EQ(format_accel_config(default_accel_config()), "auto@packets=bvh");
    EXPECT_EQ(format_accel_config(default_accel_config("cuda")), "kd+off");
}

}  // namespace
}  // namespace cellrt
