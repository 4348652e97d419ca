// The layers of docs/ARCHITECTURE.md, enforced: the test reads the table of layers from the document
// itself, so the table is exactly the rule. Every source file belongs to one module (a row); a file
// may include a file of its own module or of a lower layer, never one of a higher layer or of another
// module of its own layer.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace cellrt {
namespace {

namespace fs = std::filesystem;

struct Module {
    int layer = 0;
    std::string name;
    std::vector<std::string> paths;  // files, or folders ending in '/', relative to the root
};

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// The rows between <!-- layers --> and <!-- /layers -->: | layer | module | `path`, `path/` ... | what |
std::vector<Module> parse_layers(const std::string& doc) {
    std::vector<Module> modules;
    const auto begin = doc.find("<!-- layers -->"), end = doc.find("<!-- /layers -->");
    if (begin == std::string::npos || end == std::string::npos) return modules;
    std::istringstream lines(doc.substr(begin, end - begin));
    const std::regex row(R"(^\|\s*(\d+)\s*\|\s*([^|]+?)\s*\|([^|]*)\|)"), path("`([^`]+)`");
    for (std::string line; std::getline(lines, line);) {
        std::smatch m;
        if (!std::regex_search(line, m, row)) continue;
        Module mod{std::stoi(m[1]), m[2], {}};
        const std::string cell = m[3];
        for (auto it = std::sregex_iterator(cell.begin(), cell.end(), path); it != std::sregex_iterator(); ++it)
            mod.paths.push_back((*it)[1]);
        modules.push_back(std::move(mod));
    }
    return modules;
}

// The module of `rel` (a path relative to the root): the one with the longest matching path; -1 if none.
int module_of(const std::vector<Module>& modules, const std::string& rel) {
    int best = -1;
    std::size_t best_length = 0;
    for (std::size_t i = 0; i < modules.size(); ++i)
        for (const std::string& p : modules[i].paths) {
            const bool match = p.back() == '/' ? rel.rfind(p, 0) == 0 : rel == p;
            if (match && p.size() > best_length) best = static_cast<int>(i), best_length = p.size();
        }
    return best;
}

bool is_source(const fs::path& p) {
    const std::string e = p.extension().string();
    return e == ".hpp" || e == ".cpp" || e == ".inl" || e == ".h" || e == ".cu" || e == ".cuh";
}

// Every violation of the rule in the tree at `root` (folders src, include, apps, bench, tests, python): a file
// no module holds, or an include that climbs a layer or crosses to a sibling module.
std::vector<std::string> violations(const fs::path& root, const std::vector<Module>& modules) {
    std::vector<std::string> out;
    if (modules.empty()) return {"no table of layers found"};
    const std::regex include(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
    for (const char* top : {"src", "include", "apps", "bench", "tests", "python"}) {
        if (!fs::exists(root / top)) continue;
        std::vector<fs::path> files;
        for (const auto& f : fs::recursive_directory_iterator(root / top))
            if (f.is_regular_file() && is_source(f.path())) files.push_back(f.path());
        std::sort(files.begin(), files.end());
        for (const fs::path& file : files) {
            const std::string rel = fs::relative(file, root).generic_string();
            const int from = module_of(modules, rel);
            if (from < 0) {
                out.push_back(rel + ": in no module of the table");
                continue;
            }
            std::ifstream in(file);
            int line_number = 0;
            for (std::string line; std::getline(in, line);) {
                ++line_number;
                std::smatch m;
                if (!std::regex_search(line, m, include)) continue;
                const std::string name = m[1];
                // Resolved as the compiler does: beside the file, then under the include roots.
                std::string target;
                for (const fs::path& candidate : {file.parent_path() / name, root / "src" / name, root / "include" / name})
                    if (fs::exists(candidate)) {
                        target = fs::relative(fs::weakly_canonical(candidate), root).generic_string();
                        break;
                    }
                if (target.empty()) continue;  // a system or third-party header
                const int to = module_of(modules, target);
                if (to < 0 || to == from) continue;  // unassigned targets are reported on their own
                const Module &a = modules[static_cast<std::size_t>(from)], &b = modules[static_cast<std::size_t>(to)];
                if (b.layer >= a.layer)
                    out.push_back(rel + ":" + std::to_string(line_number) + ": " + a.name + " (layer " +
                                  std::to_string(a.layer) + ") includes " + target + " of " + b.name + " (layer " +
                                  std::to_string(b.layer) + ")");
            }
        }
    }
    return out;
}

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += x + "\n";
    return s;
}

const fs::path kRoot = fs::path(CELLRT_TEST_DATA).parent_path().parent_path();

TEST(Architecture, EveryIncludeKeepsToTheLayersOfArchitectureMd) {
    const auto modules = parse_layers(read_text(kRoot / "docs" / "ARCHITECTURE.md"));
    ASSERT_GE(modules.size(), 8u) << "the table of layers in docs/ARCHITECTURE.md was not found";
    const auto found = violations(kRoot, modules);
    EXPECT_TRUE(found.empty()) << joined(found);
}

// The check itself fails where it should: on a tree with a climbing include, a sibling include and a
// file outside every module, and only there.
TEST(Architecture, TheCheckFindsClimbingAndSiblingIncludes) {
    const fs::path root = fs::temp_directory_path() / ("cellrt_layers_" + std::to_string(::getpid()));
    fs::remove_all(root);
    auto write = [&](const std::string& rel, const std::string& text) {
        fs::create_directories((root / rel).parent_path());
        std::ofstream(root / rel) << text;
    };
    const std::string table =
        "<!-- layers -->\n| layer | module | paths | what |\n|---|---|---|---|\n"
        "| 0 | core | `include/x/core.hpp`, `src/core/` | c |\n| 1 | a | `src/a/` | a |\n"
        "| 1 | b | `src/b/` | b |\n| 2 | top | `src/top/` | t |\n<!-- /layers -->\n";
    write("include/x/core.hpp", "#pragma once\n");
    write("src/core/core.cpp", "#include \"x/core.hpp\"\n");
    write("src/a/a.hpp", "#include \"x/core.hpp\"\n#include <vector>\n");
    write("src/a/a.cpp", "#include \"a.hpp\"\n#include \"top/top.hpp\"\n");  // climbs
    write("src/b/b.hpp", "#include \"a/a.hpp\"\n");                          // sibling
    write("src/top/top.hpp", "#include \"a/a.hpp\"\n#include \"b/b.hpp\"\n");
    write("src/stray/s.hpp", "\n");
    const auto found = violations(root, parse_layers(table));
    fs::remove_all(root);
    ASSERT_EQ(found.size(), 3u) << joined(found);
    EXPECT_NE(found[0].find("src/a/a.cpp:2: a (layer 1) includes src/top/top.hpp of top (layer 2)"), std::string::npos)
        << found[0];
    EXPECT_NE(found[1].find("src/b/b.hpp:1: b (layer 1) includes src/a/a.hpp of a (layer 1)"), std::string::npos)
        << found[1];
    EXPECT_NE(found[2].find("src/stray/s.hpp: in no module"), std::string::npos) << found[2];
}

// A structure's types stay in its folder: every other consumer reaches a tree through its descriptor
// as listed once in the registry (src/accel/structures.hpp), and no library or program code picks a
// path by comparing a tree's kind string. (Tests may look inside the structures they test.)
TEST(Architecture, StructureTypesAndKindsStayInTheirFolders) {
    const std::regex names(R"(\b(KdNode|BihNode|KdTree|BihTree|KdTraits|BihTraits|KdStructure|BihStructure)\b)");
    const std::regex kinds(R"re([!=]=\s*"(kd|bih)"|"(kd|bih)"\s*[!=]=)re");
    std::vector<std::string> found;
    for (const char* top : {"src", "include", "apps", "bench", "python"})
        for (const auto& f : fs::recursive_directory_iterator(kRoot / top)) {
            if (!f.is_regular_file() || !is_source(f.path())) continue;
            const std::string rel = fs::relative(f.path(), kRoot).generic_string();
            const bool own = rel.rfind("src/kdtree/", 0) == 0 || rel.rfind("src/bih/", 0) == 0 ||
                             rel == "src/accel/structures.hpp";
            std::ifstream in(f.path());
            int n = 0;
            for (std::string line; std::getline(in, line);) {
                ++n;
                if (!own && std::regex_search(line, names)) found.push_back(rel + ":" + std::to_string(n) + ": " + line);
                if (std::regex_search(line, kinds)) found.push_back(rel + ":" + std::to_string(n) + ": " + line);
            }
        }
    EXPECT_TRUE(found.empty()) << joined(found);
}

}  // namespace
}  // namespace cellrt
