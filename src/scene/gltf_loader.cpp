// glTF 2.0 reader (loaders.hpp, docs/FORMATS.md) over tinygltf, which parses the JSON, the GLB container
// and the buffers (files or base64 data URIs). tinygltf does not check that an accessor's bytes lie
// inside its buffer, nor types, nor indices, so every one of those is checked here before a byte is
// read, as the OBJ and PLY readers check theirs.
#include "tinygltf.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numbers>

#include <nlohmann/json.hpp>

#include "cellrt/error.hpp"
#include "core/files.hpp"
#include "cellrt/loaders.hpp"
#include "core/read_file.hpp"

namespace cellrt {
namespace {

// The files tinygltf reads (the .gltf or .glb itself and external buffers), read by cellrt's own
// reader: tinygltf's takes a folder's size as 2^63 - 1 bytes and allocates it (a buffer whose uri
// names a folder; found by fuzz_gltf). Only a regular, non-empty file is read.
bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
        if (err) *err += path + ": not a regular file\n";
        return false;
    }
    try {
        const std::string bytes = detail::read_file(path);
        out->assign(bytes.begin(), bytes.end());
    } catch (const Error& e) {
        if (err) *err += std::string(e.what()) + "\n";
        return false;
    }
    if (out->empty()) {
        if (err) *err += path + ": the file is empty\n";
        return false;
    }
    return true;
}

// Whether a file tinygltf asks for exists, told without opening it: tinygltf's own check opens it,
// which waits for ever on a named pipe.
bool file_present(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::exists(path, ec);
}

// Column-major 4x4, as glTF writes matrices; double so that a chain of transforms rounds once.
using Matrix = std::array<double, 16>;

constexpr Matrix kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

Matrix multiply(const Matrix& a, const Matrix& b) {
    Matrix m{};
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
            m[c * 4 + r] = s;
        }
    return m;
}

// The determinant of m's upper-left 3 x 3 block, whose sign says whether m mirrors.
double determinant3(const Matrix& m) {
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

// m * (x, y, z, w), as floats.
Vec3 apply(const Matrix& m, double x, double y, double z, double w) {
    return {static_cast<float>(m[0] * x + m[4] * y + m[8] * z + m[12] * w),
            static_cast<float>(m[1] * x + m[5] * y + m[9] * z + m[13] * w),
            static_cast<float>(m[2] * x + m[6] * y + m[10] * z + m[14] * w)};
}

std::string named(const char* what, std::size_t index, const std::string& name) {
    std::string s = std::string(what) + " " + std::to_string(index);
    if (!name.empty()) s += " ('" + name + "')";
    return s;
}

// A mesh in its own space: the vertices of all its primitives and their triangles' indices.
struct LocalMesh {
    std::vector<Vec3> vertices;
    std::vector<std::uint32_t> indices;
    bool read = false;
};

class GltfReader {
public:
    GltfReader(const std::string& path, std::size_t max_triangles) : path_(path), max_triangles_(max_triangles) {}

    GltfScene read() {
        parse();
        check_integer_fields();
        check_required_extensions();
        const std::vector<int>& roots = default_scene_nodes();
        collect_instances(roots);
        std::size_t total = 0;
        for (const Instance& in : instances_) {
            LocalMesh& mesh = local_mesh(in.mesh);
            const std::size_t n = mesh.indices.size() / 3;
            if (n > max_triangles_ - total)
                fail("the default scene makes more than " + std::to_string(max_triangles_) +
                     " triangles once its nodes are flattened");
            total += n;
        }
        GltfScene out;
        out.triangles.reserve(total);
        std::vector<Vec3> world;
        for (const Instance& in : instances_) {
            const LocalMesh& mesh = meshes_[static_cast<std::size_t>(in.mesh)];
            world.resize(mesh.vertices.size());
            for (std::size_t i = 0; i < world.size(); ++i) {
                const Vec3& p = mesh.vertices[i];
                world[i] = apply(in.world, p.x, p.y, p.z, 1.0);
                if (!is_finite(world[i]))
                    fail(node_name(in.node) + ": its transform makes vertex " + std::to_string(i) + " of " +
                         mesh_name(in.mesh) + " non-finite");
            }
            // A transform that mirrors (a negative determinant) makes the front faces clockwise (glTF
            // 2.0, "Meshes"): the corners are swapped so that every triangle's front is
            // counter-clockwise, as an unmirrored node's and an OBJ's are (found by audit, 2026-12-07).
            const int second = determinant3(in.world) < 0.0 ? 2 : 1, third = 3 - second;
            for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
                out.triangles.push_back(
                    {world[mesh.indices[t]], world[mesh.indices[t + second]], world[mesh.indices[t + third]]});
        }
        out.camera = camera_;
        out.aspect_ratio = aspect_;
        return out;
    }

private:
    struct Instance {
        int node, mesh;
        Matrix world;
    };

    [[noreturn]] void fail(const std::string& what) const { throw Error(path_ + ": " + what); }

    std::string node_name(int i) const { return named("node", static_cast<std::size_t>(i), model_.nodes[static_cast<std::size_t>(i)].name); }
    std::string mesh_name(int i) const { return named("mesh", static_cast<std::size_t>(i), model_.meshes[static_cast<std::size_t>(i)].name); }

    // glTF 2.0 section 3.12: a loader must refuse an asset one of whose required extensions it does
    // not support. Those that change only the appearance cannot change the triangles and are taken;
    // any other (instancing, compression, quantization, ...) could (found by audit, 2026-12-07:
    // EXT_mesh_gpu_instancing's copies were dropped without a word).
    void check_required_extensions() const {
        auto appearance_only = [](const std::string& e) {
            for (const char* prefix : {"KHR_materials_", "KHR_texture_", "EXT_texture_"})
                if (e.rfind(prefix, 0) == 0) return true;
            return e == "KHR_lights_punctual" || e == "MSFT_texture_dds";
        };
        for (const std::string& e : model_.extensionsRequired)
            if (!appearance_only(e))
                fail("requires the extension '" + e + "', which this reader does not apply (it could change the "
                     "triangles)");
    }

    // What the reader does not apply and will not ignore where it moves the vertices (found by audit,
    // 2026-12-07): a skin (a skinned mesh follows its joints, not its node), and morph targets with a
    // weight other than 0 (the node's weights, else the mesh's).
    void check_deformations(int node, int mesh) const {
        const tinygltf::Node& n = model_.nodes[static_cast<std::size_t>(node)];
        if (n.skin >= 0) fail(node_name(node) + ": has a skin, which this reader does not apply");
        const tinygltf::Mesh& m = model_.meshes[static_cast<std::size_t>(mesh)];
        const std::vector<double>& weights = n.weights.empty() ? m.weights : n.weights;
        bool targets = false;
        for (const tinygltf::Primitive& p : m.primitives) targets = targets || !p.targets.empty();
        for (const double w : weights)
            if (targets && w != 0.0)
                fail(node_name(node) + ": " + mesh_name(mesh) +
                     " has morph targets with a weight other than 0, which this reader does not apply");
    }

    void parse() {
        tinygltf::TinyGLTF loader;
        // Images are not needed: accepted unread (tinygltf.hpp compiles no decoder).
        loader.SetImageLoader([](tinygltf::Image*, int, std::string*, std::string*, int, int, const unsigned char*,
                                 int, void*) { return true; },
                              nullptr);
        loader.SetFsCallbacks({&file_present, &tinygltf::ExpandFilePath, &read_whole_file,
                               &tinygltf::WriteWholeFile, nullptr});
        std::string err, warn;
        const std::string ext = lower_extension(path_);
        bool ok = false;
        if (ext != ".glb" && ext != ".gltf") fail("a glTF file must end in .gltf or .glb");
        try {
            ok = ext == ".glb" ? loader.LoadBinaryFromFile(&model_, &err, &warn, path_)
                               : loader.LoadASCIIFromFile(&model_, &err, &warn, path_);
        } catch (const std::bad_alloc&) {
            throw;
        } catch (const std::exception& e) {  // what nlohmann throws through tinygltf
            fail(std::string("invalid glTF: ") + e.what());
        }
        if (!ok) {
            // tinygltf's messages are lines; cellrt's are one line.
            while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
            for (char& c : err)
                if (c == '\n') c = ';';
            fail("invalid glTF: " + (err.empty() ? std::string("tinygltf refused the file") : err));
        }
    }

    // The file's JSON: the .gltf itself, or a GLB's first chunk (glTF 2.0 section 4.4.3; parse()
    // has checked the container).
    nlohmann::json document() const {
        const std::string bytes = detail::read_file(path_);
        if (lower_extension(path_) != ".glb") return nlohmann::json::parse(bytes);
        std::uint32_t length = 0;
        std::memcpy(&length, bytes.data() + 12, sizeof length);
        return nlohmann::json::parse(bytes.substr(20, length));
    }

    // tinygltf takes an optional integer only as a JSON integer: written `1.0` (an integer to JSON
    // Schema) it was left at its default without a word, and an index of 2^32 wrapped (found by
    // audit, 2026-12-07: `"scene": 1.0` loaded scene 0, a byteOffset of 12.0 read from 0, `"mesh":
    // 4294967296` loaded mesh 0). Each field that places or picks triangles must be a JSON integer
    // in [0, 2^31 - 1]; other fields change nothing this reader reads.
    void check_integer_fields() const {
        const nlohmann::json doc = document();
        const auto check = [&](const nlohmann::json& value, const std::string& name) {
            if (value.is_number_unsigned() && value.get<std::uint64_t>() <= std::numeric_limits<int>::max()) return;
            if (value.is_number_integer() && value.get<std::int64_t>() >= 0 &&
                value.get<std::int64_t>() <= std::numeric_limits<int>::max())
                return;
            fail(name + " is " + value.dump() + ": it must be an integer in [0, 2147483647], written without a "
                 "decimal point or exponent (this reader does not take 1.0 as 1)");
        };
        const auto fields = [&](const nlohmann::json& object, const std::string& name,
                                std::initializer_list<const char*> keys) {
            if (!object.is_object()) return;
            for (const char* key : keys)
                if (const auto it = object.find(key); it != object.end()) check(*it, name + "." + key);
        };
        const auto each = [&](const nlohmann::json& object, const char* key, const auto& visit) {
            if (!object.is_object()) return;
            const auto it = object.find(key);
            if (it == object.end() || !it->is_array()) return;
            for (std::size_t i = 0; i < it->size(); ++i) visit((*it)[i], std::string(key) + "[" + std::to_string(i) + "]");
        };
        if (const auto it = doc.find("scene"); it != doc.end()) check(*it, "scene");
        each(doc, "scenes", [&](const nlohmann::json& scene, const std::string& name) {
            each(scene, "nodes", [&](const nlohmann::json& n, const std::string& item) { check(n, name + "." + item); });
        });
        each(doc, "nodes", [&](const nlohmann::json& node, const std::string& name) {
            fields(node, name, {"camera", "mesh", "skin"});
            each(node, "children", [&](const nlohmann::json& n, const std::string& item) { check(n, name + "." + item); });
        });
        each(doc, "meshes", [&](const nlohmann::json& mesh, const std::string& name) {
            each(mesh, "primitives", [&](const nlohmann::json& p, const std::string& item) {
                fields(p, name + "." + item, {"indices", "mode"});
                if (const auto a = p.find("attributes"); a != p.end() && a->is_object())
                    for (const auto& [key, value] : a->items()) check(value, name + "." + item + ".attributes." + key);
            });
        });
        each(doc, "accessors", [&](const nlohmann::json& a, const std::string& name) {
            fields(a, name, {"bufferView", "byteOffset", "componentType", "count"});
        });
        each(doc, "bufferViews", [&](const nlohmann::json& v, const std::string& name) {
            fields(v, name, {"buffer", "byteOffset", "byteLength", "byteStride"});
        });
        each(doc, "buffers", [&](const nlohmann::json& b, const std::string& name) { fields(b, name, {"byteLength"}); });
    }

    const std::vector<int>& default_scene_nodes() const {
        if (model_.scenes.empty()) fail("the file has no scene");
        const int s = model_.defaultScene < 0 ? 0 : model_.defaultScene;
        if (static_cast<std::size_t>(s) >= model_.scenes.size())
            fail("the default scene " + std::to_string(s) + " does not exist (the file has " +
                 std::to_string(model_.scenes.size()) + " scenes)");
        return model_.scenes[static_cast<std::size_t>(s)].nodes;
    }

    Matrix local_transform(int index) const {
        const tinygltf::Node& n = model_.nodes[static_cast<std::size_t>(index)];
        auto check = [&](const std::vector<double>& v, std::size_t size, const char* field) {
            if (!v.empty() && v.size() != size)
                fail(node_name(index) + ": " + field + " must have " + std::to_string(size) + " numbers, has " +
                     std::to_string(v.size()));
            for (const double x : v)
                if (!std::isfinite(x)) fail(node_name(index) + ": " + field + " is not finite");
        };
        check(n.matrix, 16, "matrix");
        check(n.translation, 3, "translation");
        check(n.rotation, 4, "rotation");
        check(n.scale, 3, "scale");
        // tinygltf reads translation, rotation and scale only where a node has no matrix.
        if (!n.matrix.empty()) {
            Matrix m;
            std::copy(n.matrix.begin(), n.matrix.end(), m.begin());
            return m;
        }
        Matrix m = kIdentity;
        if (!n.scale.empty()) {
            m[0] = n.scale[0];
            m[5] = n.scale[1];
            m[10] = n.scale[2];
        }
        if (!n.rotation.empty()) {
            const double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                                         n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
            // glTF requires a unit quaternion; exporters write it to a few digits. Normalised, so that
            // a length of 1.0005 neither scales nor skews the mesh (found by audit, 2026-12-07).
            if (std::fabs(len - 1.0) > 1e-3) fail(node_name(index) + ": rotation is not a unit quaternion");
            const double x = n.rotation[0] / len, y = n.rotation[1] / len, z = n.rotation[2] / len,
                         w = n.rotation[3] / len;
            const Matrix r = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),     0,
                              2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),     0,
                              2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y), 0,
                              0,                       0,                       0,                       1};
            m = multiply(r, m);
        }
        if (!n.translation.empty()) {
            m[12] = n.translation[0];
            m[13] = n.translation[1];
            m[14] = n.translation[2];
        }
        return m;
    }

    // Depth first from the scene's roots, children in order, as the camera rule ("the first") needs
    // an order; glTF's nodes form trees, so a node reached twice is refused (which also ends cycles).
    void collect_instances(const std::vector<int>& roots) {
        std::vector<bool> seen(model_.nodes.size(), false);
        std::vector<std::pair<int, Matrix>> stack;
        for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.emplace_back(*r, kIdentity);
        while (!stack.empty()) {
            const auto [index, parent] = stack.back();
            stack.pop_back();
            if (index < 0 || static_cast<std::size_t>(index) >= model_.nodes.size())
                fail("node " + std::to_string(index) + " does not exist (the file has " +
                     std::to_string(model_.nodes.size()) + " nodes)");
            if (seen[static_cast<std::size_t>(index)])
                fail(node_name(index) + " is reached twice (glTF nodes form trees: one parent each, no cycles)");
            seen[static_cast<std::size_t>(index)] = true;
            const tinygltf::Node& n = model_.nodes[static_cast<std::size_t>(index)];
            const Matrix world = multiply(parent, local_transform(index));
            if (n.mesh >= 0) {
                if (static_cast<std::size_t>(n.mesh) >= model_.meshes.size())
                    fail(node_name(index) + ": mesh " + std::to_string(n.mesh) + " does not exist (the file has " +
                         std::to_string(model_.meshes.size()) + " meshes)");
                check_deformations(index, n.mesh);
                instances_.push_back({index, n.mesh, world});
            }
            if (n.camera >= 0) take_camera(index, n.camera, world);
            for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) stack.emplace_back(*c, world);
        }
    }

    void take_camera(int node, int index, const Matrix& world) {
        if (static_cast<std::size_t>(index) >= model_.cameras.size())
            fail(node_name(node) + ": camera " + std::to_string(index) + " does not exist (the file has " +
                 std::to_string(model_.cameras.size()) + " cameras)");
        const tinygltf::Camera& c = model_.cameras[static_cast<std::size_t>(index)];
        if (camera_ || c.type != "perspective") return;
        const std::string name = named("camera", static_cast<std::size_t>(index), c.name);
        const double yfov = c.perspective.yfov;
        // Checked in degrees as the float the camera gets: a yfov a few ulps below pi or above 0
        // rounds to 180 or 0 there.
        const float fov_y_deg = static_cast<float>(yfov * 180.0 / std::numbers::pi);
        if (!(yfov > 0.0 && fov_y_deg > 0.f && fov_y_deg < 180.f))
            fail(name + ": yfov must lie in (0, pi) radians, and in (0, 180) degrees as a float");
        const double aspect = c.perspective.aspectRatio;
        if (!(aspect >= 0.0) || !std::isfinite(aspect)) fail(name + ": aspectRatio must be a positive number");
        // A glTF camera looks down its node's -z with +y up.
        Camera cam;
        cam.position = apply(world, 0, 0, 0, 1);
        const Vec3 forward = apply(world, 0, 0, -1, 0), up = apply(world, 0, 1, 0, 0);
        if (!is_finite(cam.position) || !is_finite(forward) || !is_finite(up) || forward == Vec3{} ||
            cross(forward, up) == Vec3{})
            fail(node_name(node) + ": its transform leaves " + name + " without a view direction and an up vector");
        // A mirroring transform flips the image left to right (the camera's +x is its right), which a
        // camera of position, look-at and up cannot show: it gave the unmirrored view (found by audit,
        // 2026-12-07).
        if (const Vec3 right = apply(world, 1, 0, 0, 0); dot(cross(right, up), forward) > 0.f)
            fail(node_name(node) + ": its transform mirrors " + name + ", which this reader cannot show (a camera "
                 "here has a position, a view direction and an up vector)");
        cam.look_at = cam.position + normalize(forward);
        cam.up = normalize(up);
        cam.fov_y_deg = fov_y_deg;
        camera_ = cam;
        if (aspect > 0.0) aspect_ = static_cast<float>(aspect);
    }

    // The accessor's bytes, checked to lie inside its buffer view and buffer; `where` names the use.
    struct Span {
        const unsigned char* data = nullptr;
        std::size_t stride = 0, count = 0;
    };

    Span accessor_bytes(int index, const std::string& where, int type, std::size_t element_bytes) const {
        if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size())
            fail(where + ": accessor " + std::to_string(index) + " does not exist (the file has " +
                 std::to_string(model_.accessors.size()) + " accessors)");
        const tinygltf::Accessor& a = model_.accessors[static_cast<std::size_t>(index)];
        const std::string name = where + ": " + named("accessor", static_cast<std::size_t>(index), a.name);
        if (a.type != type) fail(name + ": must be of type " + (type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "SCALAR"));
        if (a.sparse.isSparse) fail(name + ": sparse accessors are not supported");
        if (a.normalized) fail(name + ": must not be normalized");
        // An accessor without a buffer view is all zeros, meant to be filled by a sparse one.
        if (a.bufferView < 0) fail(name + ": has no buffer view (an accessor of zeros is not supported)");
        Span s;
        s.count = a.count;
        if (static_cast<std::size_t>(a.bufferView) >= model_.bufferViews.size())
            fail(name + ": buffer view " + std::to_string(a.bufferView) + " does not exist");
        const tinygltf::BufferView& v = model_.bufferViews[static_cast<std::size_t>(a.bufferView)];
        const std::string view = named("buffer view", static_cast<std::size_t>(a.bufferView), v.name);
        if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model_.buffers.size())
            fail(name + ": " + view + ": buffer " + std::to_string(v.buffer) + " does not exist");
        const tinygltf::Buffer& b = model_.buffers[static_cast<std::size_t>(v.buffer)];
        if (v.byteOffset > b.data.size() || v.byteLength > b.data.size() - v.byteOffset)
            fail(name + ": " + view + ": bytes " + std::to_string(v.byteOffset) + " + " + std::to_string(v.byteLength) +
                 " lie beyond the " + std::to_string(b.data.size()) + " bytes of buffer " + std::to_string(v.buffer));
        s.stride = v.byteStride == 0 ? element_bytes : v.byteStride;
        if (s.stride < element_bytes)
            fail(name + ": " + view + ": byteStride " + std::to_string(v.byteStride) + " is less than an element's " +
                 std::to_string(element_bytes) + " bytes");
        const std::size_t component = element_bytes / static_cast<std::size_t>(tinygltf::GetNumComponentsInType(type));
        if (a.byteOffset % component != 0)
            fail(name + ": byteOffset " + std::to_string(a.byteOffset) + " is not a multiple of " + std::to_string(component));
        if (s.count > 0) {
            const std::size_t room = v.byteLength < a.byteOffset ? 0 : v.byteLength - a.byteOffset;
            if (room < element_bytes || (s.count - 1) > (room - element_bytes) / s.stride)
                fail(name + ": " + std::to_string(s.count) + " elements from byte " + std::to_string(a.byteOffset) +
                     " do not fit the " + std::to_string(v.byteLength) + " bytes of " + view);
        }
        s.data = b.data.data() + v.byteOffset + a.byteOffset;
        return s;
    }

    static std::uint32_t little_endian(const unsigned char* p, std::size_t bytes) {
        std::uint32_t v = 0;
        for (std::size_t i = bytes; i-- > 0;) v = v << 8 | p[i];
        return v;
    }

    LocalMesh& local_mesh(int index) {
        if (meshes_.empty()) meshes_.resize(model_.meshes.size());
        LocalMesh& out = meshes_[static_cast<std::size_t>(index)];
        if (out.read) return out;
        const tinygltf::Mesh& mesh = model_.meshes[static_cast<std::size_t>(index)];
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            const std::string where = mesh_name(index) + " primitive " + std::to_string(p);
            if (prim.mode != TINYGLTF_MODE_TRIANGLES)
                fail(where + ": mode " + std::to_string(prim.mode) + " is not supported (only triangles, mode 4)");
            const auto pos = prim.attributes.find("POSITION");
            if (pos == prim.attributes.end()) fail(where + ": has no POSITION attribute");
            const tinygltf::Accessor* pa = nullptr;
            if (pos->second >= 0 && static_cast<std::size_t>(pos->second) < model_.accessors.size())
                pa = &model_.accessors[static_cast<std::size_t>(pos->second)];
            if (pa && pa->componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
                fail(where + ": POSITION accessor " + std::to_string(pos->second) + ": component type " +
                     std::to_string(pa->componentType) + " is not FLOAT (5126)");
            const Span v = accessor_bytes(pos->second, where + " POSITION", TINYGLTF_TYPE_VEC3, 12);
            const std::size_t first = out.vertices.size();
            if (v.count > std::numeric_limits<std::uint32_t>::max() - first)
                fail(where + ": the mesh has more than 2^32 vertices");
            out.vertices.resize(first + v.count);
            for (std::size_t i = 0; i < v.count; ++i) {
                Vec3& q = out.vertices[first + i];
                for (int a = 0; a < 3; ++a)
                    q[a] = std::bit_cast<float>(little_endian(v.data + i * v.stride + 4 * static_cast<std::size_t>(a), 4));
                if (!is_finite(q))
                    fail(where + ": POSITION accessor " + std::to_string(pos->second) + ": vertex " + std::to_string(i) +
                         " is not finite");
            }
            if (prim.indices < 0) {
                if (v.count % 3 != 0)
                    fail(where + ": without indices the vertex count must be a multiple of 3, is " + std::to_string(v.count));
                for (std::size_t i = 0; i < v.count; ++i) out.indices.push_back(static_cast<std::uint32_t>(first + i));
                continue;
            }
            std::size_t bytes = 0;
            if (static_cast<std::size_t>(prim.indices) < model_.accessors.size()) {
                const tinygltf::Accessor& ia = model_.accessors[static_cast<std::size_t>(prim.indices)];
                switch (ia.componentType) {
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: bytes = 1; break;
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: bytes = 2; break;
                    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: bytes = 4; break;
                    default:
                        fail(where + ": indices accessor " + std::to_string(prim.indices) + ": component type " +
                             std::to_string(ia.componentType) + " is not UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
                }
            }
            const Span ix = accessor_bytes(prim.indices, where + " indices", TINYGLTF_TYPE_SCALAR, bytes);
            if (ix.count % 3 != 0)
                fail(where + ": indices accessor " + std::to_string(prim.indices) + ": count " + std::to_string(ix.count) +
                     " is not a multiple of 3");
            out.indices.reserve(out.indices.size() + ix.count);
            for (std::size_t i = 0; i < ix.count; ++i) {
                const std::uint32_t k = little_endian(ix.data + i * ix.stride, bytes);
                if (k >= v.count)
                    fail(where + ": indices accessor " + std::to_string(prim.indices) + ": index " + std::to_string(i) +
                         " is " + std::to_string(k) + ", beyond the " + std::to_string(v.count) + " vertices");
                out.indices.push_back(static_cast<std::uint32_t>(first + k));
            }
        }
        out.read = true;
        return out;
    }

    const std::string& path_;
    std::size_t max_triangles_;
    tinygltf::Model model_;
    std::vector<Instance> instances_;
    std::vector<LocalMesh> meshes_;
    std::optional<Camera> camera_;
    std::optional<float> aspect_;
};

}  // namespace

GltfScene load_gltf(const std::string& path, std::size_t max_triangles) { return GltfReader(path, max_triangles).read(); }

}  // namespace cellrt
