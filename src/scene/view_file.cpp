// View files: JSON with mesh, camera, light and image (shared/scenes/README.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string_view>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "cellrt/error.hpp"
#include "cellrt/image.hpp"
#include "cellrt/loaders.hpp"
#include "core/files.hpp"
#include "core/read_file.hpp"

namespace cellrt {
namespace {

using nlohmann::json;

// Where a text stops being JSON, found by reading it again event by event: of nlohmann's exceptions
// only the syntax errors carry a position, not a number beyond a double's range (out_of_range 406).
class ErrorPosition final : public json::json_sax_t {
public:
    // The byte offset of the first error in `text`, or its end when there is none.
    static std::size_t in(const std::string& text) {
        ErrorPosition sax;
        sax.position_ = text.size();
        json::sax_parse(text, &sax, json::input_format_t::json, /*strict=*/true, /*ignore_comments=*/true);
        return std::min(sax.position_, text.size());
    }

    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override { return true; }
    bool key(string_t&) override { return true; }
    bool end_object() override { return true; }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    bool parse_error(std::size_t position, const std::string&, const json::exception&) override {
        position_ = position;
        return false;
    }

private:
    std::size_t position_ = 0;
};

// nlohmann's description of an error without its exception id ("[json.exception.parse_error.101] ")
// and the position it gives in its own words ("parse error at line 1, column 31: "), since the
// message names the line in cellrt's form.
std::string reason(const json::exception& e) {
    std::string_view what = e.what();
    if (const std::size_t id = what.find("] "); what.starts_with("[json.exception.") && id != what.npos)
        what.remove_prefix(id + 2);
    if (const std::size_t at = what.find(": "); what.starts_with("parse error at line") && at != what.npos)
        what.remove_prefix(at + 2);
    return std::string(what);
}

class ViewReader {
public:
    explicit ViewReader(const std::string& path) : path_(path) {}

    static constexpr int kMaxDepth = 64;

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw Error(path_ + ": field '" + field + "' " + what);
    }

    const json& field(const json& parent, const std::string& parent_name, const char* key) const {
        const std::string name = parent_name.empty() ? key : parent_name + "." + key;
        if (!parent.is_object() || !parent.contains(key)) fail(name, "is missing");
        return parent.at(key);
    }

    // A field that holds fields: "camera": null was "field 'camera.position' is missing".
    const json& object(const json& parent, const char* key) const {
        const json& j = field(parent, "", key);
        if (!j.is_object()) fail(key, "must be an object");
        return j;
    }

    double number(const json& j, const std::string& name) const {
        if (!j.is_number()) fail(name, "must be a number");
        const double v = j.get<double>();
        if (!std::isfinite(v)) fail(name, "must be finite");
        return v;
    }

    // Every field is kept as a float: a number beyond float's range became an infinity that the
    // camera or the light refused without naming the field.
    float single(const json& j, const std::string& name) const {
        const double v = number(j, name);
        if (std::fabs(v) > std::numeric_limits<float>::max())
            fail(name, "is " + j.dump() + ", beyond a float's range (about 3.4e38)");
        return static_cast<float>(v);
    }

    Vec3 vec3(const json& parent, const std::string& parent_name, const char* key) const {
        const std::string name = parent_name + "." + key;
        const json& j = field(parent, parent_name, key);
        if (!j.is_array() || j.size() != 3) fail(name, "must be an array of three numbers");
        return {single(j[0], name + "[0]"), single(j[1], name + "[1]"), single(j[2], name + "[2]")};
    }

    // Refuses a key the format does not have: a misspelt optional field ("colour") would otherwise
    // leave its default in place without a word.
    void only(const json& object, const std::string& object_name, std::initializer_list<const char*> keys) const {
        if (!object.is_object()) return;  // field() says what is wrong with it
        for (const auto& item : object.items()) {
            const std::string& key = item.key();
            if (std::any_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; })) continue;
            std::string known;
            for (const char* k : keys) known += (known.empty() ? "" : ", ") + std::string(k);
            fail(object_name.empty() ? key : object_name + "." + key, "is not part of a view file (known here: " + known + ")");
        }
    }

    int positive_int(const json& parent, const std::string& parent_name, const char* key) const {
        const std::string name = parent_name + "." + key;
        const json& j = field(parent, parent_name, key);
        if (!j.is_number_integer() || j.get<long long>() < 1 || j.get<long long>() > kMaxImageSide)
            fail(name, "must be an integer in [1, " + std::to_string(kMaxImageSide) + "]");
        return static_cast<int>(j.get<long long>());
    }

    Scene read() const {
        const std::string text = detail::read_file(path_);
        // nlohmann::json keeps the last of two equal keys: a view that gave "image" twice was read
        // with the second without a word. The parser's callback sees each object's keys in turn.
        struct Object {
            std::string name;
            std::vector<std::string> keys;
        };
        std::vector<Object> objects;
        std::string key_name;  // the field the next object or value is, as "camera.position"
        const json::parser_callback_t once = [&](int depth, json::parse_event_t event, json& parsed) {
            // A view file nests three levels deep ("camera", "position", its array); a file nested a
            // million deep named every level by its dotted path, memory quadratic in the depth, and
            // took 23 GB before the system killed it (found by audit, 2026-12-07).
            if (depth > kMaxDepth) throw Error(path_ + ": JSON nested deeper than " + std::to_string(kMaxDepth) + " levels");
            if (event == json::parse_event_t::object_start) objects.push_back({key_name, {}});
            if (event == json::parse_event_t::object_end && !objects.empty()) {
                key_name = objects.back().name;  // the next object in an array is named as this one
                objects.pop_back();
            }
            if (event == json::parse_event_t::key && !objects.empty()) {
                Object& o = objects.back();
                const std::string k = parsed.get<std::string>();
                key_name = o.name.empty() ? k : o.name + "." + k;
                if (std::find(o.keys.begin(), o.keys.end(), k) != o.keys.end()) fail(key_name, "is given twice");
                o.keys.push_back(k);
            }
            return true;
        };
        json doc;
        try {
            doc = json::parse(text, once, true, /*ignore_comments=*/true);
        } catch (const json::exception& e) {
            const std::size_t at = ErrorPosition::in(text);
            const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
            throw Error(path_ + ":" + std::to_string(line) + ": invalid JSON: " + reason(e));
        }
        if (!doc.is_object()) throw Error(path_ + ": a view file must be a JSON object");
        only(doc, "", {"name", "mesh", "camera", "light", "image"});

        const json& mesh = field(doc, "", "mesh");
        if (!mesh.is_string() || mesh.get<std::string>().empty()) fail("mesh", "must be a non-empty string");
        // A path ends at a NUL for the system: "m.obj\u0000/x.obj" loaded m.obj without a word.
        if (mesh.get<std::string>().find('\0') != std::string::npos) fail("mesh", "must not contain a NUL character");
        const std::filesystem::path mesh_path =
            std::filesystem::path(path_).parent_path() / mesh.get<std::string>();
        if (!detail::file_exists(mesh_path.string()))
            fail("mesh", "names " + mesh_path.string() + ", which does not exist");
        if (std::error_code ec; std::filesystem::is_directory(mesh_path, ec))
            fail("mesh", "names " + mesh_path.string() + ", which is a folder, not a file");

        Scene scene;
        // Of the right type, as every other field: a name of 5 or null used to give way to the file's.
        if (doc.contains("name") && (!doc["name"].is_string() || doc["name"].get<std::string>().empty()))
            fail("name", "must be a non-empty string");
        scene.name = doc.contains("name") ? doc["name"].get<std::string>() : std::filesystem::path(path_).stem().string();
        const json& cam = object(doc, "camera");
        only(cam, "camera", {"position", "look_at", "up", "fov_y_deg"});
        scene.camera.position = vec3(cam, "camera", "position");
        scene.camera.look_at = vec3(cam, "camera", "look_at");
        scene.camera.up = vec3(cam, "camera", "up");
        const json& fov = field(cam, "camera", "fov_y_deg");
        scene.camera.fov_y_deg = single(fov, "camera.fov_y_deg");
        // Checked as the float the camera gets: 179.99999999999 rounds to 180 and 1e-50 to 0.
        if (!(scene.camera.fov_y_deg > 0.f && scene.camera.fov_y_deg < 180.f)) {
            const double given = fov.get<double>();
            const std::string rounded = given > 0.0 && given < 180.0
                                            ? ", which rounds to " + json(scene.camera.fov_y_deg).dump() + " as a float"
                                            : "";
            fail("camera.fov_y_deg", "is " + fov.dump() + rounded + "; it must lie in (0, 180) degrees");
        }

        const json& light = object(doc, "light");
        only(light, "light", {"type", "position", "color"});
        if (light.contains("type") && light["type"] != "point") fail("light.type", "must be \"point\"");
        scene.light.position = vec3(light, "light", "position");
        if (light.contains("color")) scene.light.color = vec3(light, "light", "color");

        const json& image = object(doc, "image");
        only(image, "image", {"width", "height"});
        scene.width = positive_int(image, "image", "width");
        scene.height = positive_int(image, "image", "height");

        scene.triangles = load_mesh(mesh_path.string());
        validate_scene(scene, path_);
        return scene;
    }

private:
    std::string path_;
};

}  // namespace

Scene load_view_file(const std::string& path) { return ViewReader(path).read(); }

namespace {

// The external buffers a .gltf file names (`"uri": "mesh.bin"`, beside it), as (what, path); none for
// data URIs, a .glb or a file that cannot be read as JSON (loading it says why).
void add_gltf_buffers(const std::string& gltf, std::vector<std::pair<std::string, std::string>>& files) {
    if (lower_extension(gltf) != ".gltf") return;
    try {
        const json doc = json::parse(detail::read_file(gltf));
        if (!doc.is_object() || !doc.contains("buffers") || !doc["buffers"].is_array()) return;
        for (const json& b : doc["buffers"])
            if (b.is_object() && b.contains("uri") && b["uri"].is_string() && b["uri"].get<std::string>().rfind("data:", 0) != 0)
                files.emplace_back("glTF buffer", (std::filesystem::path(gltf).parent_path() / b["uri"].get<std::string>()).string());
    } catch (const std::exception&) {
    }
}

}  // namespace

std::vector<std::pair<std::string, std::string>> scene_files(const std::string& spec) {
    if (spec.empty() || spec.rfind("builtin:", 0) == 0) return {};
    std::vector<std::pair<std::string, std::string>> files{{"scene", spec}};
    add_gltf_buffers(spec, files);
    if (lower_extension(spec) != ".json") return files;
    try {
        const json doc = json::parse(detail::read_file(spec), nullptr, true, /*ignore_comments=*/true);
        if (doc.is_object() && doc.contains("mesh") && doc["mesh"].is_string()) {
            const std::string mesh = (std::filesystem::path(spec).parent_path() / doc["mesh"].get<std::string>()).string();
            files.emplace_back("mesh", mesh);
            add_gltf_buffers(mesh, files);
        }
    } catch (const std::exception&) {
        // Not a view file one can read: loading it says why.
    }
    return files;
}

std::vector<std::pair<std::string, std::string>> scene_files(const std::vector<std::string>& specs) {
    std::vector<std::pair<std::string, std::string>> files;
    for (const std::string& spec : specs)
        for (auto& file : scene_files(spec)) files.push_back(std::move(file));
    return files;
}

}  // namespace cellrt
